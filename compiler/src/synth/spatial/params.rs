//! A spatial mechanism's design parameters and the candidates made from
//! them: as the planar ones (`synth/planar/params.rs`), three coordinates
//! a point.

use crate::analysis::spatial::analyse;
use crate::interp::spatial::Interpreter;
use crate::model::spatial::{Mechanism, Primitive};
use crate::model::MarkerId;
use crate::plan::spatial::Plan;
use crate::synth::{nodes, SynthError};

/// A spatial design's node: markers that move together.
pub type Node = nodes::Node<3>;

/// A spatial mechanism seen as a function of its design parameters.
#[derive(Clone, Debug)]
pub struct Design {
    base: Mechanism,
    plan: Plan,
    params: nodes::Parameters<3>,
}

/// A candidate drawing, planned and ready to run frames.
#[derive(Clone, Debug)]
pub struct Candidate {
    /// The mechanism with the candidate's marker positions.
    pub mechanism: Mechanism,
    /// Its plan's interpreter.
    pub interpreter: Interpreter,
}

impl Design {
    /// The design of `m`, whose drawing must have a plan.
    pub fn new(m: &Mechanism) -> Result<Design, SynthError> {
        let plan = analyse(m).map_err(|e| SynthError::Plan {
            reason: e.to_string(),
        })?;
        // Joints tie their markers; so do constraints that hold a point on
        // a point, a line or a plane.
        let ties = (m.joints.iter()).map(|j| (j.name.clone(), j.markers)).chain(
            (m.constraints.iter())
                .filter(|c| {
                    matches!(
                        c.kind,
                        Primitive::Coincident | Primitive::InLine | Primitive::InPlane
                    )
                })
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

    /// The nodes, in parameter order (node `n` is parameters `3n` to `3n + 2`).
    pub fn nodes(&self) -> &[Node] {
        self.params.nodes()
    }

    /// The parameters' names: `NAME.x`, `NAME.y`, `NAME.z` per node.
    pub fn names(&self) -> &[String] {
        self.params.names()
    }

    /// The parameters: nodes, names and drawn values.
    pub fn parameters(&self) -> &nodes::Parameters<3> {
        &self.params
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

    /// The candidate drawn at `values`, planned as a file is, whatever
    /// its steps: a Monte-Carlo candidate of a drawing with special
    /// geometry (two legs meeting at one point, axes that cross) is a
    /// mechanism of its own, planned differently.
    pub fn prepare_any(&self, values: &[f64]) -> Result<Candidate, SynthError> {
        let mechanism = self.drawing(values)?;
        let plan = analyse(&mechanism).map_err(|e| SynthError::Plan {
            reason: e.to_string(),
        })?;
        Ok(Candidate {
            mechanism,
            interpreter: Interpreter::new(plan),
        })
    }

    /// The candidate drawn at `values`, planned as a file is, with the
    /// original plan's steps in the original order.
    pub fn prepare(&self, values: &[f64]) -> Result<Candidate, SynthError> {
        let Candidate {
            mechanism,
            interpreter,
        } = self.prepare_any(values)?;
        let plan = interpreter.plan();
        let n = self.plan.steps.len().min(plan.steps.len());
        let same = |i: usize| {
            let (x, y) = (&self.plan.steps[i], &plan.steps[i]);
            std::mem::discriminant(&x.kind) == std::mem::discriminant(&y.kind) && x.serves == y.serves
        };
        if let Some(i) = (0..n)
            .find(|&i| !same(i))
            .or((self.plan.steps.len() != plan.steps.len()).then_some(n.saturating_sub(1)))
        {
            return Err(SynthError::PlanChanged {
                step: self.plan.explain(i),
            });
        }
        Ok(Candidate {
            mechanism,
            interpreter,
        })
    }
}
