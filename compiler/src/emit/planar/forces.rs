//! `pub mod forces` of a planar module: the mechanism's force table (the
//! runtime's `planar::forces::Table`, written out as constants) and
//! `solve_forces`, a frame's positions, rates and forces in one pass
//! (`solve_rates_into`, then the runtime's `solve_frame` on stack buffers:
//! no allocation). The interpreter solves the same table with the same
//! runtime functions (`forces::planar::reactions`).

use proc_macro2::TokenStream;
use quote::quote;

use dofplan_runtime::planar::forces::{Load, Table, Unknown};

use super::point_lit;
use crate::emit::{index, lit};
use crate::plan::Plan;

/// A body and a local point: `(body, [x, y])`.
fn end((body, at): (usize, [f64; 2])) -> TokenStream {
    let (b, p) = (index(body), point_lit(at));
    quote!((#b, #p))
}

fn unknown(u: &Unknown) -> TokenStream {
    match *u {
        Unknown::Pin {
            first,
            second,
            at,
            axis,
        } => {
            let (f, s, a, x) = (index(first), index(second), point_lit(at), index(axis));
            quote!(Unknown::Pin { first: #f, second: #s, at: #a, axis: #x })
        }
        Unknown::Across {
            first,
            second,
            at,
            dir,
        } => {
            let (f, s, a, d) = (index(first), index(second), point_lit(at), point_lit(dir));
            quote!(Unknown::Across { first: #f, second: #s, at: #a, dir: #d })
        }
        Unknown::Radial {
            first,
            second,
            centre,
            at,
        } => {
            let (f, s, c, a) = (index(first), index(second), point_lit(centre), point_lit(at));
            quote!(Unknown::Radial { first: #f, second: #s, centre: #c, at: #a })
        }
        Unknown::Moment { first, second } => {
            let (f, s) = (index(first), index(second));
            quote!(Unknown::Moment { first: #f, second: #s })
        }
        Unknown::Along {
            first,
            second,
            at,
            dir,
        } => {
            let (f, s, a, d) = (index(first), index(second), point_lit(at), point_lit(dir));
            quote!(Unknown::Along { first: #f, second: #s, at: #a, dir: #d })
        }
        Unknown::Mesh {
            first,
            second,
            carrier,
            at,
            dir,
        } => {
            let (f, s, c) = (index(first), index(second), index(carrier));
            let (a, d) = (point_lit(at), point_lit(dir));
            quote!(Unknown::Mesh { first: #f, second: #s, carrier: #c, at: #a, dir: #d })
        }
    }
}

fn load(l: &Load) -> TokenStream {
    match *l {
        Load::Force {
            body,
            at,
            force,
            body_axes,
        } => {
            let (b, a, f) = (index(body), point_lit(at), point_lit(force));
            quote!(Load::Force { body: #b, at: #a, force: #f, body_axes: #body_axes })
        }
        Load::Torque { body, torque } => {
            let (b, t) = (index(body), lit(torque));
            quote!(Load::Torque { body: #b, torque: #t })
        }
        Load::Spring {
            a,
            b,
            stiffness,
            free_length,
        } => {
            let (a, b, k, l) = (end(a), end(b), lit(stiffness), lit(free_length));
            quote!(Load::Spring { a: #a, b: #b, stiffness: #k, free_length: #l })
        }
        Load::Damper { a, b, damping } => {
            let (a, b, c) = (end(a), end(b), lit(damping));
            quote!(Load::Damper { a: #a, b: #b, damping: #c })
        }
        Load::TorsionSpring {
            first,
            second,
            stiffness,
            free_angle,
        } => {
            let (f, s, k, a) = (index(first), index(second), lit(stiffness), lit(free_angle));
            quote!(Load::TorsionSpring { first: #f, second: #s, stiffness: #k, free_angle: #a })
        }
    }
}

/// `pub type Forces`: the runtime's with the mechanism's numbers of
/// joints and inputs, and of slots and gear pairs where there are any
/// (the type's default is none).
fn forces_type(nj: usize, ni: usize, slots: usize, gears: usize) -> TokenStream {
    let (nj, ni) = (index(nj), index(ni));
    if gears > 0 {
        let (ns, ng) = (index(slots), index(gears));
        quote! {
            /// A frame's forces: per joint (file order) the force its
            /// first body exerts on its second and its moment, per input
            /// its force or torque (per radian), per pin in a slot the
            /// force the slotted body exerts on the pin, per gear pair the
            /// tooth force the first gear exerts on the second, and the
            /// force and moment on the ground.
            pub type Forces = dofplan_runtime::planar::forces::Forces<#nj, #ni, #ns, #ng>;
        }
    } else if slots > 0 {
        let ns = index(slots);
        quote! {
            /// A frame's forces: per joint (file order) the force its
            /// first body exerts on its second and its moment, per input
            /// its force or torque (per radian), per pin in a slot the
            /// force the slotted body exerts on the pin, and the force and
            /// moment on the ground.
            pub type Forces = dofplan_runtime::planar::forces::Forces<#nj, #ni, #ns>;
        }
    } else {
        quote! {
            /// A frame's forces: per joint (file order) the force its
            /// first body exerts on its second and its moment, per input
            /// its force or torque (per radian), and the force and moment
            /// on the ground.
            pub type Forces = dofplan_runtime::planar::forces::Forces<#nj, #ni>;
        }
    }
}

/// `pub const TABLE`: the force table `t` (its `slots` unknowns after the
/// inputs', then one per gear pair) written out, with its doc.
fn table_const(t: &Table, slots: usize) -> TokenStream {
    let gears = t.leaning.len();
    let rows = t.rows.iter().map(|r| match r {
        Some(r) => {
            let r = index(*r);
            quote!(Some(#r))
        }
        None => quote!(None),
    });
    let unknowns = t.unknowns.iter().map(unknown);
    let loads = t.loads.iter().map(load);
    let masses = t.masses.iter().map(|m| {
        let (b, c, mass, i) = (index(m.body), point_lit(m.centre), lit(m.mass), lit(m.inertia));
        quote!(Mass { body: #b, centre: #c, mass: #mass, inertia: #i })
    });
    let blocks = t.blocks.iter().map(|b| {
        let (r, c) = (b.rows.iter().map(|&r| index(r)), b.cols.iter().map(|&c| index(c)));
        quote!(Block { rows: &[#(#r),*], cols: &[#(#c),*] })
    });
    let nr = index(t.n_rows);
    let gravity = point_lit(t.gravity);
    let sizes = t
        .blocks
        .iter()
        .map(|b| b.rows.len().to_string())
        .collect::<Vec<_>>()
        .join(", ");
    let per_slot = if slots > 0 { ", then one per slot" } else { "" };
    let per_gear = if gears > 0 { ", then one per gear pair" } else { "" };
    let doc_table = format!(
        " The mechanism's forces as the runtime solves them: {} equations (three per moving body, each body's moment about its `about` point), {} unknowns (two per joint, then one per input{per_slot}{per_gear}), solved in blocks of {sizes}.",
        t.n_rows,
        t.unknowns.len()
    );
    let about = t.about.iter().map(|&p| point_lit(p));
    let leaning = t.leaning.iter().map(|l| {
        let (u, other) = (index(l.unknown), unknown(&l.other));
        quote!(Lean { unknown: #u, other: #other })
    });
    quote! {
        #[doc = #doc_table]
        pub const TABLE: Table<'static> = Table {
            rows: &[#(#rows),*],
            n_rows: #nr,
            unknowns: &[#(#unknowns),*],
            loads: &[#(#loads),*],
            masses: &[#(#masses),*],
            gravity: #gravity,
            blocks: &[#(#blocks),*],
            leaning: &[#(#leaning),*],
            about: &[#(#about),*],
        };
    }
}

/// The `forces` module of `plan`'s module for the force table `t` (its
/// `slots` unknowns after the inputs', then one per gear pair); an
/// error says why there is none: a plan whose reactions are solved by
/// least squares (over-constrained, or singular as drawn), which is the
/// interpreter's.
pub(in crate::emit) fn forces_module(plan: &Plan, t: &Table, slots: usize) -> Result<String, String> {
    if t.blocks.is_empty() {
        return Err("its reactions are solved by least squares (redundant joints, or a freedom no input holds), which `dofplan analyze --forces` does; compiled `solve_forces` needs a force plan of blocks".into());
    }
    let gears = t.leaning.len();
    let (nb, nj, ni) = (
        plan.bodies.len(),
        (t.unknowns.len() - plan.inputs.len() - slots - gears) / 2,
        plan.inputs.len(),
    );
    let largest = t.blocks.iter().map(|b| b.rows.len()).max().unwrap_or(0);
    let (nb_l, nr, nu) = (index(nb), index(t.n_rows), index(t.unknowns.len()));
    let forces_decl = forces_type(nj, ni, slots, gears);
    let table = table_const(t, slots);
    // A frame whose gear pair drives the other way is solved again with
    // its tooth force leaned that way: a copy of the unknowns to lean.
    let leaned = if gears > 0 {
        quote!(&mut [Unknown::Moment { first: 0, second: 0 }; #nu])
    } else {
        quote!(&mut [])
    };
    let scratch = index(largest * largest + largest);
    // Only what the table names (an unused import warns in the user's
    // build): a file may give masses and no loads, or loads and no masses.
    let kinds = [
        ("Lean", gears > 0),
        ("Load", !t.loads.is_empty()),
        ("Mass", !t.masses.is_empty()),
    ]
    .into_iter()
    .filter(|(_, used)| *used)
    .map(|(name, _)| proc_macro2::Ident::new(name, proc_macro2::Span::call_site()));
    let tokens = quote! {
        /// What holds the mechanism and what it takes to drive it, frame
        /// by frame: each joint's reaction and each input's force or
        /// torque under the file's masses, gravity and loads, running at
        /// the inputs' rates and accelerations (zero: held still).
        pub mod forces {
            use dofplan_runtime::planar::forces::{solve_frame, Block, #(#kinds,)* Table, Unknown, Work};
            use dofplan_runtime::planar::Pose;
            use dofplan_runtime::real::{ForceError, Jet2, RateError};
            use dofplan_runtime::Ctx;

            use super::{solve, solve_rates_into, State};

            #forces_decl

            #table

            /// [`solve_rates_into`] and the forces
            /// in one pass, into `out`: the frame at `inputs` moving at
            /// `rates` and `accelerations` (per second, degrees for
            /// angles; zeros hold it still, and then the frame is
            /// [`solve`]d, its rates being zero). On an error `out` holds no
            /// forces to read: the frame's break or dead point, or a
            /// block of the force plan singular here
            /// ([`ForceError::Singular`]).
            pub fn solve_forces(
                s: &mut State,
                inputs: &[f64],
                rates: &[f64],
                accelerations: &[f64],
                ctx: &mut Ctx,
                out: &mut Forces,
            ) -> Result<(), ForceError> {
                let work = Work {
                    applied: &mut [[0.0; 3]; #nb_l],
                    rhs: &mut [0.0; #nr],
                    x: &mut [0.0; #nu],
                    scratch: &mut [0.0; #scratch],
                    unknowns: #leaned,
                };
                if rates.iter().chain(accelerations).all(|v| *v == 0.0) {
                    // Held still: the positions alone (their rates are
                    // zero, and `solve_rates_into`'s values are `solve`'s),
                    // without inertia or dampers.
                    solve(s, inputs, ctx).map_err(|b| ForceError::Rates(RateError::Break(b)))?;
                    solve_frame(&TABLE, &s.poses, None, work, out)?;
                } else {
                    let mut jets = [Pose::<Jet2>::cst(Pose::IDENTITY); #nb_l];
                    solve_rates_into(s, inputs, rates, accelerations, ctx, &mut jets).map_err(ForceError::Rates)?;
                    let poses = jets.map(|j| j.value());
                    solve_frame(&TABLE, &poses, Some(&jets), work, out)?;
                }
                Ok(())
            }
        }
    };
    let file =
        syn::parse2::<syn::File>(tokens).map_err(|e| format!("the forces module does not parse: {e}"))?;
    Ok(prettyplease::unparse(&file))
}
