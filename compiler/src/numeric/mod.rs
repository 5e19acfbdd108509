//! Numeric solving where analysis is skipped or cannot help, one folder per
//! dimension with the same files: `newton.rs`, Brunkhart's pure-Newton
//! baseline (Figure 30's left column: every moving body's coordinates
//! unknown, every equation a residual, Newton–Raphson with an SVD
//! pseudo-inverse); `drag.rs`, a marker pulled to a target with the least
//! motion the joints allow.

pub mod planar;
pub mod spatial;

pub use planar::{NewtonState, PureNewton};
