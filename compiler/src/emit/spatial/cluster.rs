//! A numeric cluster of a spatial plan as a fixed-size closure for
//! `dofplan_runtime::numeric::fixed_system`, solved by `Newton` at fixed
//! size so a frame allocates nothing.
//!
//! It is [`crate::interp::spatial::cluster`] written out: the same
//! operations in the same order, so compiled and interpreted clusters
//! agree to rounding. Before the solve, each cluster body's unknowns
//! (`cluster::Unknowns`) and warm start, and each distance row's far end
//! and length, are read from the state. In the closure, each cluster
//! body's trial pose is `cluster::moved` from its warm start; each row is
//! evaluated as statements (`RowKind::eval` on the markers' world frames,
//! or |a − b| − length); and, when Newton asks for the Jacobian, each
//! unknown's twist (`cluster::columns`) gives its column: `RowKind::deriv`
//! at the frames' rates, or u·velocity for a distance row.
//!
//! In `solve_rates` (a block on jets) the same solve runs on the values of
//! the state and inputs, then the rows are written a second time, on jets,
//! in a closure the implicit function theorem evaluates twice
//! (`numeric::Implicit` at the Jacobian of the solution), and the cluster
//! bodies are placed on jets by `cluster::moved_rates`
//! (`Emitter::cluster_rates`).

use proc_macro2::{Ident, Literal, TokenStream};
use quote::quote;

use super::step::{frames, row_kind, state_pose, Block};
use super::Emitter;
use crate::emit::{ident_for, index, lit};
use crate::plan::spatial::{CheckRow, Cluster, ClusterRow, Param, PointRef};

/// A cluster body: its locals and its first unknown.
struct Member {
    body: usize,
    base: Ident,
    unknowns: Ident,
    pose: Ident,
    columns: Ident,
    first: usize,
    count: usize,
}

/// `j[(row, first + c)]`, written without `+ 0`.
fn entry(row: usize, first: usize) -> TokenStream {
    let r = index(row);
    if first == 0 {
        quote!(j[(#r, c)])
    } else {
        let f = index(first);
        quote!(j[(#r, #f + c)])
    }
}

/// `x[first..]`, the unknowns of a member from its first (`x` itself for
/// the first member).
fn unknowns_of(x: TokenStream, first: usize) -> TokenStream {
    if first == 0 {
        x
    } else {
        let f = index(first);
        quote!(&#x[#f..])
    }
}

/// A cluster's code in pieces, on `f64`s or (for its rates) on jets.
struct Pieces {
    members: Vec<Member>,
    /// The rows into `r`, at the trial poses.
    residuals: Vec<TokenStream>,
    /// The Jacobian's entries into `j` (on `f64`s only).
    jacobian: Vec<TokenStream>,
    /// Which members' columns the Jacobian reads.
    used_columns: Vec<bool>,
    /// Whether it reads `zero`, a frame at rest.
    zero_used: bool,
}

/// A body's pose in a cluster's closure: its trial pose if it is a cluster
/// body, else the state's.
fn trial_pose(members: &[Member], body: usize) -> TokenStream {
    match members.iter().find(|mb| mb.body == body) {
        Some(mb) => {
            let p = &mb.pose;
            quote!(#p)
        }
        None => state_pose(body),
    }
}

impl Emitter<'_> {
    /// The code of cluster step `id` inside its block `b`: its Newton
    /// solve, or (a block on jets, in `solve_rates`) the solve on the
    /// values and the rates by the implicit function theorem.
    pub(super) fn cluster(&self, b: &mut Block, c: &Cluster, id: &Literal) -> TokenStream {
        if b.jets {
            self.cluster_rates(b, c, id)
        } else {
            self.cluster_solve(b, c, id, false)
        }
    }

    /// The pieces of a cluster's code, with the bindings they read pushed
    /// onto `b` (on jets when `b` is).
    fn pieces(&self, b: &mut Block, c: &Cluster) -> Pieces {
        for name in [
            "x", "r", "j", "c", "t", "d", "u", "v", "zero", "system", "report", "SIZE",
        ] {
            b.fresh(name);
        }
        let members = self.members(b, c);
        let mut p = Pieces {
            used_columns: vec![false; members.len()],
            members,
            residuals: Vec::new(),
            jacobian: Vec::new(),
            zero_used: false,
        };
        // The rows, then their Jacobian entries.
        let mut row = 0;
        for r in &c.rows {
            row += match r {
                ClusterRow::Equation(e) => self.equation_rows(b, &mut p, row, e),
                ClusterRow::Distance { .. } => self.distance_row(b, &mut p, row, r),
                // Drags are run by the interpreter (`numeric::spatial::
                // drag_plan`); no plan the analysis makes pins a marker.
                ClusterRow::Pin { .. } => unreachable!("drag plans are not emitted"),
            };
        }
        debug_assert_eq!(row, c.equations());
        p
    }

    /// Before the solve: each cluster body's unknowns and warm start.
    fn members(&self, b: &mut Block, c: &Cluster) -> Vec<Member> {
        let mut members: Vec<Member> = Vec::new();
        let mut first = 0;
        for p in &c.params {
            let body = p.body();
            let name = ident_for(&self.plan.bodies[body]);
            let u = match p {
                Param::Free { .. } => quote!(Unknowns::Free),
                Param::Pivot { pivot, .. } => {
                    let c = b.point(pivot);
                    quote!(Unknowns::Pivot(#c))
                }
                Param::Axis { pivot, axis, .. } => {
                    let c = b.point(pivot);
                    let a = b.dir(axis, &format!("axis_{name}"));
                    quote!(Unknowns::Axis(#c, #a))
                }
            };
            let base = b.fresh(&format!("base_{name}"));
            let unknowns = b.fresh(&format!("unknowns_{name}"));
            let pose = b.fresh(&format!("pose_{name}"));
            let columns = b.fresh(&format!("columns_{name}"));
            let at = state_pose(body);
            b.pre.push(quote!(let #base = #at;));
            b.pre.push(quote!(let #unknowns = #u;));
            members.push(Member {
                body,
                base,
                unknowns,
                pose,
                columns,
                first,
                count: p.count(),
            });
            first += p.count();
        }
        members
    }

    /// An equation's rows from `row` on, and their Jacobian entries.
    /// Returns its row count.
    fn equation_rows(&self, b: &mut Block, p: &mut Pieces, row: usize, e: &CheckRow) -> usize {
        let trial = |body: usize| trial_pose(&p.members, body);
        let rows = e.kind.rows();
        let (f1, f2) = frames(e, &trial);
        let (f1_id, f2_id) = (b.fresh(&format!("f1_{row}")), b.fresh(&format!("f2_{row}")));
        let v = b.fresh(&format!("v_{row}"));
        let kind = row_kind(&e.kind);
        let writes = (0..rows).map(|i| {
            let (ri, vi) = (index(row + i), index(i));
            quote!(r[#ri] = #v[#vi];)
        });
        p.residuals.push(self.note(e.name.clone()));
        p.residuals.push(quote! {
            let #f1_id = #f1;
            let #f2_id = #f2;
            let #v = #kind.eval(&#f1_id, &#f2_id, inputs);
            #(#writes)*
        });
        for side in 0..2 {
            let body = e.bodies[side];
            if side == 1 && e.bodies[0] == body {
                continue;
            }
            let Some(k) = p.members.iter().position(|mb| mb.body == body) else {
                continue;
            };
            let mb = &p.members[k];
            p.used_columns[k] = true;
            let rate1 = quote!(t.rate(&#f1_id));
            let rate2 = quote!(t.rate(&#f2_id));
            let (d1, d2) = if side == 0 {
                if e.bodies[1] == body {
                    (rate1, rate2)
                } else {
                    p.zero_used = true;
                    (rate1, quote!(zero))
                }
            } else {
                p.zero_used = true;
                (quote!(zero), rate2)
            };
            let adds = (0..rows).map(|i| {
                let (at, di) = (entry(row + i, mb.first), index(i));
                quote!(#at += d[#di];)
            });
            let (cols, count) = (&mb.columns, index(mb.count));
            p.jacobian.push(quote! {
                for (c, t) in #cols.iter().take(#count).enumerate() {
                    let d = #kind.deriv(&#f1_id, &#f2_id, &#d1, &#d2, inputs);
                    #(#adds)*
                }
            });
        }
        rows
    }

    /// A contracted chain's length kept (row `row`), and its Jacobian
    /// entries. Returns its row count.
    fn distance_row(&self, b: &mut Block, p: &mut Pieces, row: usize, r: &ClusterRow) -> usize {
        let ClusterRow::Distance {
            a,
            b: pb,
            c: pc,
            d: pd,
            name,
        } = r
        else {
            unreachable!("a distance row")
        };
        let trial = |body: usize| trial_pose(&p.members, body);
        // The far end and the length are read once, before the
        // solve, as the interpreter does.
        let end = b.point(pb);
        let (qc, qd) = (b.point(pc), b.point(pd));
        let len = b.bind(
            &format!("len_{row}"),
            quote!(spatial::norm(spatial::sub(#qd, #qc))),
        );
        let (pa, ab) = (b.fresh(&format!("a_{row}")), b.fresh(&format!("ab_{row}")));
        let a_expr = match b.point_expr(a, &trial) {
            Some((_, e)) => e,
            None => b.point(a),
        };
        let ri = index(row);
        p.residuals.push(self.note(format!("{name}: its length, kept")));
        p.residuals.push(quote! {
            let #pa = #a_expr;
            let #ab = spatial::sub(#pa, #end);
            r[#ri] = spatial::norm(#ab) - #len;
        });
        let body = match a {
            PointRef::Body { body, .. } | PointRef::Slid { body, .. } => Some(*body),
            _ => None,
        };
        if let Some(k) = body.and_then(|body| p.members.iter().position(|mb| mb.body == body)) {
            let mb = &p.members[k];
            p.used_columns[k] = true;
            let (at, cols, count) = (entry(row, mb.first), &mb.columns, index(mb.count));
            p.jacobian.push(quote! {
                let u = spatial::unit(#ab);
                for (c, t) in #cols.iter().take(#count).enumerate() {
                    #at = spatial::dot(u, t.velocity(#pa));
                }
            });
        }
        1
    }

    /// The Newton solve of cluster step `id` on `f64`s, then the cluster
    /// bodies written at the solution; or, with `jacobian_out`, the
    /// solution and the Jacobian there as the block's value `(x, j)`
    /// instead of the writes (the values half of its rates).
    fn cluster_solve(&self, b: &mut Block, c: &Cluster, id: &Literal, jacobian_out: bool) -> TokenStream {
        let (n, m) = (c.unknowns(), c.equations());
        let Pieces {
            members,
            residuals,
            jacobian,
            used_columns,
            zero_used,
        } = self.pieces(b, c);
        let place = members.iter().map(|mb| {
            let (pose, base, u) = (&mb.pose, &mb.base, &mb.unknowns);
            let x = unknowns_of(quote!(x), mb.first);
            quote!(let #pose = cluster::moved(&#base, &#u, #x);)
        });
        let columns = members
            .iter()
            .zip(&used_columns)
            .filter(|(_, u)| **u)
            .map(|(mb, _)| {
                let (cols, base, u) = (&mb.columns, &mb.base, &mb.unknowns);
                let x = unknowns_of(quote!(x), mb.first);
                quote!(let #cols = cluster::columns(&#base, &#u, #x);)
            });
        let zero = if zero_used {
            quote!(let zero = FrameRate::default();)
        } else {
            quote!()
        };
        let (n_lit, m_lit, size) = (index(n), index(m), lit(c.size));
        let start = self.note("The unknowns start at 0: every cluster body at its warm start.".into());
        let tail = if jacobian_out {
            quote! {
                numeric::cluster::finish(ctx, #id, report)?;
                // The Jacobian at the solution, for the rates.
                let mut r = numeric::SVector::<f64, #m_lit>::zeros();
                let mut j = numeric::SMatrix::<f64, #m_lit, #n_lit>::zeros();
                numeric::Equations::eval(&mut system, &x, &mut r, Some(&mut j));
                (x, j)
            }
        } else {
            let writes = members.iter().map(|mb| {
                let (base, u) = (&mb.base, &mb.unknowns);
                let at = state_pose(mb.body);
                let x = unknowns_of(quote!(x.as_slice()), mb.first);
                quote!(#at = cluster::moved(&#base, &#u, #x);)
            });
            let end = self.note(
                "The poses at the solution (or, on a break, at the least-squares point the stretch policy shows).".into(),
            );
            quote! {
                #end
                #(#writes)*
                numeric::cluster::finish(ctx, #id, report)?;
            }
        };
        quote! {
            const SIZE: f64 = #size;
            #start
            let mut x = numeric::SVector::<f64, #n_lit>::zeros();
            let mut system = numeric::fixed_system::<#m_lit, #n_lit, _>(|x, r, j| {
                let x = x.as_slice();
                #(#place)*
                #(#residuals)*
                let Some(j) = j else { return };
                j.fill(0.0);
                #(#columns)*
                #zero
                #(#jacobian)*
            });
            let report = numeric::Newton::<numeric::Const<#m_lit>, numeric::Const<#n_lit>>::fixed()
                .solve(&mut system, &mut x, &numeric::cluster::options(SIZE));
            #tail
        }
    }

    /// Cluster step `id` on jets (in `solve_rates`), in its block `b`: the
    /// frame's own code of the step on the values of the state and inputs
    /// (so its positions are `solve`'s), giving the solution and the
    /// Jacobian there; then the rates by the implicit function theorem —
    /// the rows on jets with the unknowns held (their rate is
    /// `∂F/∂upstream·rates`, so `ẋ = −J⁺·F′`), again with the unknowns
    /// moving at `ẋ` (all of `F″` but `J·ẍ`, so `ẍ = −J⁺·F″`) — and the
    /// cluster bodies placed on jets (`cluster::moved_rates`, whose values
    /// are `cluster::moved`'s).
    fn cluster_rates(&self, b: &mut Block, c: &Cluster, id: &Literal) -> TokenStream {
        let (n, m) = (c.unknowns(), c.equations());
        let mut values = Block::new(self.plan);
        let solve = self.cluster_solve(&mut values, c, id, true);
        let pre = &values.pre;
        let uses = crate::emit::uses::Uses::of(&quote!(#(#pre)* #solve));
        let inputs = if uses.has("inputs") {
            quote!(let inputs = input_values;)
        } else {
            quote!()
        };

        for name in [
            "x",
            "r",
            "f",
            "q_dot",
            "q_ddot",
            "implicit",
            "jacobian",
            "residuals",
        ] {
            b.fresh(name);
        }
        let Pieces {
            members, residuals, ..
        } = self.pieces(b, c);
        let place = members.iter().map(|mb| {
            let (pose, base, u) = (&mb.pose, &mb.base, &mb.unknowns);
            let x = unknowns_of(quote!(x), mb.first);
            quote!(let #pose = cluster::moved_rates(&#base, &#u, #x);)
        });
        let writes = members.iter().map(|mb| {
            let (base, u) = (&mb.base, &mb.unknowns);
            let at = state_pose(mb.body);
            let x = unknowns_of(quote!(x), mb.first);
            quote!(#at = cluster::moved_rates(&#base, &#u, #x);)
        });
        let (n_lit, m_lit) = (index(n), index(m));
        let frame = self.note("The frame: the step's own code on the values.".into());
        let why = self.note("Its rates, by the implicit function theorem.".into());
        quote! {
            #frame
            let (x, jacobian) = {
                let w = State {
                    poses: w.poses.map(|p| p.value()),
                    temps: w.temps.map(spatial::value),
                    branches: w.branches,
                    angles: w.angles,
                };
                #inputs
                #(#pre)*
                #solve
            };
            #why
            let residuals = |x: [Jet2; #n_lit]| {
                let x = &x[..];
                let mut r = [Jet2::cst(0.0); #m_lit];
                #(#place)*
                #(#residuals)*
                r
            };
            let implicit = numeric::Implicit::new(&jacobian);
            let f = residuals(core::array::from_fn(|k| Jet2::cst(x[k])));
            let q_dot = implicit.solve(&numeric::SVector::from_fn(|i, _| f[i].d));
            let f = residuals(core::array::from_fn(|k| Jet2::new(x[k], q_dot[k], 0.0)));
            let q_ddot = implicit.solve(&numeric::SVector::from_fn(|i, _| f[i].dd));
            let x: [Jet2; #n_lit] = core::array::from_fn(|k| Jet2::new(x[k], q_dot[k], q_ddot[k]));
            let x = &x[..];
            #(#writes)*
        }
    }
}
