//! Large plans as several functions: rustc overflows its stack on a
//! function of a few thousand steps in a debug build, and optimising one
//! takes time and memory superlinear in its size. So a plan whose steps
//! weigh more than [`CHUNK_WEIGHT`] tokens is split into runs of steps of
//! at most that weight (a larger step stays whole), each the function
//! `run` of a module `steps_<first>_to_<last>`, which `solve` calls in
//! order. The modules matter: rustc makes one LLVM unit of a module's
//! functions (in debug builds always, in release builds before merging
//! units down to 16), and the unit's size sets rustc's peak memory.
//!
//! The chunks work in place on the state, and `solve` puts back a copy of
//! it on a break, so a break still leaves the state as it was. A chunk
//! reads the poses it uses from the state into the same named locals as
//! the one-function form (so each step's code is the same in both forms),
//! and writes back the ones it wrote; a point a later chunk uses is handed
//! on in `Working::temps`. `solve_rates` runs the same chunks on jets over
//! a working copy (its caller's `out`). A plan of at most
//! [`CHUNK_WEIGHT`] keeps the one-function form.

use std::collections::{HashMap, HashSet};
use std::ops::Range;

use proc_macro2::{Literal, TokenStream};
use quote::{format_ident, quote};

use super::roll::Run;
use super::uses::{param, Uses};
use super::{index, Emitter, Sink};
use crate::plan::{Plan, StepKind};

/// The most tokens of step code one generated function holds (a single
/// larger step, such as a big numeric cluster, gets a function of its
/// own). About 280 closed-form steps of a stress chain; Stress-50 (152
/// steps) and every bundled mechanism stay one function.
pub const CHUNK_WEIGHT: usize = 12_000;

/// What the chunks of a split plan hand each other: where each point is
/// computed and, when a later chunk reads it, its slot in
/// `Working::temps`; and the frame locals by name, to find what a chunk's
/// code names.
struct Handoff {
    /// Pose locals by name: their body.
    pose_of: HashMap<String, usize>,
    /// Point locals by name: their temp.
    temp_of: HashMap<String, usize>,
    /// The chunk computing each temp (`usize::MAX`: none).
    defined_in: Vec<usize>,
    /// Each temp's slot in `Working::temps`, if a later chunk reads it.
    slot: Vec<Option<Literal>>,
}

impl Handoff {
    /// The bodies or temps (by `of`) that code with uses `u` names, in order.
    fn named(&self, u: &Uses, of: &HashMap<String, usize>) -> Vec<usize> {
        let mut found: Vec<usize> = u.idents().filter_map(|id| of.get(id).copied()).collect();
        found.sort_unstable();
        found
    }
}

/// A run of steps that becomes one function.
pub(super) struct Chunk {
    steps: Range<usize>,
    /// Whether the steps repeat and are rolled into a loop (see
    /// [`roll`](super::roll)).
    rolled: Option<Run>,
}

/// The step computing each point of `plan`.
pub(super) fn temp_steps(plan: &Plan) -> Vec<usize> {
    let mut at = vec![usize::MAX; plan.temps.len()];
    for (i, step) in plan.steps.iter().enumerate() {
        if let Some(t) = out(&step.kind) {
            at[t] = i;
        }
    }
    at
}

/// The point a step computes, if any.
fn out(kind: &StepKind) -> Option<usize> {
    match kind {
        StepKind::CircleCircle { out, .. }
        | StepKind::CircleLine { out, .. }
        | StepKind::LineLine { out, .. } => Some(*out),
        _ => None,
    }
}

/// Whether step `i` must start a chunk: a large numeric cluster hands the
/// runtime every pose at once, which it reads from the working copy, so
/// no earlier step of its chunk may hold a pose in a local.
pub(super) fn starts_chunk(kind: &StepKind) -> bool {
    match kind {
        StepKind::Cluster { .. } => {
            let (n, m) = kind.cluster_size();
            !Emitter::fixed_cluster(n, m)
        }
        _ => false,
    }
}

/// The chunks of a plan whose steps weigh `weights`, or `None` when they
/// fit in one function of `limit`. Each of the `runs` (made only when the
/// plan is split) is a chunk of its own; the steps between them are packed
/// into chunks of at most `limit`.
pub(super) fn partition(
    kinds: &[&StepKind],
    weights: &[usize],
    limit: usize,
    runs: impl FnOnce() -> Vec<Run>,
) -> Option<Vec<Chunk>> {
    if weights.iter().sum::<usize>() <= limit {
        return None;
    }
    let mut chunks = Vec::new();
    let pack = |steps: Range<usize>, chunks: &mut Vec<Chunk>| {
        if steps.is_empty() {
            return;
        }
        let (mut start, mut weight) = (steps.start, 0);
        for i in steps.clone() {
            if i > start && (weight + weights[i] > limit || starts_chunk(kinds[i])) {
                chunks.push(Chunk {
                    steps: start..i,
                    rolled: None,
                });
                (start, weight) = (i, 0);
            }
            weight += weights[i];
        }
        chunks.push(Chunk {
            steps: start..steps.end,
            rolled: None,
        });
    };
    let mut next = 0;
    for run in runs() {
        pack(next..run.steps.start, &mut chunks);
        next = run.steps.end;
        chunks.push(Chunk {
            steps: run.steps.clone(),
            rolled: Some(run),
        });
    }
    pack(next..weights.len(), &mut chunks);
    Some(chunks)
}

impl Emitter<'_> {
    /// `solve` over a working copy of the state, calling one function per
    /// chunk; with `self.jets`, `solve_rates` (the same chunks on jets).
    /// `uses` are the [`Uses`] of each step's code. The items go to `sink`
    /// one at a time, each chunk's steps made again just before their
    /// function is written: the module is never held whole, as tokens or
    /// as a syntax tree, so emitting takes memory in proportion to one
    /// chunk rather than to the plan.
    pub(super) fn chunked_solve(&self, uses: Vec<Uses>, chunks: &[Chunk], doc_solve: &str, sink: &mut Sink) {
        let jets = self.jets;
        let plan = self.plan;
        // What each chunk's steps use.
        let mut step_uses = uses.into_iter();
        let uses: Vec<Uses> = chunks
            .iter()
            .map(|chunk| {
                let mut u = Uses::default();
                for s in step_uses.by_ref().take(chunk.steps.len()) {
                    // A rolled run names no frame local: it works on the
                    // state itself, and its points are its own.
                    if chunk.rolled.is_none() {
                        u.merge(s);
                    }
                }
                u
            })
            .collect();
        let chunk_of: Vec<usize> = chunks
            .iter()
            .enumerate()
            .flat_map(|(c, chunk)| chunk.steps.clone().map(move |_| c))
            .collect();
        // Where each point is computed, and which chunks use it.
        let mut defined_in = vec![usize::MAX; plan.temps.len()];
        for (i, step) in plan.steps.iter().enumerate() {
            if let Some(t) = out(&step.kind) {
                defined_in[t] = chunk_of[i];
            }
        }
        // The bodies and points each chunk names, found from its own
        // identifiers (never by a scan of every body per chunk, which made
        // emitting quadratic in the plan's length).
        let mut handoff = Handoff {
            pose_of: (0..plan.bodies.len())
                .filter(|&b| !plan.bodies[b].fixed)
                .map(|b| (self.pose_idents[b].to_string(), b))
                .collect(),
            temp_of: (self.temp_idents.iter().enumerate())
                .map(|(t, id)| (id.to_string(), t))
                .collect(),
            defined_in,
            slot: vec![None; plan.temps.len()],
        };
        let mut last_use = vec![0; plan.temps.len()];
        for (c, u) in uses.iter().enumerate() {
            for t in handoff.named(u, &handoff.temp_of) {
                last_use[t] = c;
            }
        }
        // The points a later chunk reads get a slot in `Working::temps`.
        let mut slots = 0;
        for (t, &c) in handoff.defined_in.iter().enumerate() {
            if c != usize::MAX && last_use[t] > c {
                handoff.slot[t] = Some(index(slots));
                slots += 1;
            }
        }
        let (prefix, of) = if jets {
            ("rates_", "solve_rates")
        } else {
            ("", "solve")
        };
        // Each chunk's function name and doc comment.
        let names: Vec<(proc_macro2::Ident, String)> = chunks
            .iter()
            .map(|chunk| {
                let (first, last) = (chunk.steps.start, chunk.steps.end - 1);
                if first == last {
                    (
                        format_ident!("{}step_{}", prefix, first),
                        format!(" Step {first} of [`{of}`], on its working copy."),
                    )
                } else {
                    (
                        format_ident!("{}steps_{}_to_{}", prefix, first, last),
                        format!(" Steps {first} to {last} of [`{of}`], on its working copy."),
                    )
                }
            })
            .collect();
        let calls: Vec<TokenStream> = names
            .iter()
            .map(|(f, _)| {
                if jets {
                    quote!(#f::run(s, &mut w, &inputs, ctx)?;)
                } else {
                    quote!(#f::run(s, &mut w, inputs, ctx)?;)
                }
            })
            .collect();
        if jets {
            sink.push(self.chunked_solve_rates(calls, slots));
        } else {
            sink.push(self.chunked_solve_head(calls, slots, doc_solve));
        }

        for (c, chunk) in chunks.iter().enumerate() {
            if let Some(run) = &chunk.rolled {
                let (f, doc) = &names[c];
                self.rolled_chunk(run, f, doc, sink);
                continue;
            }
            let (f, doc) = &names[c];
            sink.push(self.chunk_module(chunk, c, &uses[c], &handoff, f, doc));
        }
    }

    /// Chunk `c` of a split plan as a module of its own, whose `run` reads
    /// the poses, points and inputs its steps name (`u`) from the state and
    /// from what earlier chunks handed on (`h`), and writes back what it
    /// changed.
    fn chunk_module(
        &self,
        chunk: &Chunk,
        c: usize,
        u: &Uses,
        h: &Handoff,
        f: &proc_macro2::Ident,
        doc: &str,
    ) -> TokenStream {
        let code: Vec<TokenStream> = chunk.steps.clone().map(|i| self.step(i)).collect();
        let uses = |ident: &str| u.has(ident);
        let written: HashSet<usize> = chunk
            .steps
            .clone()
            .flat_map(|i| self.plan.steps[i].kind.writes())
            .collect();
        let mut take = Vec::new();
        let mut commit = Vec::new();
        let mut state_used = false;
        for b in h.named(u, &h.pose_of) {
            let id = &self.pose_idents[b];
            let i = index(b);
            // On values the chunks work in place on the state; on jets,
            // on the working poses (the caller's `out`).
            let poses = if self.jets {
                quote!(w.poses)
            } else {
                quote!(s.poses)
            };
            state_used = true;
            if written.contains(&b) {
                take.push(quote!(let mut #id = #poses[#i];));
                commit.push(quote!(#poses[#i] = #id;));
            } else {
                take.push(quote!(let #id = #poses[#i];));
            }
        }
        for t in h.named(u, &h.temp_of) {
            let Some(k) = &h.slot[t] else { continue };
            let id = &self.temp_idents[t];
            if h.defined_in[t] == c {
                commit.push(quote!(w.temps[#k] = #id;));
            } else if h.defined_in[t] < c {
                take.push(quote!(let #id = w.temps[#k];));
            }
        }
        let mut reads_inputs = uses("inputs");
        for k in 0..self.plan.inputs.len() {
            if uses(&self.input_idents[k].to_string()) {
                take.push(self.bind_input(k));
                reads_inputs = true;
            }
        }
        for field in ["branches", "last"] {
            if uses(field) {
                let f = format_ident!("{}", field);
                if self.jets {
                    take.insert(0, quote!(let #f = &mut w.#f;));
                } else {
                    take.insert(0, quote!(let #f = &mut s.#f;));
                    state_used = true;
                }
            }
        }
        let s = param("s", uses("s") || (state_used && !self.jets));
        let w = param(
            "w",
            self.jets || uses("w") || commit.iter().chain(&take).any(|t| Uses::of(t).has("w")),
        );
        let inputs = param("inputs", reads_inputs);
        let ctx = param("ctx", uses("ctx"));
        // Each chunk is a module of its own: rustc hands a module's
        // functions to LLVM as one unit (always, in a debug build), and
        // one unit holding every chunk of a 2,000-loop chain took 5 GB.
        if self.jets {
            quote! {
                #[doc = #doc]
                mod #f {
                    use super::*;

                    #[inline(never)]
                    pub(super) fn run(#s: &State, #w: &mut JetWorking<'_>, #inputs: &[Jet2], #ctx: &mut Ctx) -> Result<(), RateError> {
                        #(#take)*
                        #(#code)*
                        #(#commit)*
                        Ok(())
                    }
                }
            }
        } else {
            quote! {
                #[doc = #doc]
                mod #f {
                    use super::*;

                    #[inline(never)]
                    pub(super) fn run(#s: &mut State, #w: &mut Working, #inputs: &[f64], #ctx: &mut Ctx) -> Result<(), Break> {
                        #(#take)*
                        #(#code)*
                        #(#commit)*
                        Ok(())
                    }
                }
            }
        }
    }

    /// `solve` of the split form, which calls the chunks (`calls`) in place
    /// on the state, and the `Working` struct of the `slots` points chunks
    /// hand on.
    fn chunked_solve_head(&self, calls: Vec<TokenStream>, slots: usize, doc_solve: &str) -> TokenStream {
        let nt = index(slots);
        // Points handed on, if any chunk hands one on.
        let (temps_init, temps_field) = if slots == 0 {
            (quote!(), quote!())
        } else {
            (quote!(temps: [[0.0; 2]; #nt],), quote!(temps: [Point; #nt],))
        };
        quote! {
            #[doc = #doc_solve]
            #[inline]
            pub fn solve(s: &mut State, inputs: &[f64], ctx: &mut Ctx) -> Result<(), Break> {
                // The chunks place the bodies in `s` itself, and a break (an
                // early return) puts this copy back: `s` is left as it was,
                // so no caller has to copy the state per frame to roll back.
                // One copy of the state a frame: a working copy committed at
                // the end was two, and made the split form slower than the
                // interpreter.
                let was = *s;
                let result = run_chunks(s, inputs, ctx);
                if result.is_err() {
                    *s = was;
                }
                result
            }

            /// The chunks of steps in order, in place on `s`.
            #[inline]
            fn run_chunks(s: &mut State, inputs: &[f64], ctx: &mut Ctx) -> Result<(), Break> {
                let mut w = Working { #temps_init };
                #(#calls)*
                Ok(())
            }

            /// The points a chunk of steps hands to later ones.
            struct Working {
                #temps_field
            }
        }
    }

    /// `solve_rates` over a jet working copy of the state, calling the
    /// chunks' jet functions: the frame committed as `solve` commits it,
    /// its values exactly `solve`'s.
    fn chunked_solve_rates(&self, calls: Vec<TokenStream>, slots: usize) -> TokenStream {
        let plan = self.plan;
        let (nb, nk, nt, ni) = (
            index(plan.bodies.len()),
            index(plan.branches.len()),
            index(slots),
            index(plan.inputs.len()),
        );
        let (temps_init, temps_field) = if slots == 0 {
            (quote!(), quote!())
        } else {
            (
                quote!(temps: [planar::cst([0.0; 2]); #nt],),
                quote!(temps: [[Jet2; 2]; #nt],),
            )
        };
        // The chunks work on the poses in `out` itself.
        let body = quote! {
            let inputs: [Jet2; #ni] =
                core::array::from_fn(|k| Jet2::new(inputs[k], rates[k], accelerations[k]));
            for (o, p) in out.iter_mut().zip(&s.poses) {
                *o = Pose::<Jet2>::cst(*p);
            }
            let mut w = JetWorking {
                poses: out,
                last: s.last.map(planar::cst::<Jet2>),
                branches: s.branches,
                #temps_init
            };
            #(#calls)*
            for (p, o) in s.poses.iter_mut().zip(w.poses.iter()) {
                *p = o.value();
            }
            s.last = w.last.map(|p| [p[0].v, p[1].v]);
            s.branches = w.branches;
            real::checked(&*w.poses).map(|_| ())
        };
        let api = super::scaffold::rates_functions(&quote!(Pose), &nb, body);
        quote! {
            #api

            /// A frame's working copy of the state on jets, and the points a
            /// chunk of steps hands to later ones.
            struct JetWorking<'a> {
                poses: &'a mut [Pose<Jet2>; #nb],
                last: [[Jet2; 2]; #nk],
                branches: [Branch; #nk],
                #temps_field
            }
        }
    }
}
