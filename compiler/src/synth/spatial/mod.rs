//! Design parameters of spatial mechanisms: [`Design`] (parameters and
//! candidates) and [`sensitivity`] (the exact derivatives of a frame with
//! respect to them), the same files as `synth/planar/`; `problem.rs`
//! has function generation ([`Function`]) and motion generation
//! ([`Motion`]), given timing.

mod gradient;
mod params;
mod problem;

pub use gradient::{sensitivity, Sensitivity};
pub use params::{Candidate, Design, Node};
pub use problem::{output, BodyPose, Function, Motion};
