//! The plan IR: the contract between analysis and both back ends.
//!
//! A plan is straight-line: its steps run in order, each one call to a
//! runtime function, each reading what earlier steps placed. The
//! interpreter walks the steps; the emitter writes one Rust block per step.
//! Neither re-analyses anything: every constant a step needs (local marker
//! coordinates, radii, unit directions, branch slots) is in the IR. One
//! folder per dimension: [`planar::Plan`] and [`spatial::Plan`].

pub mod design;
mod explain;
pub mod planar;
pub mod spatial;

pub use explain::num;
pub use planar::{
    Affine, BodyId, BranchSlot, ClusterParam, ClusterRow, DirRef, Line, Plan, PlanBody, PlanInput, PointRef,
    Rel, Step, StepKind, Temp,
};
