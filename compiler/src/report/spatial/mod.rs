//! The reports of spatial (`dimension = 3`) files: `check`, the frames of
//! `simulate` and `drag`, and `analyze`'s rates (with the `plots` feature).

#[cfg(feature = "plots")]
pub mod analyze;
pub mod check;
pub mod forces;
pub mod frames;
pub mod sensitivity;
pub mod synth;

pub use check::check;
pub use frames::{drag, frame_value, simulate};
