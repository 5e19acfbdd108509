//! The Rust back end of spatial plans: a [`Plan`] becomes a module of the
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
//! closure (see [`cluster`]).
//!
//! Unlike a planar module, the state itself is the working set: poses,
//! pseudo-markers and branch slots are read and written in place in the
//! copy. So a large plan splits into functions of bounded size that take
//! the copy by reference, with nothing to hand from one to the next.
use std::cell::{Cell, RefCell};

use proc_macro2::{Ident, TokenStream};
use quote::{format_ident, quote};

use dofplan_runtime::Branch;

mod cluster;
mod rates;
mod step;

use super::scaffold::{self, Dimension, Field, Scaffold};
use super::uses::Uses;
use super::{index, lit, step_comments, Sink};
use crate::plan::spatial::{Plan, StepKind};
use step::vec_lit;

/// Why `solve` works on a copy, as its comment says.
const COPY: &str = "Keep a copy to restore on a break (an early return) and work on `s` itself: a break leaves `s` as it was, no caller has to copy the state per frame to roll back, and a frame copies the state once.";

/// Writes one spatial plan's module.
pub(super) struct Emitter<'p> {
    /// The plan.
    pub plan: &'p Plan,
    /// Comments inside a step (a cluster's rows), by the index their
    /// placeholder names.
    pub notes: RefCell<Vec<String>>,
    /// Whether steps are written for `solve_rates` (on jets).
    pub jets: Cell<bool>,
}

impl Emitter<'_> {
    /// A placeholder statement that becomes the comment `// text`.
    pub fn note(&self, text: String) -> TokenStream {
        let mut notes = self.notes.borrow_mut();
        let i = index(notes.len());
        notes.push(text);
        quote!(__dofplan_note!(#i);)
    }
}

impl Emitter<'_> {
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
            .any(|s| !matches!(s.kind, StepKind::Check { .. }));
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
            // Named by the steps' numbers, as the comments (and a planar
            // module's chunks) number them, from 0.
            let (f, fdoc) = if first == last {
                (
                    format_ident!("step_{}", first),
                    format!(" Step {first} of [`solve`], in place."),
                )
            } else {
                (
                    format_ident!("steps_{}_to_{}", first, last),
                    format!(" Steps {first} to {last} of [`solve`], in place."),
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

    /// The module's imports: what the steps use, and no more (an unused
    /// import would warn in the user's crate).
    /// `real`: whether the steps on jets call methods of the `Real` trait
    /// (`Jet2::cst`, `mul_f64`).
    fn imports(&self, u: &Uses, real: bool) -> TokenStream {
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
        let real = if real { quote!(Real) } else { quote!() };
        imports.push(quote!(
            use dofplan_runtime::real::{Jet2, RateError, #real};
        ));
        imports.push(quote!(
            use dofplan_runtime::BranchPolicy;
        ));
        quote!(#(#imports)*)
    }

    /// The scaffold of the module (see [`scaffold`]).
    fn scaffold(&self) -> Scaffold<'_> {
        let plan = self.plan;
        let (nt, nk) = (index(plan.temps.len()), index(plan.branches.len()));
        let temps = plan.temps.iter().map(|t| vec_lit(t.drawn));
        let initial = plan.branches.iter().map(|b| match b.initial {
            Branch::Plus => quote!(Branch::Plus),
            Branch::Minus => quote!(Branch::Minus),
        });
        let angles = plan.branches.iter().map(|b| lit(b.angle));
        Scaffold {
            dim: Dimension::spatial(),
            name: &plan.name,
            bodies: plan.bodies.iter().map(String::as_str).collect(),
            fixed: plan.fixed.clone(),
            inputs: plan
                .inputs
                .iter()
                .map(String::as_str)
                .zip(plan.input_kinds.iter().copied())
                .collect(),
            steps: plan.steps.len(),
            markers: plan
                .markers
                .iter()
                .enumerate()
                .flat_map(|(i, ms)| {
                    ms.iter()
                        .map(move |(m, at)| (i, format!("{}.{m}", plan.bodies[i]), &at[..]))
                })
                .collect(),
            fields: vec![
                Field {
                    doc: &[
                        " Each pseudo-marker's last position (nearest-root policy,",
                        " and the point later steps of the frame read).",
                    ],
                    name: "temps",
                    ty: quote!([Vec3; #nt]),
                    drawn: quote!([#(#temps),*]),
                },
                Field {
                    doc: &[" Each branch slot's branch."],
                    name: "branches",
                    ty: quote!([Branch; #nk]),
                    drawn: quote!([#(#initial),*]),
                },
                Field {
                    doc: &[
                        " Each branch slot's last root, by its sine (rotations to",
                        " a condition).",
                    ],
                    name: "angles",
                    ty: quote!([f64; #nk]),
                    drawn: quote!([#(#angles),*]),
                },
            ],
            // A frame moves each body from its last pose (idle freedoms
            // and composed rotations carry over): frames in order.
            independent: None,
        }
    }

    /// The whole module into `sink`: imports, the scaffold, `solve` and
    /// the rates.
    fn module(
        &self,
        steps: Vec<TokenStream>,
        chunks: Option<Vec<(usize, usize)>>,
        jet_steps: Vec<TokenStream>,
        sink: &mut Sink,
    ) {
        let plan = self.plan;
        let u = Uses::of(&quote!(#(#steps)*));
        let rates = self.rates(jet_steps, chunks.as_deref());
        let doc_solve = scaffold::doc_solve(
            plan.inputs
                .iter()
                .map(String::as_str)
                .zip(plan.input_kinds.iter().copied()),
        );
        let solve = self.solve(steps, &u, chunks, &doc_solve);
        let scaffold = self.scaffold();
        sink.notes = self.notes.take();
        let jets = rates.to_string();
        let real = ["Jet2 :: cst", "mul_f64"].iter().any(|m| jets.contains(m));
        scaffold.head(self.imports(&u, real), sink);
        scaffold.plan(sink);
        sink.push(solve);
        sink.push(rates);
    }
}

/// Whether every numeric cluster of `plan` fits the fixed-size matrices of
/// generated code: at most [`FIXED_LIMIT`](super::FIXED_LIMIT) unknowns
/// and equations. A spatial cluster has no dynamically sized solver in the
/// runtime to fall back on (a planar one does), so `dofplan::build`
/// refuses a plan that does not fit rather than write a module rustc
/// cannot compile or a frame cannot run on the stack.
pub fn spatial_cluster_fits(plan: &Plan) -> Result<(), (usize, usize, usize)> {
    for (i, s) in plan.steps.iter().enumerate() {
        if let StepKind::Cluster(c) = &s.kind {
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
pub(super) fn module(plan: &Plan, chunk_weight: usize) -> String {
    let e = Emitter {
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
    let header = scaffold::header(
        &plan.source,
        &format!(
            "spatial mechanism `{}`: {} steps, {} pseudo-markers, {} branch slots",
            plan.name,
            plan.steps.len(),
            plan.temps.len(),
            plan.branches.len()
        ),
    );
    let serves = plan.steps.iter().enumerate();
    let serves = serves.map(|(i, s)| (s.serves.as_slice(), plan.explain(i)));
    let comments = step_comments(serves, &plan.source, &plan.joint_lines);
    let mut sink = Sink::new(header, comments);
    e.module(steps, chunks, jet_steps, &mut sink);
    sink.finish()
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
