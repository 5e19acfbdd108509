//! Numeric solving of planar mechanisms without a closed-form plan: the
//! pure-Newton baseline and the drags (a marker pulled to a target, an
//! input pulled toward a value).

pub mod drag;
pub mod input_drag;
mod newton;

pub use newton::{NewtonState, PureNewton};
