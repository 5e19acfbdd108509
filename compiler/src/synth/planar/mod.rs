//! Synthesis of planar mechanisms: [`Design`] (parameters and candidates)
//! and [`sensitivity`] (the exact derivatives of a frame's poses with
//! respect to the parameters), [`worst_case`] and [`monte_carlo`] (what
//! tolerances on the dimensions do to a marker).

mod gradient;
mod params;
mod problem;
mod solve;
mod tolerance;

pub use gradient::{sensitivity, Linearised, Sensitivity};
pub use params::{Candidate, Design, Node};
pub use problem::{link_ratio, output, Constraints, Goal, Problem};
pub use solve::{problem, synthesize, Kind, Request};
// What a synthesis returns is the same in both dimensions.
pub use crate::synth::solution::{stats, ErrorStats, Margin, Solution, Synthesis};
pub use crate::synth::tolerance::Spread;
pub use tolerance::{monte_carlo, nominal, paths, worst_case};
