//! Numeric solving of spatial mechanisms without a closed-form plan: the
//! pure-Newton baseline and the drag of a marker.

mod drag;
mod newton;

pub use drag::{drag_plan, released};
pub use newton::pure_newton;
