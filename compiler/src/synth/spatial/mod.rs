//! Design parameters of spatial mechanisms: [`Design`] (parameters and
//! candidates) and [`sensitivity`] (the exact derivatives of a frame with
//! respect to them), the same files as `synth/planar/`; `problem.rs`
//! has path generation ([`Path`], given or free timing), function
//! generation ([`Function`]) and motion generation ([`Motion`], given
//! timing) with their [`Constraints`], and `solve.rs` runs them from a
//! [`Request`] as `dofplan synth` makes it.

mod gradient;
mod params;
mod problem;
mod solve;
mod tolerance;

pub use gradient::{sensitivity, Sensitivity};
pub use params::{Candidate, Design, Node};
pub use problem::{link_ratio, output, BodyPose, Constraints, Function, Motion, Path};
pub use solve::{problem, synthesize, Kind, Problem, Request};
pub use tolerance::{monte_carlo, nominal, paths, worst_case};
