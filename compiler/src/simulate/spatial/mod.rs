//! Reading spatial frames: marker positions, and each joint's residual
//! computed from the model's equations (not from the plan), so a wrong
//! plan cannot hide behind its own bookkeeping; and (`kinematics`) a
//! frame's rates.

use dofplan_runtime::spatial::{Pose3, Vec3};

use crate::model::spatial::equations::equations;
use crate::model::spatial::Mechanism;

pub mod kinematics;

pub use kinematics::{motion, Motion};

/// Every marker's world position, body by body in file order.
pub fn marker_positions(m: &Mechanism, poses: &[Pose3]) -> Vec<Vec3> {
    m.all_markers()
        .map(|id| poses[id.body].world(m.marker(id).at))
        .collect()
}

/// The largest residual of every joint, constraint and input equation at
/// `poses`, relative: lengths over the mechanism's size, directions as the
/// sines and cosines the rows are.
pub fn residual(m: &Mechanism, poses: &[Pose3], inputs: &[f64]) -> f64 {
    let size = m.size();
    equations(m)
        .iter()
        .map(|e| {
            let gap = e.gap(poses, inputs);
            if e.linear() {
                gap / size
            } else {
                gap
            }
        })
        .fold(0.0, f64::max)
}
