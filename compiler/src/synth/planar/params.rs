//! A planar mechanism's design parameters and the candidates made from
//! them.

use dofplan_runtime::Solver;

use crate::analysis::analyse;
use crate::interp::Interpreter;
use crate::model::{ConstraintKind, MarkerId, Mechanism};
use crate::plan::design::{DesignTable, PlacedMarker};
use crate::plan::Plan;
use crate::synth::{nodes, SynthError};

/// A planar design's node: markers that move together.
pub type Node = crate::synth::nodes::Node<2>;

/// A planar mechanism seen as a function of its design parameters.
#[derive(Clone, Debug)]
pub struct Design {
    base: Mechanism,
    plan: Plan,
    params: nodes::Parameters<2>,
}

/// A candidate drawing, planned and ready to run frames.
#[derive(Clone, Debug)]
pub struct Candidate {
    /// The mechanism with the candidate's marker positions.
    pub mechanism: Mechanism,
    /// Its plan's interpreter (the original plan's steps, the candidate's
    /// constants and branches).
    pub interpreter: Interpreter,
}

impl Design {
    /// The design of `m`, whose drawing must have a plan (the original
    /// every candidate keeps the topology and step order of).
    pub fn new(m: &Mechanism) -> Result<Design, SynthError> {
        // A gear pair ties its pivots' distance to its radii, which no
        // design parameter moves with them yet.
        if !m.slots.is_empty() {
            return Err(SynthError::Goal {
                reason: format!(
                    "design parameters (synthesis, --sensitivity) are not supported for mechanisms with slots yet (slot {}): a parameter would move a slot's marker off its pin",
                    m.slots.iter().map(|s| s.name.as_str()).collect::<Vec<_>>().join(", ")
                ),
            });
        }
        if !m.gears.is_empty() {
            return Err(SynthError::Goal {
                reason: format!(
                    "design parameters (synthesis, --sensitivity) are not supported for geared mechanisms yet (gear pair {}): their pivots' distance is tied to the pitch radii",
                    m.gear_names()
                ),
            });
        }
        let plan = analyse(m).plan.map_err(|e| SynthError::Plan {
            reason: e.to_string(),
        })?;
        let ties = (m.joints.iter()).map(|j| (j.name.clone(), j.markers)).chain(
            (m.constraints.iter())
                .filter(|c| matches!(c.kind, ConstraintKind::Coincident | ConstraintKind::InLine))
                .map(|c| (c.name.clone(), c.markers)),
        );
        let sizes: Vec<usize> = m.bodies.iter().map(|b| b.markers.len()).collect();
        let all: Vec<MarkerId> = m.all_markers().collect();
        let (kept, node_of) = nodes::group(&sizes, &all, |id| m.marker(id).at, |id| m.marker_name(id), ties);
        Ok(Design {
            base: m.clone(),
            plan,
            params: nodes::Parameters::new(kept, node_of),
        })
    }

    /// The mechanism as drawn.
    pub fn mechanism(&self) -> &Mechanism {
        &self.base
    }

    /// The plan every candidate follows.
    pub fn plan(&self) -> &Plan {
        &self.plan
    }

    /// The nodes, in parameter order (node `n` is parameters `2n`, `2n + 1`).
    pub fn nodes(&self) -> &[Node] {
        self.params.nodes()
    }

    /// The parameters: nodes, names and drawn values.
    pub fn parameters(&self) -> &nodes::Parameters<2> {
        &self.params
    }

    /// The parameters' names, in order: `NAME.x`, `NAME.y` per node.
    pub fn names(&self) -> &[String] {
        self.params.names()
    }

    /// The index of a parameter by name.
    pub fn index(&self, name: &str) -> Result<usize, SynthError> {
        self.params.index(name)
    }

    /// The node a marker moves with.
    pub fn node_of(&self, id: MarkerId) -> usize {
        self.params.node_of(id)
    }

    /// Every marker's node, body by body (`[body][marker]`).
    pub fn node_table(&self) -> &[Vec<usize>] {
        self.params.node_table()
    }

    /// The parameters' drawn values.
    pub fn drawn(&self) -> Vec<f64> {
        self.params.drawn()
    }

    /// The parameters as a back end needs them: each marker's node and
    /// drawn offset ([`crate::emit::emit_design`] writes a compiled
    /// module's `prepare` from it).
    pub fn table(&self) -> DesignTable<2> {
        let markers = (self.params.nodes().iter().enumerate())
            .flat_map(|(node, n)| {
                n.markers.iter().map(move |(id, offset)| {
                    let placed = PlacedMarker {
                        node,
                        offset: *offset,
                        drawn: self.base.marker(*id).at,
                    };
                    (self.base.marker_name(*id), placed)
                })
            })
            .collect();
        DesignTable {
            names: self.names().to_vec(),
            drawn: self.drawn(),
            markers,
        }
    }

    /// The mechanism with the markers where `values` put them.
    pub fn drawing(&self, values: &[f64]) -> Result<Mechanism, SynthError> {
        let mut m = self.base.clone();
        let base = &self.base;
        self.params.place(
            values,
            |id| base.marker(id).at,
            |id, k, v| {
                m.bodies[id.body].markers[id.marker].at[k] = v;
            },
        )?;
        Ok(m)
    }

    /// The candidate drawn at `values`, planned as a file is, whatever its
    /// steps: a Monte-Carlo candidate that moves the drawing's special
    /// geometry apart is a mechanism of its own, planned differently.
    pub fn prepare_any(&self, values: &[f64]) -> Result<Candidate, SynthError> {
        let mechanism = self.drawing(values)?;
        let plan = analyse(&mechanism).plan.map_err(|e| SynthError::Plan {
            reason: e.to_string(),
        })?;
        Ok(Candidate {
            mechanism,
            interpreter: Interpreter::new(plan),
        })
    }

    /// The candidate drawn at `values`: planned as a file is (constants from
    /// the new drawing, branches chosen so the plan reproduces it), with the
    /// original plan's steps in the original order.
    pub fn prepare(&self, values: &[f64]) -> Result<Candidate, SynthError> {
        let c = self.prepare_any(values)?;
        if let Some(i) = first_difference(&self.plan, c.interpreter.plan()) {
            return Err(SynthError::PlanChanged {
                step: self.plan.explain(i),
            });
        }
        Ok(c)
    }
}

/// The first step at which `b` is not the same plan as `a` up to its
/// constants (`Some(steps)` when `b` has another length).
fn first_difference(a: &Plan, b: &Plan) -> Option<usize> {
    let same = |i: usize| {
        let (x, y) = (&a.steps[i], &b.steps[i]);
        std::mem::discriminant(&x.kind) == std::mem::discriminant(&y.kind)
            && x.kind.writes() == y.kind.writes()
            && x.kind.computes() == y.kind.computes()
            && x.kind.branch() == y.kind.branch()
            && x.kind.cluster_size() == y.kind.cluster_size()
            && x.serves == y.serves
    };
    let n = a.steps.len().min(b.steps.len());
    (0..n)
        .find(|&i| !same(i))
        .or((a.steps.len() != b.steps.len()).then_some(n.min(a.steps.len().saturating_sub(1))))
}

impl Candidate {
    /// The frame at the drawn pose (every input 0), which a candidate
    /// reproduces by construction: the state to run its frames from.
    pub fn initial_state(&self) -> <Interpreter as Solver>::State {
        self.interpreter.initial_state()
    }
}
