//! Design parameters of spatial mechanisms: [`Design`] (parameters and
//! candidates) and [`sensitivity`] (the exact derivatives of a frame with
//! respect to them), the same files as `synth/planar/`.

mod gradient;
mod params;

pub use gradient::{sensitivity, Sensitivity};
pub use params::{Candidate, Design, Node};
