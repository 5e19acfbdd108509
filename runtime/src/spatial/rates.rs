//! Rates of spatial plans: the spatial counterpart of
//! [`Rates`](crate::real::Rates), with every body's [`Pose3`] on
//! [`Jet2`]s. A pose's rates are its entries' derivatives: the velocity of
//! the local origin is `pos[i].d`, and the angular velocity ω is read from
//! `Ṙ = [ω]×·R` (for example as `ω = vee(Ṙ·Rᵀ)`).

use super::Pose3;
use crate::drive::Solver;
use crate::frame::Ctx;
use crate::real::{Jet2, RateError};

/// A spatial plan that gives its frames' rates: every body's pose with its
/// first and second derivatives along given input rates and accelerations
/// (the generated spatial modules' `rates`, the spatial interpreter's).
pub trait Rates3: Solver<Pose = Pose3> {
    /// The rates at the frame `state` was solved to (at `inputs`), into
    /// `out` (one pose a body).
    fn rates_into(
        &self,
        state: &Self::State,
        inputs: &[f64],
        rates: &[f64],
        accelerations: &[f64],
        out: &mut [Pose3<Jet2>],
    ) -> Result<(), RateError>;

    /// A frame and its rates together: `solve` at `inputs` from `state`
    /// (committed as `solve` commits), then the rates into `out`. Generated
    /// plans do both in one pass on jets.
    fn solve_rates_into(
        &self,
        state: &mut Self::State,
        inputs: &[f64],
        rates: &[f64],
        accelerations: &[f64],
        ctx: &mut Ctx,
        out: &mut [Pose3<Jet2>],
    ) -> Result<(), RateError> {
        self.solve(state, inputs, ctx)?;
        self.rates_into(state, inputs, rates, accelerations, out)
    }
}

/// `poses` if every rate in them is finite, else [`RateError::Singular`]
/// (a dead point): what a run of the spatial steps on jets returns.
pub fn checked3<P: AsRef<[Pose3<Jet2>]>>(poses: P) -> Result<P, RateError> {
    if poses.as_ref().iter().all(Pose3::finite) {
        Ok(poses)
    } else {
        Err(RateError::Singular)
    }
}
