//! A numeric cluster step as straight-line code: the compiler
//! differentiates the cluster's primitive equations symbolically — it knows
//! at build time which unknown every world point, direction and angle
//! depends on — and writes the residuals and the non-zero Jacobian entries
//! out one by one, over fixed-size `nalgebra` matrices, so a frame's Newton
//! solve allocates nothing.
//!
//! The arithmetic of each entry is a call of the same runtime primitive
//! (`cluster::pinned_pose`, `cluster::turn`, `cluster::in_line`, …) that the
//! interpreter's `cluster::System` calls in a loop over the plan's data.

use proc_macro2::TokenStream;
use quote::{format_ident, quote};

use super::{index, lit, point_lit, Emitter};
use crate::model::InputKind;
use crate::plan::{ClusterParam, ClusterRow, DirRef};

/// Clusters larger than this (unknowns or equations) are solved by the
/// runtime's dynamically sized `cluster::solve` instead: fixed-size
/// matrices live on the stack, and `nalgebra`'s fixed sizes end at 127.
pub const FIXED_LIMIT: usize = 64;

/// One term of a world point's derivative with respect to one unknown.
enum Term {
    /// `[1, 0]` (a translation unknown's x).
    UnitX,
    /// `[0, 1]` (a translation unknown's y).
    UnitY,
    /// A slide's world direction (a local of the step).
    Dir(TokenStream),
    /// `cluster::turn(pose, v, SIZE)`: an angle unknown turning the point
    /// `v` (local, from the pivot; an expression) of the body whose pose
    /// this is.
    Turn(TokenStream, TokenStream),
}

/// A marker's local position: drawn, or carried along a slide input (a
/// local of the step, known only at run time).
enum Local {
    Drawn([f64; 2]),
    Slid(TokenStream),
}

impl Local {
    /// `self − pin` as an expression (folded for a drawn marker).
    fn from(&self, pin: [f64; 2]) -> TokenStream {
        match self {
            Local::Drawn(q) => point_lit(diff(*q, pin)),
            Local::Slid(q) if pin == [0.0, 0.0] => q.clone(),
            Local::Slid(q) => {
                let (px, py) = (lit(pin[0]), lit(pin[1]));
                quote!([#q[0] - #px, #q[1] - #py])
            }
        }
    }
}

impl Term {
    fn tokens(&self) -> TokenStream {
        match self {
            Term::UnitX => quote!([1.0, 0.0]),
            Term::UnitY => quote!([0.0, 1.0]),
            Term::Dir(d) => d.clone(),
            Term::Turn(pose, v) => quote!(cluster::turn(#pose, #v, SIZE)),
        }
    }
}

/// The cluster's params with their first unknowns.
struct Layout<'a> {
    params: &'a [ClusterParam],
    offsets: Vec<usize>,
}

impl Layout<'_> {
    fn of(&self, body: usize) -> Option<(usize, &ClusterParam)> {
        let k = self.params.iter().position(|p| p.body() == body)?;
        Some((self.offsets[k], &self.params[k]))
    }

    /// The unknown turning `body`, if any.
    fn angle(&self, body: usize) -> Option<usize> {
        match self.of(body)? {
            (o, ClusterParam::Free { .. }) => Some(o + 2),
            (o, ClusterParam::Angle { .. } | ClusterParam::Hinge { .. }) => Some(o),
            _ => None,
        }
    }
}

fn diff(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

impl Emitter<'_> {
    /// Whether the cluster is written as fixed-size straight-line code.
    pub(super) fn fixed_cluster(n: usize, m: usize) -> bool {
        n.max(m) <= FIXED_LIMIT
    }

    /// The unknowns the world point of local `q` on `body` depends on, with
    /// the derivative's term (a hinge's point also moves with its parent's
    /// unknowns, recursively).
    fn terms(&self, layout: &Layout, body: usize, q: &Local, out: &mut Vec<(usize, Term)>) {
        let Some((o, p)) = layout.of(body) else { return };
        let pose = self.pose(body);
        match p {
            ClusterParam::Free { .. } => {
                out.push((o, Term::UnitX));
                out.push((o + 1, Term::UnitY));
                out.push((o + 2, Term::Turn(pose, q.from([0.0, 0.0]))));
            }
            ClusterParam::Angle { pin, .. } => out.push((o, Term::Turn(pose, q.from(*pin)))),
            ClusterParam::Hinge { pin, parent, at, .. } => {
                out.push((o, Term::Turn(pose, q.from(*pin))));
                self.terms(layout, *parent, &Local::Drawn(*at), out);
            }
            ClusterParam::Slide { .. } => {
                let d = format_ident!("slide_dir_{}", body);
                out.push((o, Term::Dir(quote!(#d))));
            }
            ClusterParam::Translate { .. } => {
                out.push((o, Term::UnitX));
                out.push((o + 1, Term::UnitY));
            }
        }
    }

    /// The pieces of a cluster's straight-line code: on `f64`s, or on jets
    /// (whose Jacobian and warm start are not used: the rates take the
    /// values' Jacobian at the solution).
    fn cluster_code(
        &self,
        params: &[ClusterParam],
        rows: &[ClusterRow],
        pre: &mut Vec<TokenStream>,
    ) -> ClusterCode {
        let mut offsets = Vec::with_capacity(params.len());
        let mut o = 0;
        for p in params {
            offsets.push(o);
            o += p.count();
        }
        let layout = Layout { params, offsets };
        let mut code = ClusterCode {
            warm: Vec::new(),
            place: Vec::new(),
            residuals: Vec::new(),
            jacobian: Vec::new(),
        };
        self.placing(&layout, pre, &mut code);
        // Residuals, then the Jacobian's non-zero entries.
        let mut row = 0;
        for (k, r) in rows.iter().enumerate() {
            row += match *r {
                ClusterRow::Coincident { .. } => self.coincident_row(&layout, (k, row), r, pre, &mut code),
                ClusterRow::InLine { .. } => self.in_line_row(&layout, row, r, &mut code),
                ClusterRow::OnCircle { .. } => self.on_circle_row(&layout, row, r, &mut code),
                ClusterRow::Parallel { .. } => self.parallel_row(&layout, row, r, &mut code),
            };
        }
        code
    }

    /// Before the solve: where each pinned body is pinned, each slide's
    /// direction and base, and the warm start read from the standing pose;
    /// then each body's placement from the unknowns (a hinge's parent
    /// first, as the params come).
    fn placing(&self, layout: &Layout, pre: &mut Vec<TokenStream>, code: &mut ClusterCode) {
        let (warm, place) = (&mut code.warm, &mut code.place);
        for (k, p) in layout.params.iter().enumerate() {
            let b = p.body();
            let pose = self.pose(b);
            let o = layout.offsets[k];
            let x = |i: usize| {
                let i = index(o + i);
                quote!(x[#i])
            };
            let (x0, x1, x2) = (x(0), x(1), x(2));
            let base = format_ident!("base_{}", b);
            match p {
                ClusterParam::Free { .. } => {
                    warm.push(quote!(#pose.at[0], #pose.at[1], cluster::scaled_angle(#pose, SIZE)));
                    place.push((pose, quote!(cluster::free_pose(#x0, #x1, #x2, SIZE))));
                }
                ClusterParam::Angle { pin, at, .. } => {
                    let at = self.point(at, pre);
                    let pin = self.plit(*pin);
                    warm.push(quote!(cluster::scaled_angle(#pose, SIZE)));
                    place.push((pose, quote!(cluster::pinned_pose(#x0, SIZE, #pin, #at))));
                }
                ClusterParam::Hinge { pin, parent, at, .. } => {
                    let parent = self.pose(*parent);
                    let (pin, at) = (self.plit(*pin), self.point_lit(*at));
                    warm.push(quote!(cluster::scaled_angle(#pose, SIZE)));
                    place.push((
                        pose,
                        quote!(cluster::pinned_pose(#x0, SIZE, #pin, #parent.world(#at))),
                    ));
                }
                ClusterParam::Slide { dir, .. } => {
                    // Bound to `slide_dir_<body>` whatever its source: the
                    // Jacobian's terms name it.
                    let name = format!("slide_dir_{b}");
                    let id = format_ident!("{}", name);
                    match dir {
                        DirRef::Fixed(v) => {
                            let v = self.plit(*v);
                            pre.push(quote!(let #id = #v;));
                        }
                        DirRef::Body { .. } => {
                            self.dir(dir, &name, pre);
                        }
                    }
                    pre.push(quote!(let #base = #pose;));
                    warm.push(quote!(0.0));
                    place.push((pose, quote!(cluster::slide_pose(#base, #id, #x0))));
                }
                ClusterParam::Translate { .. } => {
                    pre.push(quote!(let #base = #pose;));
                    warm.push(quote!(#pose.at[0], #pose.at[1]));
                    place.push((pose, quote!(cluster::translate_pose(#base, #x0, #x1))));
                }
            }
        }
    }

    /// A coincident row pair (`k`th row, first residual `row`): the two
    /// markers' world points differ by nothing. Returns its row count.
    fn coincident_row(
        &self,
        layout: &Layout,
        (k, row): (usize, usize),
        r: &ClusterRow,
        pre: &mut Vec<TokenStream>,
        code: &mut ClusterCode,
    ) -> usize {
        let ClusterRow::Coincident { a, la, slide, b, lb } = *r else {
            unreachable!("a coincident row")
        };
        let (i, i1) = (index(row), index(row + 1));
        let (pa, pb) = (self.pose(a), self.pose(b));
        // A slid marker moves with `a` like any of its points,
        // at its slid position: the slide is an input, not an
        // unknown.
        let (la_tokens, la_local) = match slide {
            Some((input, d)) => {
                let name = format_ident!("slid_{}", k);
                let u = &self.input_idents[input];
                let (lx, ly, dx, dy) = (
                    self.slit(la[0]),
                    self.slit(la[1]),
                    self.slit(d[0]),
                    self.slit(d[1]),
                );
                pre.push(quote!(let #name = [#lx + #u * #dx, #ly + #u * #dy];));
                (quote!(#name), Local::Slid(quote!(#name)))
            }
            // A marker's local position: a constant of its body, a plain
            // number even on jets (`Pose::world`).
            None => (self.point_lit(la), Local::Drawn(la)),
        };
        let lb_tokens = self.point_lit(lb);
        code.residuals.push(quote! {
            let p = #pa.world(#la_tokens);
            let q = #pb.world(#lb_tokens);
            r[#i] = p[0] - q[0];
            r[#i1] = p[1] - q[1];
        });
        let mut terms = Vec::new();
        self.terms(layout, a, &la_local, &mut terms);
        code.jacobian.extend(
            terms
                .drain(..)
                .map(|(col, t)| coincident_entry(row, col, &t, true)),
        );
        self.terms(layout, b, &Local::Drawn(lb), &mut terms);
        code.jacobian.extend(
            terms
                .drain(..)
                .map(|(col, t)| coincident_entry(row, col, &t, false)),
        );
        2
    }

    /// An in-line row: marker `lb` of `b` on the line of `a` through `la`
    /// along `dir`. Returns its row count.
    fn in_line_row(&self, layout: &Layout, row: usize, r: &ClusterRow, code: &mut ClusterCode) -> usize {
        let ClusterRow::InLine { a, la, dir, b, lb } = *r else {
            unreachable!("an in-line row")
        };
        let i = index(row);
        let (pa, pb) = (self.pose(a), self.pose(b));
        let (la_t, lb_t, dir_t) = (self.point_lit(la), self.point_lit(lb), self.plit(dir));
        let (d, v) = (format_ident!("d_{}", row), format_ident!("v_{}", row));
        let turns = layout.angle(a);
        let v_bind = if turns.is_some() && !self.jets {
            quote!(#v)
        } else {
            quote!(_)
        };
        code.residuals.push(quote! {
            let #d = #pa.world_dir(#dir_t);
            let (residual, #v_bind) = cluster::in_line(#d, #pa.world(#la_t), #pb.world(#lb_t));
            r[#i] = residual;
        });
        let mut terms = Vec::new();
        self.terms(layout, b, &Local::Drawn(lb), &mut terms);
        for (col, t) in terms.drain(..) {
            let (c, t) = (index(col), t.tokens());
            code.jacobian.push(quote!(j[(#i, #c)] += cluster::cross(#d, #t);));
        }
        self.terms(layout, a, &Local::Drawn(la), &mut terms);
        for (col, t) in terms.drain(..) {
            let (c, t) = (index(col), t.tokens());
            code.jacobian.push(quote!(j[(#i, #c)] -= cluster::cross(#d, #t);));
        }
        if let Some(col) = turns {
            let c = index(col);
            code.jacobian
                .push(quote!(j[(#i, #c)] += cluster::line_turn(#d, #v, SIZE);));
        }
        1
    }

    /// An on-circle row: marker `lb` of `b` at distance `r` from `a`'s
    /// `la` (a pin in an arc slot). Returns its row count.
    fn on_circle_row(&self, layout: &Layout, row: usize, r: &ClusterRow, code: &mut ClusterCode) -> usize {
        let ClusterRow::OnCircle {
            a,
            la,
            r: radius,
            b,
            lb,
        } = *r
        else {
            unreachable!("an on-circle row")
        };
        let i = index(row);
        let (pa, pb) = (self.pose(a), self.pose(b));
        let (la_t, lb_t, radius) = (self.point_lit(la), self.point_lit(lb), self.lit(radius));
        let u = format_ident!("u_{}", row);
        let u_bind = if self.jets { quote!(_) } else { quote!(#u) };
        code.residuals.push(quote! {
            let (residual, #u_bind) = cluster::on_circle(#pa.world(#la_t), #pb.world(#lb_t), #radius);
            r[#i] = residual;
        });
        let mut terms = Vec::new();
        self.terms(layout, b, &Local::Drawn(lb), &mut terms);
        for (col, t) in terms.drain(..) {
            let (c, t) = (index(col), t.tokens());
            code.jacobian.push(quote!(j[(#i, #c)] += cluster::dot(#u, #t);));
        }
        self.terms(layout, a, &Local::Drawn(la), &mut terms);
        for (col, t) in terms.drain(..) {
            let (c, t) = (index(col), t.tokens());
            code.jacobian.push(quote!(j[(#i, #c)] -= cluster::dot(#u, #t);));
        }
        1
    }

    /// A parallel row: `b`'s rotation is `a`'s turned by the input (or
    /// equal). Returns its row count.
    fn parallel_row(&self, layout: &Layout, row: usize, r: &ClusterRow, code: &mut ClusterCode) -> usize {
        let ClusterRow::Parallel { a, b, input } = *r else {
            unreachable!("a parallel row")
        };
        let i = index(row);
        let (pa, pb) = (self.pose(a), self.pose(b));
        let rel = match input {
            Some(u) => {
                let u = &self.input_idents[u];
                quote!(#u)
            }
            None if self.jets => quote!(Rot::cst(Rot::IDENTITY)),
            None => quote!(Rot::IDENTITY),
        };
        let slope = format_ident!("slope_{}", row);
        let (ta, tb) = (layout.angle(a), layout.angle(b));
        let bind = if (ta.is_some() || tb.is_some()) && !self.jets {
            quote!(#slope)
        } else {
            quote!(_)
        };
        code.residuals.push(quote! {
            let (residual, #bind) = cluster::parallel(#pa.rot, #rel, #pb.rot, SIZE);
            r[#i] = residual;
        });
        if let Some(col) = tb {
            let c = index(col);
            code.jacobian.push(quote!(j[(#i, #c)] += #slope;));
        }
        if let Some(col) = ta {
            let c = index(col);
            code.jacobian.push(quote!(j[(#i, #c)] -= #slope;));
        }
        1
    }

    /// A numeric cluster too large for fixed-size matrices: the runtime's
    /// dynamically sized solver, which allocates (`cluster::solve`, or
    /// `cluster::solve_rates` on jets: solved on the values as `solve`
    /// does, then differentiated by the implicit function theorem).
    ///
    /// `id` and `marker` are the step's number and comment as `step` wrote
    /// them (written once: a rolled run records what it writes).
    pub(super) fn dynamic_cluster_step(
        &self,
        i: usize,
        id: &TokenStream,
        marker: &TokenStream,
        params: &[ClusterParam],
        rows: &[ClusterRow],
        pre: &mut Vec<TokenStream>,
    ) -> TokenStream {
        let step = &self.plan.steps[i];
        let (n, m) = step.kind.cluster_size();
        let param_tokens: Vec<TokenStream> = params
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let b = index(p.body());
                match p {
                    ClusterParam::Free { .. } => quote!(cluster::Param::Free { body: #b }),
                    ClusterParam::Angle { pin, at, .. } => {
                        let at = self.point(at, pre);
                        // The pin is local: constants either way.
                        let pin = point_lit(*pin);
                        quote!(cluster::Param::Angle { body: #b, pin: #pin, at: #at })
                    }
                    ClusterParam::Hinge { pin, parent, at, .. } => {
                        let (pin, parent, at) = (point_lit(*pin), index(*parent), point_lit(*at));
                        quote!(cluster::Param::Hinge { body: #b, pin: #pin, parent: #parent, at: #at })
                    }
                    ClusterParam::Slide { dir, .. } => {
                        let d = self.dir(dir, &format!("slide_dir_{k}"), pre);
                        quote!(cluster::Param::Slide { body: #b, dir: #d })
                    }
                    ClusterParam::Translate { .. } => quote!(cluster::Param::Translate { body: #b }),
                }
            })
            .collect();
        let opt = |o: Option<usize>| match o {
            Some(i) => {
                let i = index(i);
                quote!(Some(#i))
            }
            None => quote!(None),
        };
        let row_tokens = rows.iter().map(|r| match *r {
            ClusterRow::Coincident { a, la, slide, b, lb } => {
                let (a, b, la, lb) = (index(a), index(b), point_lit(la), point_lit(lb));
                let slide = match slide {
                    Some((i, d)) => {
                        let (i, d) = (index(i), point_lit(d));
                        quote!(Some((#i, #d)))
                    }
                    None => quote!(None),
                };
                quote!(cluster::Row::Coincident { a: #a, la: #la, slide: #slide, b: #b, lb: #lb })
            }
            ClusterRow::InLine { a, la, dir, b, lb } => {
                let (a, b, la, lb, dir) = (index(a), index(b), point_lit(la), point_lit(lb), point_lit(dir));
                quote!(cluster::Row::InLine { a: #a, la: #la, dir: #dir, b: #b, lb: #lb })
            }
            ClusterRow::OnCircle { a, la, r, b, lb } => {
                let (a, b, la, lb, r) = (index(a), index(b), point_lit(la), point_lit(lb), lit(r));
                quote!(cluster::Row::OnCircle { a: #a, la: #la, r: #r, b: #b, lb: #lb })
            }
            ClusterRow::Parallel { a, b, input } => {
                let (a, b, input) = (index(a), index(b), opt(input));
                quote!(cluster::Row::Parallel { a: #a, b: #b, input: #input })
            }
        });
        let nrows = index(rows.len());
        // Every pose, current (in the split form too, from the
        // chunk's locals: the bodies it writes are then read before
        // they are written).
        let all = (0..self.plan.bodies.len()).map(|b| self.pose(b));
        let all = quote!([#(#all),*]);
        let writes = params.iter().map(|p| {
            let b = p.body();
            let id = &self.pose_idents[b];
            let i = index(b);
            quote!(#id = all[#i];)
        });
        let (n, m, size) = (index(n), index(m), lit(self.plan.size));
        // On jets: solved on the values as `solve` does, then
        // differentiated by the implicit function theorem.
        let solve = if self.jets {
            quote!(cluster::solve_rates(ctx, #id, &mut all, &params, &ROWS, &inputs, #size, &mut newton)?;)
        } else {
            quote!(cluster::solve(ctx, #id, &mut all, &params, &ROWS, inputs, #size, &mut newton)?;)
        };
        quote! {
            #marker
            {
                #(#pre)*
                let params = [#(#param_tokens),*];
                const ROWS: [cluster::Row; #nrows] = [#(#row_tokens),*];
                let mut all = #all;
                // Too large for fixed-size matrices: the runtime's
                // dynamically sized solver (which allocates).
                let mut newton = numeric::Newton::new(#n, #m);
                #solve
                #(#writes)*
            }
        }
    }

    /// The straight-line code of cluster step `id`: its Newton solve, then
    /// the cluster bodies written at the solution; or, with `jacobian_out`,
    /// the solution and the Jacobian there as the block's value `(x, j)`
    /// instead of the writes (the values half of its rates).
    pub(super) fn fixed_cluster_step(
        &self,
        id: &TokenStream,
        params: &[ClusterParam],
        rows: &[ClusterRow],
        (n, m): (usize, usize),
        pre: &mut Vec<TokenStream>,
        jacobian_out: bool,
    ) -> TokenStream {
        let ClusterCode {
            warm,
            place,
            residuals,
            jacobian,
        } = self.cluster_code(params, rows, pre);
        let trial = place.iter().map(|(pose, e)| quote!(let #pose = #e;));
        let size = lit(self.plan.size);
        let (n_lit, m_lit) = (index(n), index(m));
        let tail = if jacobian_out {
            quote! {
                cluster::finish(ctx, #id, report)?;
                // The Jacobian at the solution, for the rates.
                let mut r = numeric::SVector::<f64, #m_lit>::zeros();
                let mut j = numeric::SMatrix::<f64, #m_lit, #n_lit>::zeros();
                numeric::Equations::eval(&mut system, &x, &mut r, Some(&mut j));
                (x, j)
            }
        } else {
            let writes = place.iter().map(|(pose, e)| quote!(#pose = #e;));
            quote! {
                // The poses at the solution (or, on a break, the least-squares
                // point the stretch policy shows), by the same placements.
                #(#writes)*
                cluster::finish(ctx, #id, report)?;
            }
        };
        quote! {
            #(#pre)*
            const SIZE: f64 = #size;
            let mut x = numeric::SVector::<f64, #n_lit>::from([#(#warm),*]);
            let mut system = numeric::fixed_system::<#m_lit, #n_lit, _>(|x, r, j| {
                #(#trial)*
                #(#residuals)*
                let Some(j) = j else { return };
                j.fill(0.0);
                #(#jacobian)*
            });
            let report = numeric::Newton::<numeric::Const<#m_lit>, numeric::Const<#n_lit>>::fixed()
                .solve(&mut system, &mut x, &cluster::options(SIZE));
            #tail
        }
    }

    /// The straight-line code of cluster step `id` on jets (in
    /// `solve_rates`): the values of what it hangs on handed to the
    /// frame's own code of the step (so its positions are `solve`'s), then
    /// the implicit function theorem with the Jacobian at the solution —
    /// the residuals on jets with the unknowns held (their rate is
    /// `∂F/∂upstream·rates`, so `q̇ = −J⁺·F'`), again with the unknowns
    /// moving at `q̇` (all of `F''` but `J·q̈`, so `q̈ = −J⁺·F''`) — and the
    /// cluster bodies placed on jets.
    pub(super) fn fixed_cluster_rates(
        &self,
        id: &TokenStream,
        params: &[ClusterParam],
        rows: &[ClusterRow],
        (n, m): (usize, usize),
    ) -> TokenStream {
        let values = Emitter {
            jets: false,
            ..self.clone()
        };
        let mut pre = Vec::new();
        // (It writes `pre` out itself.)
        let solve = values.fixed_cluster_step(id, params, rows, (n, m), &mut pre, true);
        // The frame's locals the values' code reads, as values.
        let uses = crate::emit::uses::Uses::of(&solve);
        let mut shadows = Vec::new();
        for (b, body) in self.plan.bodies.iter().enumerate() {
            let pose = &self.pose_idents[b];
            if !body.fixed && uses.has(&pose.to_string()) {
                shadows.push(quote!(let #pose = #pose.value();));
            }
        }
        for t in &self.temp_idents {
            if uses.has(&t.to_string()) {
                shadows.push(quote!(let #t = [#t[0].v, #t[1].v];));
            }
        }
        for (k, u) in self.input_idents.iter().enumerate() {
            if uses.has(&u.to_string()) {
                shadows.push(match self.plan.inputs[k].kind {
                    InputKind::Angle => quote!(let #u = #u.value();),
                    InputKind::Slide => quote!(let #u = #u.v;),
                });
            }
        }

        let mut pre = Vec::new();
        let ClusterCode { place, residuals, .. } = self.cluster_code(params, rows, &mut pre);
        let trial = place.iter().map(|(pose, e)| quote!(let #pose = #e;));
        let writes = place.iter().map(|(pose, e)| quote!(#pose = #e;));
        let size = lit(self.plan.size);
        let (n_lit, m_lit) = (index(n), index(m));
        quote! {
            // The frame: the step's own code on the values.
            let (x, jacobian) = {
                #(#shadows)*
                #solve
            };
            // Its rates, by the implicit function theorem.
            #(#pre)*
            const SIZE: f64 = #size;
            let residuals = |x: [Jet2; #n_lit]| {
                let mut r = [Jet2::cst(0.0); #m_lit];
                #(#trial)*
                #(#residuals)*
                r
            };
            let implicit = numeric::Implicit::new(&jacobian);
            let f = residuals(core::array::from_fn(|k| Jet2::cst(x[k])));
            let q_dot = implicit.solve(&numeric::SVector::from_fn(|i, _| f[i].d));
            let f = residuals(core::array::from_fn(|k| Jet2::new(x[k], q_dot[k], 0.0)));
            let q_ddot = implicit.solve(&numeric::SVector::from_fn(|i, _| f[i].dd));
            let x: [Jet2; #n_lit] = core::array::from_fn(|k| Jet2::new(x[k], q_dot[k], q_ddot[k]));
            #(#writes)*
        }
    }
}

/// A cluster's straight-line code in pieces.
struct ClusterCode {
    /// The warm start, unknown by unknown.
    warm: Vec<TokenStream>,
    /// Each cluster body's pose local and its placement from the unknowns
    /// `x`, in param order (a hinge's parent first).
    place: Vec<(TokenStream, TokenStream)>,
    /// The residuals into `r`.
    residuals: Vec<TokenStream>,
    /// The Jacobian's non-zero entries into `j`.
    jacobian: Vec<TokenStream>,
}

/// The entries of a coincident row pair for one term, `+` for the first
/// marker and `−` for the second.
fn coincident_entry(row: usize, col: usize, term: &Term, plus: bool) -> TokenStream {
    let (i, i1, c) = (index(row), index(row + 1), index(col));
    let add = |k: &proc_macro2::Literal, v: TokenStream| {
        if plus {
            quote!(j[(#k, #c)] += #v;)
        } else {
            quote!(j[(#k, #c)] -= #v;)
        }
    };
    match term {
        Term::UnitX => add(&i, quote!(1.0)),
        Term::UnitY => add(&i1, quote!(1.0)),
        _ => {
            let t = term.tokens();
            let (e0, e1) = (add(&i, quote!(t[0])), add(&i1, quote!(t[1])));
            quote!({ let t = #t; #e0 #e1 })
        }
    }
}
