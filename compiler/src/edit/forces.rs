//! The `"forces"` a frame of a file with loads carries, in either
//! dimension: what holds the pose on screen still, for the page's arrows.

use serde_json::{json, Value};

/// A frame's `"forces"`: each input's force or torque, each joint's
/// reaction (the force its first body exerts on its second) and moment, by
/// joint in file order; `"held"` false where the inputs cannot hold the
/// pose (the reactions then the least-squares ones: a freedom no input
/// drives, after a drag); `"indeterminate"` the joints whose share is not
/// unique.
pub(crate) fn frame_forces<F: serde::Serialize, M: serde::Serialize>(
    inputs: &[f64],
    reactions: &[F],
    moments: &[M],
    sizes: impl Iterator<Item = f64>,
    residual: f64,
    indeterminate: Vec<&str>,
) -> Value {
    let scale = (sizes.chain(inputs.iter().map(|q| q.abs()))).fold(0.0f64, f64::max);
    json!({
        "inputs": inputs,
        "reactions": reactions,
        "moments": moments,
        "held": residual <= 1e-8 * scale.max(1e-300),
        "indeterminate": indeterminate,
    })
}
