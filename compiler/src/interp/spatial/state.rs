//! What the spatial interpreter carries from frame to frame, and where a
//! plan's points and directions are at given poses: read by the plan's
//! steps (`super`) and by its numeric clusters (`cluster`) alike.

use dofplan_runtime::real::Real;
use dofplan_runtime::spatial::{add, cst, scale, sub, unit, Pose3, Vec3};
use dofplan_runtime::Branch;

use crate::plan::spatial::{DirRef, PointRef};

/// What the interpreter carries from frame to frame.
#[derive(Clone, Debug)]
pub struct InterpState {
    /// Body poses, in the mechanism's body order.
    pub poses: Vec<Pose3>,
    /// Each pseudo-marker's last position.
    pub temps: Vec<Vec3>,
    /// Each branch slot's current branch.
    pub branches: Vec<Branch>,
    /// Each branch slot's last root, by its sine (rotations to a condition).
    pub angles: Vec<f64>,
    /// The state before the frame being computed: restored when a step
    /// breaks (a frame is a transaction), in buffers sized once so a frame
    /// does not allocate for it.
    pub(super) undo: Box<Undo>,
}

#[derive(Clone, Debug, Default)]
pub(super) struct Undo {
    pub(super) poses: Vec<Pose3>,
    pub(super) temps: Vec<Vec3>,
    pub(super) branches: Vec<Branch>,
    pub(super) angles: Vec<f64>,
}

/// A world point at given poses and pseudo-markers.
pub(crate) fn point_at<T: Real>(
    poses: &[Pose3<T>],
    temps: &[Vec3<T>],
    p: &PointRef,
    inputs: &[T],
) -> Vec3<T> {
    match p {
        PointRef::Fixed(v) => cst(*v),
        PointRef::Body { body, local } => poses[*body].world(*local),
        // `input·sign`, the same product as the generated `sign * input`.
        PointRef::Slid {
            body,
            local,
            dir,
            input,
            sign,
        } => poses[*body].world_of(add(cst(*local), scale(cst(*dir), inputs[*input].mul_f64(*sign)))),
        PointRef::Temp(t) => temps[*t],
    }
}

/// A world direction (unit) at given poses and pseudo-markers.
pub(crate) fn dir_at<T: Real>(poses: &[Pose3<T>], temps: &[Vec3<T>], d: &DirRef, inputs: &[T]) -> Vec3<T> {
    match d {
        DirRef::Fixed(v) => cst(*v),
        DirRef::Body { body, local } => poses[*body].dir(*local),
        DirRef::Between(a, b) => unit(sub(
            point_at(poses, temps, b, inputs),
            point_at(poses, temps, a, inputs),
        )),
        DirRef::Temp(t) => temps[*t],
    }
}
