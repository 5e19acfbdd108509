//! Planar plans: a [`Plan`] becomes one straight-line module. Bodies live
//! in a fixed-size array in the state struct, so a frame allocates
//! nothing. Each step's code is written by `step`; a large plan's steps
//! are split into functions of bounded size (see `chunk`), so that rustc
//! compiles a mechanism of any size, and its repeated steps are rolled
//! into loops over tables (see `roll`); numeric clusters are written by
//! `cluster`, and the steps on jets and lanes by `rates`.

use proc_macro2::{Ident, Span, TokenStream};
use quote::quote;

mod chunk;
mod cluster;
mod design;
mod forces;
mod rates;
mod roll;
mod step;

pub use chunk::CHUNK_WEIGHT;
pub use cluster::FIXED_LIMIT;
pub(super) use design::design_module;
pub(super) use forces::forces_module;

use super::scaffold::{self, Dimension, Field, Scaffold};
use super::{ident_for, index, lit, step_comments, uses, Sink};
use crate::model::InputKind;
use crate::plan::{Plan, StepKind};

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

fn point_lit(p: [f64; 2]) -> TokenStream {
    let (x, y) = (lit(p[0]), lit(p[1]));
    quote!([#x, #y])
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
    /// With `jets` and `design`: the steps are written for the design
    /// module's `gradient`, on `Dual`s (a
    /// [`Tangent`](dofplan_runtime::real::Tangent) per design parameter).
    dual: bool,
    /// While a step is written for a rolled run (see [`roll`]): its
    /// constants go to a table row instead of the code.
    row: std::cell::RefCell<Option<roll::Recording>>,
    /// The step computing each point.
    temp_steps: Vec<usize>,
    /// The tables of the rolled runs written so far, by first step: their
    /// module and rows, for the jets' functions to share.
    tables: std::cell::RefCell<std::collections::HashMap<usize, (Ident, Vec<roll::Row>)>>,
    /// While the design module is written (see [`design`]): the design
    /// parameters, and each number of the plan the code reads from the
    /// candidate's geometry instead of a literal, with where it comes from.
    design: Option<design::Recording<'p>>,
}

impl Emitter<'_> {
    /// The number type constants are lifted to (with `jets`).
    fn num(&self) -> TokenStream {
        if self.lanes {
            quote!(Lanes)
        } else if self.dual {
            quote!(Dual)
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
                    | StepKind::Within { .. }
                    | StepKind::Align { redundant: true, .. }
            )
        })
    }

    /// The binding of input `k` to its local.
    fn bind_input(&self, k: usize) -> TokenStream {
        let id = &self.input_idents[k];
        let i = index(k);
        match self.plan.inputs[k].kind {
            // The inputs are held: constants of the parameters' derivatives.
            InputKind::Angle if self.dual => {
                quote!(let #id = Rot::<Dual>::cst(Rot::from_degrees(inputs[#i]));)
            }
            InputKind::Slide if self.dual => quote!(let #id = Dual::cst(inputs[#i]);),
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
        // The design module's frame reads the candidate's numbers from
        // its geometry (`g.f`), all else as `solve`.
        let head = if self.design.is_some() {
            quote!(pub fn solve_with(g: &Geometry, s: &mut State, inputs: &[f64], ctx: &mut Ctx) -> Result<(), Break>)
        } else {
            quote!(pub fn solve(s: &mut State, inputs: &[f64], ctx: &mut Ctx) -> Result<(), Break>)
        };
        let unused_g = if self.design.as_ref().is_some_and(|d| d.is_empty()) {
            quote!(let _ = g;)
        } else {
            quote!()
        };
        quote! {
            #[doc = #doc_solve]
            #[inline]
            #head {
                #unused_g
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

    /// The module up to `solve`: imports, then the scaffold (names,
    /// `State`, the constants and `Plan` with its trait impls). `real`:
    /// whether the steps on jets or lanes lift constants (`Jet2::cst`,
    /// `Lanes::cst`, which need the `Real` trait); `lanes`: whether
    /// `solve_batch` runs in lanes.
    fn prefix(&self, real: bool, lanes: bool, sink: &mut Sink) {
        let plan = self.plan;
        let numeric_use = if plan.clusters() > 0 {
            quote!(
                use dofplan_runtime::numeric;
                use dofplan_runtime::planar::cluster;
            )
        } else {
            quote!()
        };
        // `Jet2::cst` and `Lanes::cst` need the trait (a plan of large clusters alone, whose
        // rates the runtime computes, has none).
        let real = if real { quote!(Real) } else { quote!() };
        let lanes_use = if lanes {
            quote!(
                use dofplan_runtime::lanes::Lanes;
            )
        } else {
            quote!()
        };
        let imports = quote! {
            use dofplan_runtime::planar::{self, Point, Pose, Rot};
            use dofplan_runtime::{Branch, Break, Ctx, Marker, Solver};
            #numeric_use
            use dofplan_runtime::real::{self, Jet2, RateError, #real};
            use dofplan_runtime::BranchPolicy;
            #lanes_use
        };
        let nk = index(plan.branches.len());
        let drawn = plan.branches.iter().map(|b| point_lit(b.drawn));
        let initial = plan.branches.iter().map(|b| match b.initial {
            dofplan_runtime::Branch::Plus => quote!(Branch::Plus),
            dofplan_runtime::Branch::Minus => quote!(Branch::Minus),
        });
        let scaffold = Scaffold {
            dim: Dimension::planar(),
            name: &plan.mechanism,
            bodies: plan.bodies.iter().map(|b| b.name.as_str()).collect(),
            fixed: plan.bodies.iter().map(|b| b.fixed).collect(),
            inputs: plan.inputs.iter().map(|i| (i.name.as_str(), i.kind)).collect(),
            steps: plan.steps.len(),
            markers: plan
                .bodies
                .iter()
                .enumerate()
                .flat_map(|(i, b)| {
                    b.markers
                        .iter()
                        .map(move |(m, at)| (i, format!("{}.{m}", b.name), &at[..]))
                })
                .collect(),
            fields: vec![
                Field {
                    doc: &[" Each branching step's last root (nearest-root policy)."],
                    name: "last",
                    ty: quote!([Point; #nk]),
                    drawn: quote!([#(#drawn),*]),
                },
                Field {
                    doc: &[" Each branching step's branch."],
                    name: "branches",
                    ty: quote!([Branch; #nk]),
                    drawn: quote!([#(#initial),*]),
                },
            ],
            independent: lanes.then_some("in lanes"),
        };
        scaffold.head(imports, sink);
        scaffold.plan(sink);
    }

    /// The doc comment of `solve`.
    fn doc_solve(&self) -> String {
        scaffold::doc_solve(self.plan.inputs.iter().map(|i| (i.name.as_str(), i.kind)))
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
}

impl<'p> Emitter<'p> {
    /// The emitter of `plan`'s module, its identifiers chosen.
    fn new(plan: &'p Plan) -> Emitter<'p> {
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
        Emitter {
            plan,
            input_idents,
            temp_idents,
            pose_idents,
            chunked: false,
            jets: false,
            lanes: false,
            dual: false,
            row: Default::default(),
            temp_steps: chunk::temp_steps(plan),
            tables: Default::default(),
            design: None,
        }
    }
}

/// Rust source of the compiled plan module of `plan`, with functions of
/// at most `chunk_weight` tokens of steps (see [`super::emit_chunked`]).
pub(super) fn module(plan: &Plan, chunk_weight: usize) -> String {
    let mut e = Emitter::new(plan);
    // Each step's code is made to be measured and then dropped: a large
    // plan's steps are made again, chunk by chunk, as they are written.
    let kinds: Vec<&StepKind> = plan.steps.iter().map(|s| &s.kind).collect();
    let mut uses: Vec<uses::Uses> = (0..plan.steps.len())
        .map(|i| uses::Uses::of(&e.step(i)))
        .collect();
    let weights: Vec<usize> = uses.iter().map(|u| u.weight).collect();
    let chunks = chunk::partition(&kinds, &weights, chunk_weight, || e.runs());
    let header = scaffold::header(
        &plan.source,
        &format!(
            "mechanism `{}`: {} steps, {} branch slots",
            plan.mechanism,
            plan.steps.len(),
            plan.branches.len()
        ),
    );
    let serves = plan.steps.iter().map(|s| s.serves.as_slice());
    let comments = step_comments(serves.zip(plan.explanations()), &plan.source, &plan.joint_lines);
    let mut sink = Sink::new(header, comments);
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
            // `cst` and `mul_f64` are the `Real` trait's: imported when used.
            let fused_code = fused.to_string();
            let real = ["Jet2 :: cst", "Lanes :: cst", "mul_f64"]
                .iter()
                .any(|n| fused_code.contains(n) || lane_code.contains(n));
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
                    let code_text = code.to_string();
                    real |= code_text.contains("Jet2 :: cst") || code_text.contains("mul_f64");
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
    sink.finish()
}
