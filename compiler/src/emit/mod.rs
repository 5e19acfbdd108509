//! The Rust back end: a plan IR becomes one straight-line module per
//! mechanism (tokens by `quote`, checked by `syn`, laid out by
//! `prettyplease`).
//!
//! Every step becomes one block calling the same runtime function the
//! interpreter calls, under a comment holding the step's explanation and
//! the joints it serves. Bodies live in a fixed-size array in the state
//! struct, so a frame allocates nothing. A large plan's steps are split
//! into functions of bounded size (see `chunk`), so that rustc compiles
//! a mechanism of any size, and its repeated steps are rolled into loops
//! over tables (see `roll`); every body and marker gets a named constant
//! (see `names`).
//!
//! Spatial plans get a module of the same shape from [`emit_spatial`]
//! (`spatial.rs`, clusters in `spatial_cluster.rs`).

use std::fmt::Write;

use proc_macro2::{Ident, Literal, Span, TokenStream};
use quote::{format_ident, quote};

mod chunk;
mod cluster;
mod names;
mod rates;
mod roll;
mod spatial;
mod spatial_cluster;
mod uses;

pub use chunk::CHUNK_WEIGHT;
pub use cluster::FIXED_LIMIT;
pub use spatial::{emit_spatial, emit_spatial_chunked, spatial_cluster_fits};

use crate::model::InputKind;
use crate::plan::{DirRef, Plan, PointRef, Rel, StepKind};

/// A Rust identifier made from a user's name ("coupler.C" → `coupler_c`).
pub fn ident_for(name: &str) -> String {
    let mut s = names::word(name, false);
    if s.is_empty() || s.starts_with(|c: char| c.is_ascii_digit()) {
        s.insert_str(0, "m_");
    }
    if syn::parse_str::<Ident>(&s).is_err() {
        s.push('_'); // a keyword
    }
    s
}

/// The local naming a marker's world point inside a step's block; never
/// one of the prefixes of the frame-wide locals (poses, temps, inputs).
fn point_ident(name: &str) -> String {
    let id = ident_for(name);
    if ["pose_", "at_", "input_"].iter().any(|p| id.starts_with(p))
        || [
            "from", "line_dir", "dir_a", "dir_b", "last", "branches", "s", "ctx", "inputs",
        ]
        .contains(&id.as_str())
    {
        format!("m_{id}")
    } else {
        id
    }
}

fn lit(x: f64) -> Literal {
    Literal::f64_unsuffixed(x)
}

fn point_lit(p: [f64; 2]) -> TokenStream {
    let (x, y) = (lit(p[0]), lit(p[1]));
    quote!([#x, #y])
}

fn index(i: usize) -> Literal {
    Literal::usize_unsuffixed(i)
}

#[derive(Clone)]
struct Emitter<'p> {
    plan: &'p Plan,
    input_idents: Vec<Ident>,
    temp_idents: Vec<Ident>,
    /// The local holding each mobile body's pose during a frame.
    pose_idents: Vec<Ident>,
    /// Whether the steps are split into functions over a working copy of
    /// the state (see [`chunk`]).
    chunked: bool,
    /// Whether the steps are written for `rates`: on jets, every constant
    /// lifted ([`Real::cst`](dofplan_runtime::real::Real::cst)).
    jets: bool,
    /// With `jets`: the steps are written for `solve_lanes`, on
    /// [`Lanes`](dofplan_runtime::lanes::Lanes) of frames instead of jets.
    lanes: bool,
    /// While a step is written for a rolled run (see [`roll`]): its
    /// constants go to a table row instead of the code.
    row: std::cell::RefCell<Option<roll::Recording>>,
    /// The step computing each point.
    temp_steps: Vec<usize>,
    /// The tables of the rolled runs written so far, by first step: their
    /// module and rows, for the jets' functions to share.
    tables: std::cell::RefCell<std::collections::HashMap<usize, (Ident, Vec<roll::Row>)>>,
}

impl Emitter<'_> {
    /// The number type constants are lifted to (with `jets`).
    fn num(&self) -> TokenStream {
        if self.lanes {
            quote!(Lanes)
        } else {
            quote!(Jet2)
        }
    }

    /// A body's pose: its local for a mobile body, the state's (never
    /// written) entry for a fixed one.
    fn pose(&self, body: usize) -> TokenStream {
        if let Some(pose) = self.rolled_pose(body) {
            return pose;
        }
        if self.plan.bodies[body].fixed {
            let b = index(body);
            if self.jets {
                let t = self.num();
                quote!(Pose::<#t>::cst(s.poses[#b]))
            } else {
                quote!(s.poses[#b])
            }
        } else {
            let id = &self.pose_idents[body];
            quote!(#id)
        }
    }

    /// A constant point: a literal, or lifted to jets.
    fn plit(&self, p: [f64; 2]) -> TokenStream {
        let l = self.point_lit(p);
        if self.jets {
            quote!(planar::cst(#l))
        } else {
            l
        }
    }

    /// A constant number: a literal, or lifted to a jet.
    fn slit(&self, x: f64) -> TokenStream {
        let l = self.lit(x);
        if self.jets {
            let t = self.num();
            quote!(#t::cst(#l))
        } else {
            quote!(#l)
        }
    }

    /// Binds a point to a local inside a step's block and returns the
    /// expression that names it.
    fn point(&self, p: &PointRef, prelude: &mut Vec<TokenStream>) -> TokenStream {
        match p {
            PointRef::Fixed { at, .. } => self.plit(*at),
            PointRef::Marker { body, local, name } => {
                let id = self.local_point(name, prelude);
                // A marker's local position is a constant of its body: a
                // plain number even on jets and lanes (`Pose::world`).
                let (b, l) = (self.pose(*body), self.point_lit(*local));
                prelude.push(quote!(let #id = #b.world(#l);));
                quote!(#id)
            }
            PointRef::Slid {
                body,
                local,
                dir,
                input,
                sign,
                name,
            } => {
                let id = self.local_point(name, prelude);
                let b = self.pose(*body);
                let u = &self.input_idents[*input];
                let u = if *sign < 0.0 { quote!((-#u)) } else { quote!(#u) };
                let (lx, ly) = (self.slit(local[0]), self.slit(local[1]));
                // The slide direction is a constant: on jets and lanes a
                // multiplication by a plain number.
                let (dx, dy) = (self.lit(dir[0]), self.lit(dir[1]));
                let (ux, uy) = if self.jets {
                    (quote!(#u.mul_f64(#dx)), quote!(#u.mul_f64(#dy)))
                } else {
                    (quote!(#u * #dx), quote!(#u * #dy))
                };
                // On a fixed body (at its drawn pose, the identity, as
                // `PointRef::Fixed` takes it) the carried point is the world
                // point: no rotation to multiply by.
                if self.plan.bodies[*body].fixed {
                    prelude.push(quote!(let #id = [#lx + #ux, #ly + #uy];));
                } else {
                    prelude.push(quote!(let #id = #b.world_carried([#lx + #ux, #ly + #uy]);));
                }
                quote!(#id)
            }
            PointRef::Temp { id } => {
                let t = self.temp(*id);
                quote!(#t)
            }
        }
    }

    fn dir(&self, d: &DirRef, name: &str, prelude: &mut Vec<TokenStream>) -> TokenStream {
        match d {
            DirRef::Fixed(v) => self.plit(*v),
            DirRef::Body { body, local } => {
                let id = format_ident!("{}", name);
                let (b, l) = (self.pose(*body), self.point_lit(*local));
                prelude.push(quote!(let #id = #b.world_dir(#l);));
                quote!(#id)
            }
        }
    }

    fn step(&self, i: usize) -> TokenStream {
        let step = &self.plan.steps[i];
        let id = self.step_id(i);
        let mut pre = Vec::new();
        let marker = self.step_marker(i);
        match &step.kind {
            StepKind::Orient { body, from, rel } => {
                let b = self.pose(*body);
                let r = match rel {
                    Rel::Identity if self.jets => quote!(Rot::cst(Rot::IDENTITY)),
                    Rel::Identity => quote!(Rot::IDENTITY),
                    Rel::Input { input, inverse } => {
                        let u = &self.input_idents[*input];
                        if *inverse {
                            quote!(#u.inverse())
                        } else {
                            quote!(#u)
                        }
                    }
                };
                match from {
                    Some(f) => {
                        let f = self.pose(*f);
                        quote! {
                            #marker
                            planar::orient(&mut #b, #f.rot, #r);
                        }
                    }
                    None => quote! {
                        #marker
                        planar::set_rotation(&mut #b, #r);
                    },
                }
            }
            StepKind::Anchor { body, local, at } => {
                let at = self.point(at, &mut pre);
                let (b, l) = (self.pose(*body), self.point_lit(*local));
                quote! {
                    #marker
                    {
                        #(#pre)*
                        planar::anchor(&mut #b, #l, #at);
                    }
                }
            }
            StepKind::Align {
                body,
                p,
                p_at,
                q,
                q_at,
                redundant,
            } => {
                let p_at = self.point(p_at, &mut pre);
                let q_at = self.point(q_at, &mut pre);
                let (b, p, q) = (self.pose(*body), self.point_lit(*p), self.point_lit(*q));
                let call = if *redundant {
                    quote!(planar::align_consistent(ctx, #id, &mut #b, #p, #p_at, #q, #q_at)?;)
                } else {
                    quote!(planar::align(&mut #b, #p, #p_at, #q, #q_at);)
                };
                quote! {
                    #marker
                    {
                        #(#pre)*
                        #call
                    }
                }
            }
            StepKind::CircleCircle {
                out,
                c1,
                r1,
                c2,
                r2,
                branch,
            } => {
                let t = &self.temp(*out);
                let c1 = self.point(c1, &mut pre);
                let c2 = self.point(c2, &mut pre);
                let (r1, r2, k) = (self.slit(*r1), self.slit(*r2), self.index(*branch));
                quote! {
                    #marker
                    let #t = {
                        #(#pre)*
                        planar::circle_circle(ctx, #id, #c1, #r1, #c2, #r2, &mut branches[#k], &mut last[#k])?
                    };
                }
            }
            StepKind::CircleLine {
                out,
                c,
                r,
                line,
                branch,
            } => {
                let t = &self.temp(*out);
                let c = self.point(c, &mut pre);
                let p = self.point(&line.through, &mut pre);
                // A fixed direction stays a pair of plain numbers: the
                // step multiplies by it at a third of a jet product's cost.
                let d = match &line.dir {
                    DirRef::Fixed(v) => self.point_lit(*v),
                    body => self.dir(body, "line_dir", &mut pre),
                };
                let (r, k) = (self.slit(*r), self.index(*branch));
                quote! {
                    #marker
                    let #t = {
                        #(#pre)*
                        planar::circle_line(ctx, #id, #c, #r, #p, #d, &mut branches[#k], &mut last[#k])?
                    };
                }
            }
            StepKind::LineLine { out, a, b } => {
                let t = &self.temp(*out);
                let p1 = self.point(&a.through, &mut pre);
                let d1 = self.dir(&a.dir, "dir_a", &mut pre);
                let p2 = self.point(&b.through, &mut pre);
                let d2 = self.dir(&b.dir, "dir_b", &mut pre);
                quote! {
                    #marker
                    let #t = {
                        #(#pre)*
                        planar::line_line(ctx, #id, #p1, #d1, #p2, #d2)?
                    };
                }
            }
            StepKind::Cluster { params, rows, .. }
                if Self::fixed_cluster(step.kind.cluster_size().0, step.kind.cluster_size().1) =>
            {
                let size = step.kind.cluster_size();
                let code = if self.jets {
                    self.fixed_cluster_rates(&quote!(#id), params, rows, size)
                } else {
                    self.fixed_cluster_step(&quote!(#id), params, rows, size, &mut pre, false)
                };
                quote! {
                    #marker
                    {
                        #code
                    }
                }
            }
            StepKind::Cluster { params, rows, .. } => {
                self.dynamic_cluster_step(i, &id, &marker, params, rows, &mut pre)
            }
            StepKind::TurnLine {
                body,
                pivot,
                target,
                dir,
                kappa,
                branch,
            } => {
                let pv = self.point(pivot, &mut pre);
                let tg = self.point(target, &mut pre);
                let (b, d, kp, k) = (
                    self.pose(*body),
                    self.plit(*dir),
                    self.slit(*kappa),
                    self.index(*branch),
                );
                quote! {
                    #marker
                    {
                        #(#pre)*
                        #b.rot = planar::turn_line_through(ctx, #id, #pv, #tg, #d, #kp, &mut branches[#k], &mut last[#k])?;
                    }
                }
            }
        }
    }

    /// The constants naming each body and marker, and the state's marker
    /// reader, into `sink`; the two modules of constants a batch of
    /// constants at a time (a chain of 20,000 loops has 120,000 markers).
    fn names(&self, sink: &mut Sink<'_>) {
        let plan = self.plan;
        let body_names = names::constants(plan.bodies.iter().map(|b| b.name.as_str()));
        let bodies = (plan.bodies.iter().zip(&body_names).enumerate()).map(|(i, (b, c))| {
            let (doc, c, i) = (format!(" `{}`", b.name), format_ident!("{}", c), index(i));
            quote! {
                #[doc = #doc]
                pub const #c: usize = #i;
            }
        });
        let all_markers: Vec<(usize, String, [f64; 2])> = plan
            .bodies
            .iter()
            .enumerate()
            .flat_map(|(i, b)| {
                b.markers
                    .iter()
                    .map(move |(m, at)| (i, format!("{}.{m}", b.name), *at))
            })
            .collect();
        let marker_names = names::constants(all_markers.iter().map(|(_, n, _)| n.as_str()));
        let markers = all_markers.iter().zip(&marker_names).map(|((b, name, at), c)| {
            let doc = format!(" `{name}`");
            let (c, b, at) = (format_ident!("{}", c), index(*b), point_lit(*at));
            quote! {
                #[doc = #doc]
                pub const #c: Marker = Marker::new(#name, #b, #at);
            }
        });
        let use_marker = if all_markers.is_empty() {
            quote!()
        } else {
            quote!(
                use dofplan_runtime::Marker;
            )
        };
        sink.push_module(
            quote! {
                /// Each body's index in [`BODIES`] and [`State::poses`], by name:
                /// upper-cased, other characters than ASCII letters and digits
                /// made `_`, and `_2`, `_3`, … after a name an earlier body took.
                pub mod body
            },
            quote!(),
            bodies,
        );
        sink.push_module(
            quote! {
                /// Each marker's body and local coordinates (its drawn position),
                /// named `BODY_MARKER` by the rule of `body`; read one with
                /// `State::marker` or `Marker::world`.
                pub mod marker
            },
            use_marker,
            markers,
        );
        sink.push(quote! {
            impl State {
                /// The world position of marker `m` (a constant of
                /// [`marker`]) in this state.
                #[inline]
                pub fn marker(&self, m: Marker) -> Point {
                    m.world(&self.poses)
                }
            }
        });
    }

    /// Whether any step can break the frame (needs `ctx` and returns early).
    fn fallible(&self) -> bool {
        self.plan.steps.iter().any(|s| {
            matches!(
                s.kind,
                StepKind::CircleCircle { .. }
                    | StepKind::CircleLine { .. }
                    | StepKind::LineLine { .. }
                    | StepKind::TurnLine { .. }
                    | StepKind::Cluster { .. }
                    | StepKind::Align { redundant: true, .. }
            )
        })
    }

    /// The binding of input `k` to its local.
    fn bind_input(&self, k: usize) -> TokenStream {
        let id = &self.input_idents[k];
        let i = index(k);
        match self.plan.inputs[k].kind {
            InputKind::Angle if self.lanes => quote!(let #id = Rot::from_degrees_lanes(inputs[#i]);),
            InputKind::Angle if self.jets => quote!(let #id = Rot::from_degrees_jet(inputs[#i]);),
            InputKind::Angle => quote!(let #id = Rot::from_degrees(inputs[#i]);),
            InputKind::Slide => quote!(let #id = inputs[#i];),
        }
    }

    /// `solve` as one function: every mobile body's pose is a named local
    /// for the frame, written back at the end; fixed bodies are never
    /// copied.
    fn single_solve(&self, steps: Vec<TokenStream>, doc_solve: &str) -> TokenStream {
        let plan = self.plan;
        let written = self.written_bodies();
        let take_poses = written.iter().map(|&b| {
            let (id, i) = (&self.pose_idents[b], index(b));
            quote!(let mut #id = s.poses[#i];)
        });
        let commit_poses = written.iter().map(|&b| {
            let (id, i) = (&self.pose_idents[b], index(b));
            quote!(s.poses[#i] = #id;)
        });
        let (take, commit) = if plan.branches.is_empty() {
            (quote!(#(#take_poses)*), quote!(#(#commit_poses)*))
        } else {
            (
                quote!(#(#take_poses)* let mut last = s.last; let mut branches = s.branches;),
                quote!(#(#commit_poses)* s.last = last; s.branches = branches;),
            )
        };
        let bind_inputs = (0..plan.inputs.len()).map(|k| self.bind_input(k));
        let unused_ctx = if self.fallible() {
            quote!()
        } else {
            quote!(let _ = ctx;)
        };
        let unused_inputs = if plan.inputs.is_empty() {
            quote!(let _ = inputs;)
        } else {
            quote!()
        };
        quote! {
            #[doc = #doc_solve]
            #[inline]
            pub fn solve(s: &mut State, inputs: &[f64], ctx: &mut Ctx) -> Result<(), Break> {
                #unused_ctx
                #unused_inputs
                // Work on copies and commit at the end: a break (an early
                // return) leaves `s` as it was, so no caller has to copy the
                // state per frame to roll back.
                #take
                #(#bind_inputs)*
                #(#steps)*
                #commit
                Ok(())
            }
        }
    }

    /// The module up to `solve`: imports, names, `State`, the constants and
    /// `Plan` with its trait impls. `real`: whether the steps on jets or
    /// lanes lift constants (`Jet2::cst`, `Lanes::cst`, which need the
    /// `Real` trait); `lanes`: whether `solve_batch` runs in lanes.
    fn prefix(&self, real: bool, lanes: bool, sink: &mut Sink<'_>) {
        let plan = self.plan;
        let name = &plan.mechanism;
        let nb = index(plan.bodies.len());
        let nsteps = index(plan.steps.len());
        let nk = index(plan.branches.len());
        let ni = index(plan.inputs.len());
        let body_names = plan.bodies.iter().map(|b| &b.name);
        let input_names = plan.inputs.iter().map(|i| &i.name);
        let input_kinds = plan.inputs.iter().map(|i| match i.kind {
            InputKind::Angle => quote!(InputKind::Angle),
            InputKind::Slide => quote!(InputKind::Slide),
        });
        let fixed = plan.bodies.iter().map(|b| b.fixed);
        let drawn = plan.branches.iter().map(|b| point_lit(b.drawn));
        let initial = plan.branches.iter().map(|b| match b.initial {
            dofplan_runtime::Branch::Plus => quote!(Branch::Plus),
            dofplan_runtime::Branch::Minus => quote!(Branch::Minus),
        });
        let numeric_use = if plan.clusters() > 0 {
            quote!(
                use dofplan_runtime::numeric::{self, cluster};
            )
        } else {
            quote!()
        };
        let rate_methods = rates::rates_trait_methods(&quote!(Pose));
        // `Jet2::cst` and `Lanes::cst` need the trait (a plan of large clusters alone, whose
        // rates the runtime computes, has none).
        let real = if real { quote!(Real) } else { quote!() };
        let rates_use = quote!(
            use dofplan_runtime::real::{self, Jet2, RateError, #real};
            use dofplan_runtime::BranchPolicy;
        );
        let (lanes_use, batch_impl) = if lanes {
            (
                quote!(
                    use dofplan_runtime::lanes::Lanes;
                ),
                quote! {
                    /// Frames of a closed-form plan are independent: solved in
                    /// lanes, and on several cores by
                    /// `dofplan_runtime::batch::solve_batch_parallel`.
                    impl dofplan_runtime::Batch for Plan {
                        fn independent(&self) -> bool {
                            true
                        }

                        fn solve_batch(&self, inputs: &[f64], out: &mut [Pose], status: &mut [dofplan_runtime::FrameStatus]) {
                            self::solve_batch(inputs, out, status)
                        }

                        fn solve_frames(&self, inputs: &[f64], out: &mut [Pose], status: &mut [dofplan_runtime::FrameStatus]) {
                            self::solve_frames(inputs, out, status)
                        }
                    }
                },
            )
        } else {
            (
                quote!(),
                quote! {
                    /// Frames solved in order, each warm-started from the last.
                    impl dofplan_runtime::Batch for Plan {}
                },
            )
        };
        sink.push(quote! {
            use dofplan_runtime::planar::{self, Point, Pose, Rot};
            use dofplan_runtime::{Branch, Break, Ctx, Marker, Solver};
            #numeric_use
            #rates_use
            #lanes_use

            /// Kind of an input.
            pub use dofplan_runtime::planar::InputKind;

            /// The mechanism's name.
            pub const NAME: &str = #name;
            /// Body names, in the order of [`State::poses`].
            pub const BODIES: [&str; #nb] = [#(#body_names),*];
            /// Which bodies are fixed (ground).
            pub const FIXED: [bool; #nb] = [#(#fixed),*];
            /// Input names, in the order [`solve`] takes them.
            pub const INPUTS: [&str; #ni] = [#(#input_names),*];
            /// Input kinds (angles in degrees, slides in length units).
            pub const INPUT_KINDS: [InputKind; #ni] = [#(#input_kinds),*];
            /// Number of plan steps.
            pub const STEPS: usize = #nsteps;

            /// What a frame reads from the previous one and writes.
            #[derive(Clone, Copy, Debug, PartialEq)]
            pub struct State {
                /// Body poses, in [`BODIES`] order.
                pub poses: [Pose; #nb],
                /// Each branching step's last root (nearest-root policy).
                pub last: [Point; #nk],
                /// Each branching step's branch.
                pub branches: [Branch; #nk],
            }

            impl State {
                /// The drawn pose.
                pub const DRAWN: State = State {
                    poses: [Pose::IDENTITY; #nb],
                    last: [#(#drawn),*],
                    branches: [#(#initial),*],
                };
            }

        });
        self.names(sink);
        sink.push(quote! {

            /// The compiled plan, for [`dofplan_runtime::Driver`].
            #[derive(Clone, Copy, Debug, Default)]
            pub struct Plan;

            impl Solver for Plan {
                type Pose = Pose;
                type State = State;
                type Inputs = [f64; #ni];

                fn initial_state(&self) -> State {
                    State::DRAWN
                }

                fn initial_inputs(&self) -> [f64; #ni] {
                    [0.0; #ni]
                }

                fn poses(state: &State) -> &[Pose] {
                    &state.poses
                }

                fn solve(&self, s: &mut State, inputs: &[f64], ctx: &mut Ctx) -> Result<(), Break> {
                    solve(s, inputs, ctx)
                }
            }

            impl dofplan_runtime::real::Rates for Plan {
                #rate_methods
            }

            #batch_impl
        });
    }

    /// The doc comment of `solve`.
    fn doc_solve(&self) -> String {
        let plan = self.plan;
        format!(
            "Places every body for `inputs` ({}), warm-started from `s`. On a break `s` is left unchanged.",
            if plan.inputs.is_empty() {
                "none".to_string()
            } else {
                plan.inputs
                    .iter()
                    .map(|i| {
                        format!(
                            "{} in {}",
                            i.name,
                            match i.kind {
                                InputKind::Angle => "degrees",
                                InputKind::Slide => "length units",
                            }
                        )
                    })
                    .collect::<Vec<_>>()
                    .join(", ")
            }
        )
    }

    /// For each body, the last step that writes it (`None`: no step does).
    fn last_writes(&self) -> Vec<Option<usize>> {
        let mut last = vec![None; self.plan.bodies.len()];
        for (i, step) in self.plan.steps.iter().enumerate() {
            for b in step.kind.writes() {
                last[b] = Some(i);
            }
        }
        last
    }

    /// The mobile bodies some step writes: each is a named local during a
    /// frame, read from the state first and written back at the end.
    fn written_bodies(&self) -> Vec<usize> {
        let last = self.last_writes();
        (0..self.plan.bodies.len())
            .filter(|&b| !self.plan.bodies[b].fixed && last[b].is_some())
            .collect()
    }

    /// The state's last roots lifted to `real` (`Jet2` or `Lanes`), slot by
    /// slot rather than by `s.last.map(..)`, which stays a call: in a plan
    /// of a few steps that call is a fifth of a frame on jets, and on lanes
    /// (which only write `last`, under keep-branch) the stores into an
    /// array nothing reads are then dropped.
    fn lifted_last(&self, real: TokenStream) -> TokenStream {
        let k = (0..self.plan.branches.len()).map(index);
        quote!([#(planar::cst::<#real>(s.last[#k])),*])
    }

    /// The steps with each placed body's working pose (on `real`: `Jet2`
    /// or `Lanes`) declared just before the first step that names it, not
    /// all at the top: their lifetimes then overlap little, so the compiler
    /// can give them the same stack slots (a chain of 50 bodies otherwise
    /// keeps 12.8 KB of lanes alive, and its stack frame no longer fits the
    /// data cache). `after(i)` follows step `i`.
    fn declared_late(
        &self,
        steps: Vec<TokenStream>,
        real: TokenStream,
        after: impl Fn(usize) -> TokenStream,
    ) -> Vec<TokenStream> {
        let uses: Vec<uses::Uses> = steps.iter().map(uses::Uses::of).collect();
        let first_use: Vec<(usize, usize)> = self
            .written_bodies()
            .into_iter()
            .filter_map(|b| {
                let id = self.pose_idents[b].to_string();
                uses.iter().position(|u| u.has(&id)).map(|i| (b, i))
            })
            .collect();
        steps
            .into_iter()
            .enumerate()
            .map(|(i, step)| {
                let takes = first_use.iter().filter(|&&(_, f)| f == i).map(|&(b, _)| {
                    let (id, k) = (&self.pose_idents[b], index(b));
                    quote!(let mut #id = Pose::<#real>::cst(s.poses[#k]);)
                });
                let after = after(i);
                quote!(#(#takes)* #step #after)
            })
            .collect()
    }

    /// `solve_rates`: a frame and its rates in one pass on jets (their
    /// values are `solve`'s, the same operations on the same numbers),
    /// committed to `s` as `solve` commits.
    fn solve_rates_fn(&self, steps: Vec<TokenStream>) -> TokenStream {
        let plan = self.plan;
        let written = self.written_bodies();
        let steps = self.declared_late(steps, quote!(Jet2), |_| quote!());
        let commit = written.iter().map(|&b| {
            let (id, i) = (&self.pose_idents[b], index(b));
            quote!(s.poses[#i] = #id.value();)
        });
        let out = (0..plan.bodies.len()).map(|b| {
            let i = index(b);
            if written.contains(&b) {
                let id = &self.pose_idents[b];
                quote!(out[#i] = #id;)
            } else {
                quote!(out[#i] = Pose::<Jet2>::cst(s.poses[#i]);)
            }
        });
        let (take_branches, commit_branches) = if plan.branches.is_empty() {
            (quote!(), quote!())
        } else {
            let last = self.lifted_last(quote!(Jet2));
            let k = (0..plan.branches.len()).map(index);
            (
                quote!(let mut last = #last; let mut branches = s.branches;),
                quote!(#(s.last[#k] = [last[#k][0].v, last[#k][1].v];)* s.branches = branches;),
            )
        };
        let bind_inputs = (0..plan.inputs.len()).map(|k| self.bind_input(k));
        let (nb, ni) = (index(plan.bodies.len()), index(plan.inputs.len()));
        let body = quote! {
            let inputs: [Jet2; #ni] =
                core::array::from_fn(|k| Jet2::new(inputs[k], rates[k], accelerations[k]));
            let _ = (&inputs, &ctx);
            #take_branches
            #(#bind_inputs)*
            #(#steps)*
            #(#commit)*
            #commit_branches
            #(#out)*
            real::checked(&*out).map(|_| ())
        };
        rates::rates_functions(&quote!(Pose), &nb, body)
    }

    /// `solve_lanes`: [`LANES`](dofplan_runtime::lanes::LANES) frames at
    /// once from the drawn pose (keep-branch, no stretching), for
    /// `solve_batch`.
    fn solve_lanes_fn(&self, steps: Vec<TokenStream>) -> TokenStream {
        let plan = self.plan;
        let written = self.written_bodies();
        // Each body goes to the rows right after the last step that places
        // it; the bodies no step places (ground, idle ones), first.
        let last_write = self.last_writes();
        let put = |b: usize| {
            let i = index(b);
            if written.contains(&b) {
                let id = &self.pose_idents[b];
                quote!(dofplan_runtime::batch::put_body(&#id, rows, #i);)
            } else {
                quote!(dofplan_runtime::batch::put_body(&Pose::<Lanes>::cst(s.poses[#i]), rows, #i);)
            }
        };
        let unplaced = (0..plan.bodies.len()).filter(|&b| !written.contains(&b)).map(put);
        let steps = self.declared_late(steps, quote!(Lanes), |i| {
            let puts = (0..plan.bodies.len())
                .filter(|&b| written.contains(&b) && last_write[b] == Some(i))
                .map(put);
            quote!(#(#puts)*)
        });
        let take_branches = if plan.branches.is_empty() {
            quote!()
        } else {
            let last = self.lifted_last(quote!(Lanes));
            quote!(let mut last = #last; let mut branches = s.branches;)
        };
        let bind_inputs = (0..plan.inputs.len()).map(|k| self.bind_input(k));
        let (nb, ni) = (index(plan.bodies.len()), index(plan.inputs.len()));
        quote! {
        /// [`solve`] of [`LANES`](dofplan_runtime::lanes::LANES) frames
        /// side by side (lane `l` of every input is frame `l`'s; frame
        /// `l`'s poses go to `rows[l]`, each body's as soon as its last
        /// step has placed it), each
        /// from the drawn pose under keep-branch: the frames of a
        /// closed-form plan do not depend on each other. A break in any
        /// frame, or frames that part ways at a step
        /// ([`BreakKind::LanesDiffer`](dofplan_runtime::BreakKind::LanesDiffer)),
        /// is an error for all of them: [`solve_batch`] then solves
        /// them one at a time.
        #[inline(always)]
        pub fn solve_lanes(inputs: &[Lanes; #ni], rows: &mut [[Pose; #nb]; dofplan_runtime::lanes::LANES]) -> Result<(), Break> {
            let s = &State::DRAWN;
            let ctx = &mut Ctx::new(dofplan_runtime::BranchPolicy::Keep, false);
            let _ = (&inputs, &ctx);
            #(#unplaced)*
            #take_branches
            #(#bind_inputs)*
            #(#steps)*
            Ok(())
        }

        /// Every frame of `inputs` (one row of [`INPUTS`] values a
        /// frame) into `out` (one row of [`BODIES`] poses a frame),
        /// with the driver's results (keep-branch and limit policies,
        /// from the drawn pose) in `status`:
        /// [`LANES`](dofplan_runtime::lanes::LANES) frames at a time
        /// through [`solve_lanes`].
        ///
        /// # Panics
        /// If `inputs` or `out` is not `status.len()` rows long.
        pub fn solve_batch(inputs: &[f64], out: &mut [Pose], status: &mut [dofplan_runtime::FrameStatus]) {
            solve_frames(inputs, out, status);
            dofplan_runtime::batch::settle(&Plan, inputs, out, status)
        }

        /// Every frame of `inputs` on its own, from the drawn pose, as
        /// [`solve_batch`] solves them before the holds past limits
        /// (`dofplan_runtime::batch::settle`).
        ///
        /// # Panics
        /// If `inputs` or `out` is not `status.len()` rows long.
        pub fn solve_frames(inputs: &[f64], out: &mut [Pose], status: &mut [dofplan_runtime::FrameStatus]) {
            #[cfg(target_arch = "x86_64")]
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: this CPU has AVX2, checked just above.
                return unsafe { solve_batch_avx2(inputs, out, status) };
            }
            solve_batch_baseline(inputs, out, status)
        }

        /// [`solve_frames`] for any CPU. Its own function, as the AVX2
        /// one is, so that `solve_frames` does not hold a frame of lane
        /// temporaries on the stack beside the one it calls (unoptimised
        /// builds give every temporary a slot of its own).
        #[inline(never)]
        fn solve_batch_baseline(inputs: &[f64], out: &mut [Pose], status: &mut [dofplan_runtime::FrameStatus]) {
            batch_in_lanes(inputs, out, status)
        }

        /// [`solve_frames`] compiled for AVX2: a lane group in two
        /// registers instead of four. The same operations in the same
        /// order (no fused multiply-add), so the same numbers.
        ///
        /// # Safety
        /// The CPU must have AVX2.
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx2")]
        unsafe fn solve_batch_avx2(inputs: &[f64], out: &mut [Pose], status: &mut [dofplan_runtime::FrameStatus]) {
            batch_in_lanes(inputs, out, status)
        }

        /// The lane groups through [`solve_lanes`], the rest one frame
        /// at a time (see `dofplan_runtime::batch::lane_groups`).
        #[inline(always)]
        fn batch_in_lanes(inputs: &[f64], out: &mut [Pose], status: &mut [dofplan_runtime::FrameStatus]) {
            use dofplan_runtime::batch;
            let groups = batch::lane_groups(&Plan, inputs, out, status);
            for g in 0..groups {
                match solve_lanes(&batch::group_inputs(inputs, g), batch::group_rows(out, g)) {
                    // A group that does not finish leaves its rows partly
                    // written: solving its frames one at a time rewrites
                    // them (and `settle` holds those that break).
                    Ok(()) => batch::solved(status, g),
                    Err(_) => {
                        let lanes = dofplan_runtime::lanes::LANES;
                        batch::one_at_a_time(&Plan, g * lanes..(g + 1) * lanes, inputs, out, status)
                    }
                }
            }
            batch::finish(&Plan, groups * dofplan_runtime::lanes::LANES, inputs, out, status);
        }        }
    }
}

/// Rust source of the compiled plan module of `plan`.
pub fn emit(plan: &Plan) -> String {
    emit_chunked(plan, CHUNK_WEIGHT)
}

/// [`emit`] with functions of at most `chunk_weight` tokens of steps
/// instead of [`CHUNK_WEIGHT`] (1 puts every step in a function of its
/// own: tests use it to check the split form on small mechanisms).
pub fn emit_chunked(plan: &Plan, chunk_weight: usize) -> String {
    let mut used = std::collections::HashSet::new();
    let mut unique = |base: String| {
        let mut name = base.clone();
        let mut n = 2;
        while !used.insert(name.clone()) {
            name = format!("{base}_{n}");
            n += 1;
        }
        Ident::new(&name, Span::call_site())
    };
    let input_idents = plan
        .inputs
        .iter()
        .map(|i| unique(format!("input_{}", ident_for(&i.name))))
        .collect();
    let temp_idents = plan
        .temps
        .iter()
        .map(|t| unique(format!("at_{}", ident_for(&t.name))))
        .collect();
    let pose_idents = plan
        .bodies
        .iter()
        .map(|b| unique(format!("pose_{}", ident_for(&b.name))))
        .collect();
    let mut e = Emitter {
        plan,
        input_idents,
        temp_idents,
        pose_idents,
        chunked: false,
        jets: false,
        lanes: false,
        row: Default::default(),
        temp_steps: chunk::temp_steps(plan),
        tables: Default::default(),
    };
    // Each step's code is made to be measured and then dropped: a large
    // plan's steps are made again, chunk by chunk, as they are written.
    let kinds: Vec<&StepKind> = plan.steps.iter().map(|s| &s.kind).collect();
    let mut uses: Vec<uses::Uses> = (0..plan.steps.len())
        .map(|i| uses::Uses::of(&e.step(i)))
        .collect();
    let weights: Vec<usize> = uses.iter().map(|u| u.weight).collect();
    let chunks = chunk::partition(&kinds, &weights, chunk_weight, || e.runs());
    let mut sink = Sink::new(plan);
    let doc_solve = e.doc_solve();
    match chunks {
        None => {
            let steps: Vec<TokenStream> = (0..plan.steps.len()).map(|i| e.step(i)).collect();
            // The steps again on jets, in one function.
            e.jets = true;
            let jet_steps: Vec<TokenStream> = (0..plan.steps.len()).map(|i| e.step(i)).collect();
            let fused = e.solve_rates_fn(jet_steps);
            e.jets = false;
            // The steps on lanes of frames, for `solve_batch`: only
            // closed-form plans, whose frames do not depend on each other
            // (a cluster's Newton solve starts from the last frame's pose).
            let lanes = (plan.clusters() == 0).then(|| {
                e.jets = true;
                e.lanes = true;
                let lane_steps: Vec<TokenStream> = (0..plan.steps.len()).map(|i| e.step(i)).collect();
                let lanes = e.solve_lanes_fn(lane_steps);
                e.lanes = false;
                e.jets = false;
                lanes
            });
            let lane_code = lanes.as_ref().map(|l| l.to_string()).unwrap_or_default();
            let real = fused.to_string().contains("Jet2 :: cst") || lane_code.contains("Lanes :: cst");
            e.prefix(real, lanes.is_some(), &mut sink);
            sink.push(e.single_solve(steps, &doc_solve));
            sink.push(fused);
            if let Some(lanes) = lanes {
                sink.push(lanes);
            }
        }
        Some(chunks) => {
            e.chunked = true;
            for (i, kind) in kinds.iter().enumerate() {
                if chunk::starts_chunk(kind) {
                    uses[i] = uses::Uses::of(&e.step(i));
                }
            }
            // The steps on jets, in the same chunks as `solve`: measured
            // here, made again as their functions are written.
            e.jets = true;
            let mut real = false;
            let jet_uses: Vec<uses::Uses> = (0..plan.steps.len())
                .map(|i| {
                    let code = e.step(i);
                    real |= code.to_string().contains("Jet2 :: cst");
                    uses::Uses::of(&code)
                })
                .collect();
            e.jets = false;
            e.prefix(real, false, &mut sink);
            e.chunked_solve(uses, &chunks, &doc_solve, &mut sink);
            e.jets = true;
            e.chunked_solve(jet_uses, &chunks, "", &mut sink);
        }
    }
    sink.out
}

/// Constants of `body` and `marker` laid out at a time.
const NAMES_BATCH: usize = 1000;

/// The generated module's text, written item by item: each item is parsed
/// by `syn` and laid out by `prettyplease` as soon as it is made, so that
/// only one item's tokens and syntax tree are held at a time.
struct Sink<'p> {
    plan: &'p Plan,
    /// Each step's explanation, made once: `Plan::explain` alone looks up
    /// the steps a step reads by scanning the plan.
    explanations: Vec<String>,
    out: String,
}

impl<'p> Sink<'p> {
    /// The module's header comment.
    fn new(plan: &'p Plan) -> Sink<'p> {
        let out = format!(
            "// @generated by dofplan from {} — do not edit.\n// Compiled plan of mechanism `{}`: {} steps, {} branch slots.\n// Regenerate with `dofplan emit {}` or by rebuilding the crate that compiles it.\n\n",
            plan.source,
            plan.mechanism,
            plan.steps.len(),
            plan.branches.len(),
            plan.source
        );
        Sink {
            plan,
            explanations: plan.explanations(),
            out,
        }
    }

    /// Appends the module `head { first items }` (`head`: its attributes,
    /// visibility and name), laid out as one item would be, but parsed
    /// and laid out [`NAMES_BATCH`] items at a time.
    fn push_module(
        &mut self,
        head: TokenStream,
        first: TokenStream,
        items: impl Iterator<Item = TokenStream>,
    ) {
        let mut items = items.peekable();
        let batch: Vec<TokenStream> = items.by_ref().take(NAMES_BATCH).collect();
        if items.peek().is_none() {
            return self.push(quote!(#head { #first #(#batch)* }));
        }
        // The module's first lines, up to its closing brace; then each
        // further batch in a stand-in module, which lays its items out at
        // the same depth, without that module's first and last lines.
        let text = Self::lay_out(quote!(#head { #first #(#batch)* }));
        self.out
            .push_str(text.strip_suffix("}\n").expect("a module ends with its brace"));
        while items.peek().is_some() {
            let batch = items.by_ref().take(NAMES_BATCH);
            let text = Self::lay_out(quote!(mod batch { #(#batch)* }));
            let inner = text
                .strip_prefix("mod batch {\n")
                .and_then(|t| t.strip_suffix("}\n"))
                .expect("a module of items");
            self.out.push_str(inner);
        }
        self.out.push_str("}\n");
    }

    /// The items of `tokens` laid out by prettyplease.
    fn lay_out(tokens: TokenStream) -> String {
        let file = syn::parse2::<syn::File>(tokens).expect("the emitter produces valid Rust");
        prettyplease::unparse(&file)
    }

    /// Appends the items of `tokens`, laid out, with `rows` (a rolled
    /// run's table, a row a line) in place of their `__dofplan_rows!()`.
    fn push_with_rows(&mut self, tokens: TokenStream, rows: &str) {
        let pretty = Self::lay_out(tokens);
        let (before, after) = pretty
            .split_once("__dofplan_rows!()")
            .expect("a rolled run's module holds its table");
        let indent = before
            .rsplit('\n')
            .next()
            .map_or(0, |line| line.len() - line.trim_start().len());
        let mut text = String::with_capacity(pretty.len() + rows.len() + rows.len() / 40 * (indent + 4));
        text.push_str(before);
        text.push_str("[\n");
        for row in rows.lines() {
            text.extend(std::iter::repeat_n(' ', indent + 4));
            text.push_str(row);
            text.push('\n');
        }
        text.extend(std::iter::repeat_n(' ', indent));
        text.push(']');
        text.push_str(after);
        self.push_laid_out(&text);
    }

    /// Appends the items of `tokens`, laid out.
    fn push(&mut self, tokens: TokenStream) {
        let pretty = Self::lay_out(tokens);
        self.push_laid_out(&pretty);
    }

    /// Appends laid-out items, each step's mark replaced by its comment.
    fn push_laid_out(&mut self, pretty: &str) {
        // Comments are not tokens: each step was marked by a macro call
        // that is replaced here by the step's explanation.
        for line in pretty.lines() {
            let trimmed = line.trim_start();
            if let Some(rest) = trimmed.strip_prefix("__dofplan_step!(") {
                let indent = &line[..line.len() - trimmed.len()];
                let i: usize = rest.trim_end_matches(");").parse().expect("step marker");
                let step = &self.plan.steps[i];
                let serves = if step.serves.is_empty() {
                    String::new()
                } else {
                    format!("  [{}]", step.serves.join(", "))
                };
                let _ = writeln!(self.out, "{indent}// {i}: {}{serves}", self.explanations[i]);
            } else {
                self.out.push_str(line);
                self.out.push('\n');
            }
        }
    }
}
