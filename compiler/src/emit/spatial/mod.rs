//! The Rust back end of spatial plans: a [`Plan3`] becomes a module of the
//! same shape as a planar one — named constants for bodies and markers, a
//! `State` of fixed-size arrays, `solve` as straight-line code and a `Plan`
//! implementing `dofplan_runtime::Solver` (with `Pose = Pose3`).
//!
//! Every step becomes one block under a comment holding its explanation,
//! calling exactly the runtime function the interpreter
//! ([`crate::interp::spatial`]) calls for it, on the points and directions
//! it reads bound to named locals. The frame runs on a copy of the (`Copy`)
//! state that is written back only when every step succeeded, so a break
//! leaves the state as it was. A numeric cluster becomes a fixed-size
//! closure (see [`super::spatial_cluster`]).
//!
//! Unlike a planar module, the state itself is the working set: poses,
//! pseudo-markers and branch slots are read and written in place in the
//! copy. So a large plan splits into functions of bounded size that take
//! the copy by reference, with nothing to hand from one to the next.
use std::cell::{Cell, RefCell};

use proc_macro2::{Ident, TokenStream};
use quote::{format_ident, quote};

use dofplan_runtime::spatial::Vec3;
use dofplan_runtime::Branch;

mod cluster;
mod rates;
mod step;

use super::uses::Uses;
use super::{index, lit, names, scaffold};
use crate::model::InputKind;
use crate::plan::spatial::{Plan3, StepKind3};
use step::vec_lit;

/// Why `solve` works on a copy, as its comment says.
const COPY: &str = "Keep a copy to restore on a break (an early return) and work on `s` itself: a break leaves `s` as it was, no caller has to copy the state per frame to roll back, and a frame copies the state once.";

/// Writes one spatial plan's module.
pub(super) struct Emitter3<'p> {
    /// The plan.
    pub plan: &'p Plan3,
    /// Comments inside a step (a cluster's rows), by the index their
    /// placeholder names.
    pub notes: RefCell<Vec<String>>,
    /// Whether steps are written for `solve_rates` (on jets).
    pub jets: Cell<bool>,
}

impl Emitter3<'_> {
    /// A placeholder statement that becomes the comment `// text`.
    pub fn note(&self, text: String) -> TokenStream {
        let mut notes = self.notes.borrow_mut();
        let i = index(notes.len());
        notes.push(text);
        quote!(__dofplan_note!(#i);)
    }
}

impl Emitter3<'_> {
    /// The constants naming each body and marker, and the state's marker
    /// reader (as a planar module's, with [`Marker3`](dofplan_runtime::Marker3)).
    fn names(&self) -> TokenStream {
        let plan = self.plan;
        let body_names = names::constants(plan.bodies.iter().map(String::as_str));
        let bodies = plan
            .bodies
            .iter()
            .zip(&body_names)
            .enumerate()
            .map(|(i, (b, c))| {
                let (doc, c, i) = (format!(" `{b}`"), format_ident!("{}", c), index(i));
                quote! {
                    #[doc = #doc]
                    pub const #c: usize = #i;
                }
            });
        let all_markers: Vec<(usize, String, Vec3)> = plan
            .markers
            .iter()
            .enumerate()
            .flat_map(|(i, ms)| {
                ms.iter()
                    .map(move |(m, at)| (i, format!("{}.{m}", plan.bodies[i]), *at))
            })
            .collect();
        let marker_names = names::constants(all_markers.iter().map(|(_, n, _)| n.as_str()));
        let markers = all_markers.iter().zip(&marker_names).map(|((b, name, at), c)| {
            let doc = format!(" `{name}`");
            let (c, b, at) = (format_ident!("{}", c), index(*b), vec_lit(*at));
            quote! {
                #[doc = #doc]
                pub const #c: Marker3 = Marker3::new(#name, #b, #at);
            }
        });
        let use_marker = if all_markers.is_empty() {
            quote!()
        } else {
            quote!(
                use dofplan_runtime::Marker3;
            )
        };
        quote! {
            /// Each body's index in [`BODIES`] and [`State::poses`], by name:
            /// upper-cased, other characters than ASCII letters and digits
            /// made `_`, and `_2`, `_3`, … after a name an earlier body took.
            pub mod body {
                #(#bodies)*
            }

            /// Each marker's body and local coordinates (its drawn position),
            /// named `BODY_MARKER` by the rule of `body`; read one with
            /// `State::marker` or `Marker3::world`.
            pub mod marker {
                #use_marker
                #(#markers)*
            }

            impl State {
                /// The world position of marker `m` (a constant of
                /// [`marker`]) in this state.
                #[inline]
                pub fn marker(&self, m: Marker3) -> Vec3 {
                    m.world(&self.poses)
                }
            }
        }
    }

    /// `solve`: the steps on a working copy of the state, in one function
    /// or (`chunks`) in functions of a few steps each.
    fn solve(
        &self,
        steps: Vec<TokenStream>,
        uses: &Uses,
        chunks: Option<Vec<(usize, usize)>>,
        doc: &str,
    ) -> TokenStream {
        let writes = self
            .plan
            .steps
            .iter()
            .any(|s| !matches!(s.kind, StepKind3::Check { .. }));
        let mut unused = Vec::new();
        if !uses.has("inputs") {
            unused.push(quote!(let _ = inputs;));
        }
        if !uses.has("ctx") {
            unused.push(quote!(let _ = ctx;));
        }
        // As the interpreter: every moving body's rotation corrected once a
        // frame, after the steps, so composed rotations stay rigid.
        let moving: Vec<TokenStream> = (0..self.plan.bodies.len())
            .filter(|&b| self.plan.composes(b))
            .map(|b| {
                let b = index(b);
                quote!(w.poses[#b].renormalize();)
            })
            .collect();
        let Some(chunks) = chunks else {
            if !writes {
                // Only checks (or nothing): the state is read, never written.
                let take = if steps.is_empty() {
                    quote!(let _ = s;)
                } else {
                    quote!(let w = *s;)
                };
                return quote! {
                    #[doc = #doc]
                    #[inline]
                    pub fn solve(s: &mut State, inputs: &[f64], ctx: &mut Ctx) -> Result<(), Break> {
                        #(#unused)*
                        #take
                        #(#steps)*
                        Ok(())
                    }
                };
            }
            let solve = self.transaction(doc);
            return quote! {
                #solve

                /// Every step of [`solve`] in place; `solve` restores the
                /// state when one breaks.
                #[inline(always)]
                fn run_steps(w: &mut State, inputs: &[f64], ctx: &mut Ctx) -> Result<(), Break> {
                    #(#unused)*
                    #(#steps)*
                    #(#moving)*
                    Ok(())
                }
            };
        };
        let mut steps = steps.into_iter();
        let mut functions = Vec::new();
        let mut calls = Vec::new();
        for (first, last) in chunks {
            let code: Vec<TokenStream> = steps.by_ref().take(last - first + 1).collect();
            let u = Uses::of(&quote!(#(#code)*));
            let param = |name: &str| {
                if u.has(name) {
                    format_ident!("{}", name)
                } else {
                    format_ident!("_{}", name)
                }
            };
            let (inputs, ctx) = (param("inputs"), param("ctx"));
            // Named by the steps' 1-based numbers, as the comments are.
            let (f, fdoc) = if first == last {
                (
                    format_ident!("step_{}", first + 1),
                    format!(" Step {} of [`solve`], in place.", first + 1),
                )
            } else {
                (
                    format_ident!("steps_{}_to_{}", first + 1, last + 1),
                    format!(" Steps {} to {} of [`solve`], in place.", first + 1, last + 1),
                )
            };
            functions.push(quote! {
                #[doc = #fdoc]
                #[inline(never)]
                fn #f(w: &mut State, #inputs: &[f64], #ctx: &mut Ctx) -> Result<(), Break> {
                    #(#code)*
                    Ok(())
                }
            });
            calls.push(quote!(#f(w, inputs, ctx)?;));
        }
        let solve = self.transaction(doc);
        quote! {
            #solve

            /// Every step of [`solve`] in place, a few steps a function;
            /// `solve` restores the state when one breaks.
            #[inline(always)]
            fn run_steps(w: &mut State, inputs: &[f64], ctx: &mut Ctx) -> Result<(), Break> {
                #(#calls)*
                #(#moving)*
                Ok(())
            }

            #(#functions)*
        }
    }

    /// `solve` as a transaction: [`run_steps`] on the state, restored from a
    /// copy if a step breaks.
    fn transaction(&self, doc: &str) -> TokenStream {
        let why = self.note(COPY.to_string());
        quote! {
            #[doc = #doc]
            #[inline]
            pub fn solve(s: &mut State, inputs: &[f64], ctx: &mut Ctx) -> Result<(), Break> {
                #why
                let before = *s;
                let result = run_steps(s, inputs, ctx);
                if result.is_err() {
                    *s = before;
                }
                result
            }
        }
    }

    fn module(
        &self,
        steps: Vec<TokenStream>,
        chunks: Option<Vec<(usize, usize)>>,
        jet_steps: Vec<TokenStream>,
    ) -> TokenStream {
        let plan = self.plan;
        let code = quote!(#(#steps)*);
        let u = Uses::of(&code);
        let rates = self.rates(jet_steps, chunks.as_deref());
        let rate_methods = super::scaffold::rates_trait_methods(&quote!(Pose3));
        let name = &plan.name;
        let nb = index(plan.bodies.len());
        let nt = index(plan.temps.len());
        let nk = index(plan.branches.len());
        let ni = index(plan.inputs.len());
        let nsteps = index(plan.steps.len());
        let body_names = &plan.bodies;
        let input_names = &plan.inputs;
        let input_kinds = plan.input_kinds.iter().map(|k| match k {
            InputKind::Angle => quote!(InputKind::Angle),
            InputKind::Slide => quote!(InputKind::Slide),
        });
        let fixed = &plan.fixed;
        let temps = plan.temps.iter().map(|t| vec_lit(t.drawn));
        let initial = plan.branches.iter().map(|b| match b.initial {
            Branch::Plus => quote!(Branch::Plus),
            Branch::Minus => quote!(Branch::Minus),
        });
        let angles = plan.branches.iter().map(|b| lit(b.angle));

        // Import what the steps use, and no more: an unused import would
        // warn in the user's crate.
        let pick = |names: &[&str]| -> Vec<Ident> {
            names
                .iter()
                .filter(|n| u.has(n))
                .map(|n| format_ident!("{}", n))
                .collect()
        };
        // (The rates always use `spatial`.)
        let mut imports = vec![quote!(
            use dofplan_runtime::spatial::{self, Pose3, Vec3};
        )];
        let rows = pick(&["FrameRate", "RowKind", "WorldFrame"]);
        if !rows.is_empty() {
            imports.push(quote!(use dofplan_runtime::spatial::rows::{#(#rows),*};));
        }
        let mut cluster = pick(&["Unknowns"]);
        if u.has("cluster") {
            cluster.insert(0, format_ident!("self"));
        }
        if !cluster.is_empty() {
            imports.push(quote!(use dofplan_runtime::spatial::cluster::{#(#cluster),*};));
        }
        if u.has("numeric") {
            imports.push(quote!(
                use dofplan_runtime::numeric;
            ));
        }
        let kinds = pick(&["BreakKind"]);
        imports.push(quote!(use dofplan_runtime::{Branch, Break, #(#kinds,)* Ctx, Marker3, Solver};));
        imports.push(quote!(
            use dofplan_runtime::real::{Jet2, RateError, Real};
        ));
        imports.push(quote!(
            use dofplan_runtime::BranchPolicy;
        ));

        let doc_solve = format!(
            " Places every body for `inputs` ({}), warm-started from `s`. On a break `s` is left unchanged.",
            if plan.inputs.is_empty() {
                "none".to_string()
            } else {
                plan.inputs
                    .iter()
                    .zip(&plan.input_kinds)
                    .map(|(n, k)| {
                        format!(
                            "{n} in {}",
                            match k {
                                InputKind::Angle => "degrees",
                                InputKind::Slide => "length units",
                            }
                        )
                    })
                    .collect::<Vec<_>>()
                    .join(", ")
            }
        );
        let solve = self.solve(steps, &u, chunks, &doc_solve);
        let names = self.names();
        quote! {
            #(#imports)*

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
                pub poses: [Pose3; #nb],
                /// Each pseudo-marker's last position (nearest-root policy,
                /// and the point later steps of the frame read).
                pub temps: [Vec3; #nt],
                /// Each branch slot's branch.
                pub branches: [Branch; #nk],
                /// Each branch slot's last root, by its sine (rotations to
                /// a condition).
                pub angles: [f64; #nk],
            }

            impl State {
                /// The drawn pose.
                pub const DRAWN: State = State {
                    poses: [Pose3::IDENTITY; #nb],
                    temps: [#(#temps),*],
                    branches: [#(#initial),*],
                    angles: [#(#angles),*],
                };
            }

            #names

            /// The compiled plan, for [`dofplan_runtime::Driver`].
            #[derive(Clone, Copy, Debug, Default)]
            pub struct Plan;

            impl Solver for Plan {
                type Pose = Pose3;
                type State = State;
                type Inputs = [f64; #ni];

                fn initial_state(&self) -> State {
                    State::DRAWN
                }

                fn initial_inputs(&self) -> [f64; #ni] {
                    [0.0; #ni]
                }

                fn poses(state: &State) -> &[Pose3] {
                    &state.poses
                }

                fn solve(&self, s: &mut State, inputs: &[f64], ctx: &mut Ctx) -> Result<(), Break> {
                    solve(s, inputs, ctx)
                }
            }

            impl dofplan_runtime::spatial::Rates3 for Plan {
                #rate_methods
            }

            #solve

            #rates
        }
    }
}

/// Whether every numeric cluster of `plan` fits the fixed-size matrices of
/// generated code: at most [`FIXED_LIMIT`](super::FIXED_LIMIT) unknowns
/// and equations. A spatial cluster has no dynamically sized solver in the
/// runtime to fall back on (a planar one does), so `dofplan::build`
/// refuses a plan that does not fit rather than write a module rustc
/// cannot compile or a frame cannot run on the stack.
pub fn spatial_cluster_fits(plan: &Plan3) -> Result<(), (usize, usize, usize)> {
    for (i, s) in plan.steps.iter().enumerate() {
        if let StepKind3::Cluster(c) = &s.kind {
            let (n, m) = (c.unknowns(), c.equations());
            if n.max(m) > super::FIXED_LIMIT {
                return Err((i + 1, n, m));
            }
        }
    }
    Ok(())
}
/// Rust source of the compiled plan module of `plan`, with functions of
/// at most `chunk_weight` tokens of steps (see
/// [`super::emit_spatial_chunked`]).
pub(super) fn module(plan: &Plan3, chunk_weight: usize) -> String {
    let e = Emitter3 {
        plan,
        notes: RefCell::new(Vec::new()),
        jets: Cell::new(false),
    };
    let steps: Vec<TokenStream> = (0..plan.steps.len()).map(|i| e.step(i)).collect();
    let weights: Vec<usize> = steps.iter().map(|s| Uses::of(s).weight).collect();
    let chunks = partition(&weights, chunk_weight);
    // The steps on jets, for the rates (in the same chunks as `solve`'s).
    e.jets.set(true);
    let jet_steps = (0..plan.steps.len()).map(|i| e.step(i)).collect();
    e.jets.set(false);
    let tokens = e.module(steps, chunks, jet_steps);
    let file = syn::parse2::<syn::File>(tokens).expect("the emitter produces valid Rust");
    let pretty = prettyplease::unparse(&file);
    let notes = e.notes.into_inner();
    let mut out = format!(
        "// @generated by dofplan from {} — do not edit.\n// Compiled plan of spatial mechanism `{}`: {} steps, {} pseudo-markers, {} branch slots.\n// Regenerate with `dofplan emit {}` or by rebuilding the crate that compiles it.\n\n",
        plan.source,
        plan.name,
        plan.steps.len(),
        plan.temps.len(),
        plan.branches.len(),
        plan.source
    );
    // Comments are not tokens: each step and each cluster row was marked by
    // a macro call that is replaced here by its text.
    for line in pretty.lines() {
        let trimmed = line.trim_start();
        let indent = &line[..line.len() - trimmed.len()];
        if let Some(rest) = trimmed.strip_prefix("__dofplan_step!(") {
            let i: usize = rest.trim_end_matches(");").parse().expect("step marker");
            let step = &plan.steps[i];
            let serves = if step.serves.is_empty() {
                String::new()
            } else {
                format!("  [{}]", step.serves.join(", "))
            };
            out.push_str(&format!("{indent}// {i}: {}{serves}\n", step.text));
        } else if let Some(rest) = trimmed.strip_prefix("__dofplan_note!(") {
            let i: usize = rest.trim_end_matches(");").parse().expect("note marker");
            out.push_str(&format!("{indent}// {}\n", notes[i]));
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
}

/// Runs of steps `(first, last)` of at most `limit` tokens each (a larger
/// step stays whole), or `None` when all fit in one function.
fn partition(weights: &[usize], limit: usize) -> Option<Vec<(usize, usize)>> {
    if weights.iter().sum::<usize>() <= limit {
        return None;
    }
    let mut chunks = Vec::new();
    let (mut start, mut weight) = (0, 0);
    for (i, &w) in weights.iter().enumerate() {
        if i > start && weight + w > limit {
            chunks.push((start, i - 1));
            (start, weight) = (i, 0);
        }
        weight += w;
    }
    chunks.push((start, weights.len() - 1));
    Some(chunks)
}
