//! The design module of a planar plan: the plan's steps once more, each
//! number the drawing fixes read from a candidate's geometry (`g.f[k]`)
//! instead of written as a literal, and `prepare`, which computes those
//! numbers from the design parameters (see [`crate::plan::design`]).
//!
//! Each number is recorded with where it comes from as the step's code is
//! written ([`Recipe`]): a marker's coordinate, a radius (the drawn
//! distance between a circle's centre and the point on it), a turned
//! line's offset (the drawn offset of the point it passes). Every recipe is
//! checked against the plan's own number at the drawn parameters before
//! anything is written, so a recipe that does not give the plan back is an
//! error here, not a wrong candidate later. Closed-form plans only: a
//! numeric cluster's code folds its numbers together (`Local::Drawn`),
//! which a candidate would have to unfold.

use std::cell::RefCell;

use proc_macro2::{Literal, TokenStream};
use quote::quote;

use super::{index, lit, point_lit, step_comments, Emitter, Sink};
use crate::plan::design::DesignTable;
use crate::plan::{Plan, PointRef, StepKind};

/// Where a number of the plan comes from in the drawing.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Recipe {
    /// Coordinate `k` of a marker ("body.marker").
    Coord { marker: usize, k: usize },
    /// The distance between two markers.
    Radius { centre: usize, on: usize },
    /// The signed distance from the line through `pivot` along `dir` to
    /// `target`.
    Offset {
        pivot: usize,
        target: usize,
        dir: [f64; 2],
    },
}

/// The design module being written: the parameters, the markers in the
/// module's order, the numbers recorded so far and the first problem met.
#[derive(Clone, Debug)]
pub(super) struct Recording<'p> {
    table: &'p DesignTable<2>,
    /// "body.marker", in the order of the module's `marker` constants.
    names: Vec<String>,
    /// Each body's markers: their index in `names` and drawn position.
    of_body: Vec<Vec<(usize, [f64; 2])>>,
    recipes: RefCell<Vec<(Recipe, f64)>>,
    problem: RefCell<Option<String>>,
}

impl Recording<'_> {
    /// Whether no number is read from the geometry.
    pub fn is_empty(&self) -> bool {
        self.recipes.borrow().is_empty()
    }

    fn fail(&self, why: String) {
        self.problem.borrow_mut().get_or_insert(why);
    }

    fn marker(&self, name: &str) -> usize {
        match self.names.iter().position(|n| n == name) {
            Some(k) => k,
            None => {
                self.fail(format!(
                    "the plan reads marker {name}, which the mechanism does not have"
                ));
                0
            }
        }
    }
}

impl Emitter<'_> {
    /// `g.f[k]` for a new number `value` made by `recipe`.
    fn geometry_number(&self, recipe: Recipe, value: f64) -> TokenStream {
        let d = self.design.as_ref().expect("in the design module");
        let mut r = d.recipes.borrow_mut();
        let k = Literal::usize_unsuffixed(r.len());
        r.push((recipe, value));
        // On lanes every number is one lane-wide (a broadcast, hoisted out
        // of nothing: the frames share the candidate's numbers).
        if self.lanes {
            quote!(Lanes::cst(g.f[#k]))
        } else {
            quote!(g.f[#k])
        }
    }

    /// The coordinates of a marker's local (= drawn) position `local`: the
    /// marker named, or else the one of `body` drawn there. Literals
    /// outside the design module.
    pub(super) fn drawn_coords(&self, body: usize, local: [f64; 2], name: Option<&str>) -> [TokenStream; 2] {
        self.drawn_coords_at(body, local, name, None)
    }

    /// [`Self::drawn_coords`] of a marker a step puts at the point `at`:
    /// where a body has several markers drawn at `local` (a slider's pin
    /// and its slide), the one that moves with `at`'s.
    fn drawn_coords_at(
        &self,
        body: usize,
        local: [f64; 2],
        name: Option<&str>,
        at: Option<&PointRef>,
    ) -> [TokenStream; 2] {
        let Some(d) = self.design.as_ref() else {
            return [self.slit(local[0]), self.slit(local[1])];
        };
        let node = |k: usize| d.table.markers[&d.names[k]].node;
        let marker = match name {
            // A slid point is its partner's: at zero slide the carried
            // marker sits where it is drawn, the named one's drawn offset
            // along the slide away (a node's other marker).
            Some(n) => {
                let k = d.marker(n);
                if d.table.markers[&d.names[k]].drawn == local {
                    k
                } else {
                    let partner = (0..d.names.len())
                        .find(|&j| node(j) == node(k) && d.table.markers[&d.names[j]].drawn == local);
                    partner.unwrap_or_else(|| {
                        d.fail(format!(
                            "the plan reads {n} at {local:?}, where no marker of its joint is drawn"
                        ));
                        k
                    })
                }
            }
            None => {
                let mut here: Vec<usize> = (d.of_body[body].iter())
                    .filter(|(_, at)| *at == local)
                    .map(|(k, _)| *k)
                    .collect();
                if let Some(with) = at.map(|p| node(self.drawn_marker(p))) {
                    if here.iter().any(|k| node(*k) == with) {
                        here.retain(|k| node(*k) == with);
                    }
                }
                let nodes: Vec<usize> = here.iter().map(|k| node(*k)).collect();
                if here.is_empty() || nodes.iter().any(|n| *n != nodes[0]) {
                    let body = &self.plan.bodies[body].name;
                    d.fail(format!(
                        "the plan reads a point of body {body} at {local:?}, which is not one marker that moves with one node"
                    ));
                    return [quote!(0.0), quote!(0.0)];
                }
                here[0]
            }
        };
        [0, 1].map(|k| self.geometry_number(Recipe::Coord { marker, k }, local[k]))
    }

    /// A marker's local position as a point (see [`Self::drawn_coords`]).
    pub(super) fn drawn_point(&self, body: usize, local: [f64; 2], name: Option<&str>) -> TokenStream {
        if self.design.is_none() {
            return self.point_lit(local);
        }
        let [x, y] = self.drawn_coords(body, local, name);
        quote!([#x, #y])
    }

    /// The local position of the marker of `body` a step puts at `at`
    /// (see [`Self::drawn_coords_at`]).
    pub(super) fn drawn_point_at(&self, body: usize, local: [f64; 2], at: &PointRef) -> TokenStream {
        if self.design.is_none() {
            return self.point_lit(local);
        }
        let [x, y] = self.drawn_coords_at(body, local, None, Some(at));
        quote!([#x, #y])
    }

    /// The marker a point read by a step is drawn at.
    fn drawn_marker(&self, p: &PointRef) -> usize {
        let d = self.design.as_ref().expect("in the design module");
        match p {
            PointRef::Fixed { name, .. } | PointRef::Marker { name, .. } | PointRef::Slid { name, .. } => {
                d.marker(name)
            }
            PointRef::Temp { id } => d.marker(&self.plan.temps[*id].name),
        }
    }

    /// A circle's radius `r` (centre `centre`, through the point a step
    /// computes into temp `out`).
    pub(super) fn radius(&self, r: f64, centre: &PointRef, out: usize) -> TokenStream {
        if self.design.is_none() {
            return self.slit(r);
        }
        let recipe = Recipe::Radius {
            centre: self.drawn_marker(centre),
            on: self.drawn_marker(&PointRef::Temp { id: out }),
        };
        self.geometry_number(recipe, r)
    }

    /// A turned line's offset `kappa` from `target` (see
    /// [`StepKind::TurnLine`]).
    pub(super) fn line_offset(
        &self,
        kappa: f64,
        pivot: &PointRef,
        target: &PointRef,
        dir: [f64; 2],
    ) -> TokenStream {
        if self.design.is_none() {
            return self.slit(kappa);
        }
        let recipe = Recipe::Offset {
            pivot: self.drawn_marker(pivot),
            target: self.drawn_marker(target),
            dir,
        };
        self.geometry_number(recipe, kappa)
    }
}

/// A recipe evaluated on drawn marker positions, for the check at the
/// drawing.
fn evaluate(recipe: &Recipe, at: &[[f64; 2]]) -> f64 {
    use dofplan_runtime::design::{line_offset, radius};
    match *recipe {
        Recipe::Coord { marker, k } => at[marker][k],
        Recipe::Radius { centre, on } => radius(at[centre], at[on]),
        Recipe::Offset { pivot, target, dir } => line_offset(at[pivot], at[target], dir),
    }
}

/// The expression of a recipe in `prepare`, over its `markers` array.
fn expression(recipe: &Recipe) -> TokenStream {
    let m = |k: usize| {
        let k = index(k);
        quote!(markers[#k])
    };
    match *recipe {
        Recipe::Coord { marker, k } => {
            let (p, k) = (m(marker), index(k));
            quote!(#p[#k])
        }
        Recipe::Radius { centre, on } => {
            let (c, o) = (m(centre), m(on));
            quote!(d::radius(#c, #o))
        }
        Recipe::Offset { pivot, target, dir } => {
            let (p, t, dir) = (m(pivot), m(target), point_lit(dir));
            quote!(d::line_offset(#p, #t, #dir))
        }
    }
}

/// The text of `pub mod design` for `plan`'s module, or why the plan has
/// none.
pub(in crate::emit) fn design_module(plan: &Plan, table: &DesignTable<2>) -> Result<String, String> {
    if let Some(i) = (plan.steps.iter()).position(|s| matches!(s.kind, StepKind::Cluster { .. })) {
        return Err(format!(
            "step {i} is a numeric cluster ({}): design modules are compiled for closed-form plans only; prepare candidates through the library's Design instead",
            plan.explain(i)
        ));
    }
    let names: Vec<String> = (plan.bodies.iter())
        .flat_map(|b| b.markers.iter().map(move |(m, _)| format!("{}.{m}", b.name)))
        .collect();
    let mut of_body = Vec::new();
    let mut k = 0;
    for b in &plan.bodies {
        of_body.push(
            b.markers
                .iter()
                .enumerate()
                .map(|(i, (_, at))| (k + i, *at))
                .collect(),
        );
        k += b.markers.len();
    }
    if let Some(missing) = names.iter().find(|n| !table.markers.contains_key(*n)) {
        return Err(format!("marker {missing} has no design parameter"));
    }
    let recording = || Recording {
        table,
        names: names.clone(),
        of_body: of_body.clone(),
        recipes: RefCell::new(Vec::new()),
        problem: RefCell::new(None),
    };
    let mut e = Emitter::new(plan);
    e.design = Some(recording());
    let steps: Vec<TokenStream> = (0..plan.steps.len()).map(|i| e.step(i)).collect();
    let doc = " The frame at `inputs` of the candidate `g` (made by [`prepare`]), from `s`: the module's `solve` with the candidate's numbers.";
    let solve_with = e.single_solve(steps, doc);
    let rec = e.design.as_ref().expect("set above");
    if let Some(why) = rec.problem.borrow().clone() {
        return Err(why);
    }
    check_at_drawing(plan, table, rec)?;
    let prepare = prepare_items(plan, table, rec);
    // The same steps on tangents and on lanes of frames: they must read
    // the same numbers.
    let again = |on: &str, dual: bool, write: &dyn Fn(&Emitter, Vec<TokenStream>) -> TokenStream| {
        let mut e = Emitter::new(plan);
        (e.jets, e.dual, e.lanes, e.design) = (true, dual, !dual, Some(recording()));
        let steps: Vec<TokenStream> = (0..plan.steps.len()).map(|i| e.step(i)).collect();
        let code = write(&e, steps);
        let same = *e.design.as_ref().expect("set above").recipes.borrow() == *rec.recipes.borrow();
        same.then_some(code)
            .ok_or_else(|| format!("the steps on {on} read other numbers than the steps on values"))
    };
    let gradient = again("tangents", true, &|e, steps| e.gradient_fn(steps))?;
    let lanes = again("lanes", false, &|e, steps| e.lanes_with_fns(steps))?;
    let tangents = tangent_items(plan, table, rec);
    let serves = plan.steps.iter().map(|s| s.serves.as_slice());
    let comments = step_comments(serves.zip(plan.explanations()), &plan.source, &plan.joint_lines);
    let mut sink = Sink::new(String::new(), comments);
    sink.push(quote! {
        /// The mechanism as a function of its design parameters: every
        /// joint's drawn position and every free marker's, per coordinate.
        /// `design::prepare` makes a candidate drawing's `Geometry` once;
        /// `design::solve_with` runs its frames as `solve` runs the
        /// drawing's (`design::solve_frames_with` many at once, in lanes),
        /// and `design::gradient` gives a frame's derivatives
        /// with respect to every parameter. Topology and step order are
        /// the drawing's.
        pub mod design {
            use super::State;
            use dofplan_runtime::design::{self as d, PrepareError};
            #[allow(unused_imports)]
            use dofplan_runtime::planar::{self, Point, Pose, Rot};
            #[allow(unused_imports)]
            use dofplan_runtime::real::{RateError, Real, Tangent};
            use dofplan_runtime::{Branch, BranchPolicy, Break, Ctx, Marker};
            #[allow(unused_imports)]
            use dofplan_runtime::lanes::Lanes;
            #prepare
            #solve_with
            #lanes
            #tangents
            #gradient
        }
    });
    Ok(sink.finish())
}

/// Checks that every recipe gives the plan's own number at the drawn
/// parameters.
fn check_at_drawing(plan: &Plan, table: &DesignTable<2>, rec: &Recording) -> Result<(), String> {
    let at: Vec<[f64; 2]> = rec.names.iter().map(|n| table.markers[n].drawn).collect();
    let tol = 1e-9 * plan.size;
    for (recipe, value) in rec.recipes.borrow().iter() {
        let got = evaluate(recipe, &at);
        if (got - value).abs() > tol {
            return Err(format!(
                "the plan's number {value} is not the drawing's ({recipe:?} gives {got}): the plan relies on something the design parameters do not describe"
            ));
        }
    }
    Ok(())
}

/// `Params`, `Geometry` and `prepare`.
fn prepare_items(plan: &Plan, table: &DesignTable<2>, rec: &Recording) -> TokenStream {
    let params = params_items(table);
    let geometry = geometry_items(plan, rec);
    let prepare = prepare_fn(plan, table, rec);
    quote!(#params #geometry #prepare)
}

/// `PARAMETERS`, `NAMES` and `Params`.
fn params_items(table: &DesignTable<2>) -> TokenStream {
    let np = index(table.names.len());
    let names = &table.names;
    let drawn = table.drawn.iter().map(|v| lit(*v));
    quote! {
        /// Number of design parameters.
        pub const PARAMETERS: usize = #np;
        /// The design parameters' names (`NAME.x`, `NAME.y`), in the
        /// order of [`Params`].
        pub const NAMES: [&str; #np] = [#(#names),*];
        /// Values of the design parameters, in [`NAMES`] order.
        #[derive(Clone, Copy, Debug, PartialEq)]
        pub struct Params(pub [f64; #np]);

        impl Params {
            /// The drawing's values: [`prepare`] gives back the module's
            /// own plan.
            pub const DRAWN: Params = Params([#(#drawn),*]);

            /// The index of parameter `name` (`D.x`) in [`NAMES`].
            pub fn index(name: &str) -> Option<usize> {
                NAMES.iter().position(|n| *n == name)
            }
        }

    }
}

/// `Geometry`: the candidate's numbers, markers and drawn state.
fn geometry_items(plan: &Plan, rec: &Recording) -> TokenStream {
    let (nm, nk) = (index(rec.names.len()), index(rec.recipes.borrow().len()));
    let body_of =
        (plan.bodies.iter().enumerate()).flat_map(|(b, body)| body.markers.iter().map(move |_| index(b)));
    let marker_arms = rec.names.iter().enumerate().map(|(k, n)| {
        let k = index(k);
        quote!(#n => #k,)
    });
    quote! {
        /// Each marker's body, in the order of the module's `marker`
        /// constants.
        const BODY_OF: [usize; #nm] = [#(#body_of),*];

        /// A prepared candidate: the numbers its frames read, its markers
        /// and its drawn state.
        #[derive(Clone, Debug, PartialEq)]
        pub struct Geometry {
            f: [f64; #nk],
            markers: [Point; #nm],
            state: State,
        }

        impl Geometry {
            /// The candidate's drawn pose (every input 0), with its
            /// branches chosen: the state to run its frames from.
            pub fn state(&self) -> State {
                self.state
            }

            /// Marker `m` (a constant of the module's `marker`) as the
            /// candidate draws it; read it with `State::marker`.
            pub fn marker(&self, m: Marker) -> Marker {
                match slot(m.name) {
                    Some(k) => Marker::new(m.name, m.body, self.markers[k]),
                    None => m,
                }
            }
        }

        /// The place of marker `name` ("body.marker") in [`BODY_OF`].
        fn slot(name: &str) -> Option<usize> {
            Some(match name {
                #(#marker_arms)*
                _ => return None,
            })
        }

    }
}

/// `prepare`: the markers placed, the numbers computed, the branches
/// chosen by the frame at the drawing, the drawing checked.
fn prepare_fn(plan: &Plan, table: &DesignTable<2>, rec: &Recording) -> TokenStream {
    let nm = index(rec.names.len());
    let (nb, ni, ns) = (
        index(plan.bodies.len()),
        index(plan.inputs.len()),
        index(plan.branches.len()),
    );
    let placed = rec.names.iter().map(|n| {
        let p = &table.markers[n];
        let [x, y] = [0, 1].map(|k| {
            let (v, at, dr, off) = (
                index(2 * p.node + k),
                lit(table.drawn[2 * p.node + k]),
                lit(p.drawn[k]),
                lit(p.offset[k]),
            );
            if p.offset[k] == 0.0 && p.drawn[k] == table.drawn[2 * p.node + k] {
                quote!(v[#v])
            } else {
                quote!(d::place(v[#v], #at, #dr, #off))
            }
        });
        quote!([#x, #y])
    });
    let numbers = (rec.recipes.borrow().iter())
        .map(|(r, _)| expression(r))
        .collect::<Vec<_>>();
    // Each branch slot starts from its drawn value: the point the step
    // computes (a marker) or, for a turned line, the unturned rotation.
    let last = plan
        .branches
        .iter()
        .map(|slot| match plan.steps[slot.step].kind.computes() {
            Some(t) => {
                let k = index(rec.marker(&plan.temps[t].name));
                quote!(markers[#k])
            }
            None => point_lit(slot.drawn),
        });
    let unused = if plan.branches.is_empty() {
        quote!(let _ = Branch::Plus;)
    } else {
        quote!()
    };
    let numbers_binding = if numbers.is_empty() {
        quote!(let f = [0.0; 0];)
    } else {
        quote!(let f = [#(#numbers),*];)
    };
    quote! {
        /// The candidate drawn at `p`: its numbers computed and its
        /// branches chosen so the plan reproduces its drawing, as the
        /// compiler chooses a file's. Fails when a parameter is not
        /// finite, the plan breaks at the drawing, or the plan does not
        /// put every body where the candidate draws it (the candidate
        /// needs another plan).
        pub fn prepare(p: &Params) -> Result<Geometry, PrepareError> {
            let v = &p.0;
            if let Some(k) = v.iter().position(|x| !x.is_finite()) {
                return Err(PrepareError::NotFinite { parameter: NAMES[k] });
            }
            #unused
            let markers: [Point; #nm] = [#(#placed),*];
            #numbers_binding
            let state = State {
                poses: [Pose::IDENTITY; #nb],
                last: [#(#last),*],
                branches: [Branch::Plus; #ns],
            };
            let mut g = Geometry { f, markers, state };
            // The frame at the drawing with the nearest-root policy from
            // the drawn values picks every branch.
            let mut s = g.state;
            let mut ctx = Ctx::new(BranchPolicy::Nearest, false);
            if let Err(b) = solve_with(&g, &mut s, &[0.0; #ni], &mut ctx) {
                return Err(PrepareError::Broken { step: b.step, why: b.kind.describe() });
            }
            let tol = 1e-9 * d::size(&g.markers);
            for (k, at) in g.markers.iter().enumerate() {
                let w = s.poses[BODY_OF[k]].world(*at);
                let gap = ((w[0] - at[0]).powi(2) + (w[1] - at[1]).powi(2)).sqrt();
                if gap > tol {
                    return Err(PrepareError::NotReproduced { body: super::BODIES[BODY_OF[k]], gap });
                }
            }
            g.state.branches = s.branches;
            Ok(g)
        }
    }
}

/// `Dual`, `Tangents` and `Geometry::tangents`: a candidate's numbers and
/// markers with their derivatives, computed once per candidate as
/// `prepare` computes the numbers.
fn tangent_items(plan: &Plan, table: &DesignTable<2>, rec: &Recording) -> TokenStream {
    let np = index(table.names.len());
    let (nm, nk, nb) = (
        index(rec.names.len()),
        index(rec.recipes.borrow().len()),
        index(plan.bodies.len()),
    );
    let seeded = rec.names.iter().enumerate().map(|(k, n)| {
        let (k, node) = (index(k), index(table.markers[n].node));
        quote!(d::seeded(self.markers[#k], #node))
    });
    let numbers: Vec<TokenStream> = (rec.recipes.borrow().iter())
        .map(|(r, _)| expression(r))
        .collect();
    quote! {
        /// A number with its derivatives with respect to every design
        /// parameter, in [`NAMES`] order.
        pub type Dual = Tangent<#np>;

        /// A prepared candidate's numbers and markers with their
        /// derivatives with respect to every design parameter: what
        /// [`gradient`] runs on.
        #[derive(Clone, Debug, PartialEq)]
        pub struct Tangents {
            f: [Dual; #nk],
            markers: [[Dual; 2]; #nm],
        }

        impl Geometry {
            /// The candidate's numbers and markers with their
            /// derivatives (once per candidate, as [`prepare`]).
            pub fn tangents(&self) -> Tangents {
                let markers: [[Dual; 2]; #nm] = [#(#seeded),*];
                let f: [Dual; #nk] = [#(#numbers),*];
                Tangents { f, markers }
            }
        }

        impl Tangents {
            /// Marker `m` (a constant of the module's `marker`) in the
            /// frame `poses` (from [`gradient`]), with its derivatives
            /// with respect to every parameter; `None` for a marker of
            /// another mechanism.
            pub fn marker(&self, poses: &[Pose<Dual>; #nb], m: Marker) -> Option<[Dual; 2]> {
                let k = slot(m.name)?;
                Some(poses[BODY_OF[k]].world(self.markers[k]))
            }
        }
    }
}

impl Emitter<'_> {
    /// `gradient`: the steps once more on `Dual`s, from the branches a
    /// frame took (keep-branch), the candidate's numbers read from its
    /// `Tangents`.
    fn gradient_fn(&self, steps: Vec<TokenStream>) -> TokenStream {
        let plan = self.plan;
        let steps = self.declared_late(steps, quote!(Dual), |_| quote!());
        let out = self.pose_outputs(quote!(Dual));
        let take_branches = if plan.branches.is_empty() {
            quote!()
        } else {
            let last = self.lifted_last(quote!(Dual));
            quote!(let mut last = #last; let mut branches = s.branches;)
        };
        let bind_inputs = (0..plan.inputs.len()).map(|k| self.bind_input(k));
        let unused_g = if self.design.as_ref().is_some_and(|d| d.is_empty()) {
            quote!(let _ = g;)
        } else {
            quote!()
        };
        let nb = index(plan.bodies.len());
        quote! {
            /// Every body's pose in the frame `s` holds (solved by
            /// [`solve_with`] at `inputs`, for the candidate `g` comes
            /// from), with its derivatives with respect to every design
            /// parameter: the steps run again on [`Dual`]s with the
            /// branches the frame took — forward-mode differentiation
            /// through `prepare`'s numbers and the plan. A dead point,
            /// where a derivative is infinite, is [`RateError::Singular`].
            pub fn gradient(g: &Tangents, s: &State, inputs: &[f64]) -> Result<[Pose<Dual>; #nb], RateError> {
                #unused_g
                let ctx = &mut Ctx::new(BranchPolicy::Keep, false);
                let _ = (&inputs, &ctx);
                #take_branches
                #(#bind_inputs)*
                #(#steps)*
                let mut out = [Pose::<Dual>::cst(Pose::IDENTITY); #nb];
                #(#out)*
                let finite = out.iter().all(|p| p.at[0].finite() && p.at[1].finite() && p.rot.c.finite() && p.rot.s.finite());
                if finite { Ok(out) } else { Err(RateError::Singular) }
            }
        }
    }
}

impl Emitter<'_> {
    /// `solve_lanes_with` (the steps on lanes of frames, from a
    /// candidate's drawn state) and `solve_frames_with`, which runs a
    /// candidate's frames through it a lane group at a time.
    fn lanes_with_fns(&self, steps: Vec<TokenStream>) -> TokenStream {
        let (nb, ni) = (index(self.plan.bodies.len()), index(self.plan.inputs.len()));
        let body = self.lanes_body(steps);
        let unused_g = if self.design.as_ref().is_some_and(|d| d.is_empty()) {
            quote!(let _ = g;)
        } else {
            quote!()
        };
        quote! {
            /// [`solve_with`] of [`LANES`](dofplan_runtime::lanes::LANES)
            /// frames of the candidate `g` side by side (lane `l` of every
            /// input is frame `l`'s; its poses go to `rows[l]`), each from
            /// the candidate's drawn state under keep-branch. A break in
            /// any frame, or frames that part ways at a step, is an error
            /// for all of them: [`solve_frames_with`] then solves them one
            /// at a time.
            #[inline(always)]
            pub fn solve_lanes_with(g: &Geometry, inputs: &[Lanes; #ni], rows: &mut [[Pose; #nb]; dofplan_runtime::lanes::LANES]) -> Result<(), Break> {
                #unused_g
                let s = &g.state;
                #body
            }

            /// Every frame of `inputs` (one row of `INPUTS` values a
            /// frame) of the candidate `g` into `out` (one row of `BODIES`
            /// poses a frame), each from the candidate's drawn state under
            /// keep-branch: the frames of a closed-form plan do not depend
            /// on each other, so these are, to the bit, the poses
            /// [`solve_with`] gives frame after frame from `g.state()`.
            /// [`LANES`](dofplan_runtime::lanes::LANES) frames at a time
            /// (AVX2 where the CPU has it); a group that breaks or parts
            /// ways, and the frames left over, one at a time. The first
            /// frame that breaks is the error, with its index; the rows
            /// from it on are left unwritten or partly written.
            ///
            /// # Panics
            /// If `out` does not have one row for each row of `inputs`.
            pub fn solve_frames_with(g: &Geometry, inputs: &[f64], out: &mut [Pose]) -> Result<(), (usize, Break)> {
                #[cfg(target_arch = "x86_64")]
                if std::arch::is_x86_feature_detected!("avx2") {
                    // SAFETY: this CPU has AVX2, checked just above.
                    return unsafe { frames_with_avx2(g, inputs, out) };
                }
                frames_with_baseline(g, inputs, out)
            }

            /// [`solve_frames_with`] for any CPU, in a function of its own
            /// as `solve_frames`'s is.
            #[inline(never)]
            fn frames_with_baseline(g: &Geometry, inputs: &[f64], out: &mut [Pose]) -> Result<(), (usize, Break)> {
                frames_in_lanes_with(g, inputs, out)
            }

            /// [`solve_frames_with`] compiled for AVX2: the same operations
            /// in the same order, so the same numbers.
            ///
            /// # Safety
            /// The CPU must have AVX2.
            #[cfg(target_arch = "x86_64")]
            #[target_feature(enable = "avx2")]
            unsafe fn frames_with_avx2(g: &Geometry, inputs: &[f64], out: &mut [Pose]) -> Result<(), (usize, Break)> {
                frames_in_lanes_with(g, inputs, out)
            }

            /// The lane groups through [`solve_lanes_with`], the rest one
            /// frame at a time.
            #[inline(always)]
            fn frames_in_lanes_with(g: &Geometry, inputs: &[f64], out: &mut [Pose]) -> Result<(), (usize, Break)> {
                use dofplan_runtime::{batch, lanes::LANES};
                let (ni, nb) = (super::INPUTS.len(), super::BODIES.len());
                let frames = inputs.len() / ni;
                assert!(
                    inputs.len() == frames * ni && out.len() == frames * nb,
                    "solve_frames_with: {} inputs and {} poses are not rows of {ni} and {nb}",
                    inputs.len(), out.len()
                );
                let groups = frames / LANES;
                for k in 0..groups {
                    // A group that does not finish leaves its rows partly
                    // written: one at a time rewrites them.
                    if solve_lanes_with(g, &batch::group_inputs(inputs, k), batch::group_rows(out, k)).is_err() {
                        one_at_a_time_with(g, k * LANES..(k + 1) * LANES, inputs, out)?;
                    }
                }
                one_at_a_time_with(g, groups * LANES..frames, inputs, out)
            }

            /// The frames `frames` of the candidate `g`, each by
            /// [`solve_with`] from its drawn state.
            fn one_at_a_time_with(g: &Geometry, frames: core::ops::Range<usize>, inputs: &[f64], out: &mut [Pose]) -> Result<(), (usize, Break)> {
                let (ni, nb) = (super::INPUTS.len(), super::BODIES.len());
                let mut ctx = Ctx::new(BranchPolicy::Keep, false);
                for f in frames {
                    let mut s = g.state;
                    solve_with(g, &mut s, &inputs[f * ni..(f + 1) * ni], &mut ctx).map_err(|b| (f, b))?;
                    out[f * nb..(f + 1) * nb].copy_from_slice(&s.poses);
                }
                Ok(())
            }
        }
    }
}
