//! Rates of plans of either dimension: every body's pose on [`Jet2`]s, its
//! first and second derivatives along given input rates and accelerations
//! ([`Rates`], one trait for planar and spatial plans, whose poses name
//! their version on jets through [`JetPose`]), and why a frame's rates were
//! not computed ([`RateError`]).
//!
//! They are made of the numbers (`Jet2`), the poses and the solver, so
//! they stand above all three rather than among the numbers.

use crate::drive::Solver;
use crate::frame::{Break, Ctx};
use crate::planar::Pose;
use crate::scalar::Jet2;

/// Why a frame's rates were not computed.
#[derive(Clone, Debug, PartialEq)]
pub enum RateError {
    /// The plan has a numeric cluster whose rates are not computed: only a
    /// spatial drag's (a marker pinned, solved by task priority). Planar
    /// and spatial plans' clusters have theirs (by the implicit function
    /// theorem on the cluster's Jacobian) and never give this.
    Cluster,
    /// The frame is at a dead point: a rate is infinite there (two roots
    /// of a step meet), so it is reported as singular, not as a number.
    Singular,
    /// The frame does not assemble at these inputs.
    Break(Break),
    /// The plan was split into functions (too large for one) whose rates
    /// are not generated. Generated planar and spatial plans have them in
    /// the split form too and never give this.
    Split,
}

impl From<Break> for RateError {
    fn from(b: Break) -> RateError {
        RateError::Break(b)
    }
}

impl std::fmt::Display for RateError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            RateError::Cluster => write!(f, "rates of this numeric cluster are not computed"),
            RateError::Singular => write!(f, "singular: a dead point, where a rate is infinite"),
            RateError::Break(b) => write!(f, "step {} breaks ({})", b.step, b.kind.describe()),
            RateError::Split => write!(f, "rates of this plan split into functions are not generated"),
        }
    }
}

impl std::error::Error for RateError {}

/// A pose with a version on jets: what a plan's rates are made of.
/// [`Pose`] is [`Pose<Jet2>`](Pose) on jets; the spatial pose implements it
/// in [`spatial`](crate::spatial).
pub trait JetPose {
    /// The same pose with every entry a [`Jet2`].
    type Jets;
}

impl JetPose for Pose {
    type Jets = Pose<Jet2>;
}

/// A plan of either dimension that gives its frames' rates: every body's
/// pose with its first and second derivatives along given input rates and
/// accelerations (the generated modules' `rates`, the interpreters').
pub trait Rates: Solver
where
    Self::Pose: JetPose,
{
    /// The rates at the frame `state` was solved to (at `inputs`), into
    /// `out` (one pose a body).
    fn rates_into(
        &self,
        state: &Self::State,
        inputs: &[f64],
        rates: &[f64],
        accelerations: &[f64],
        out: &mut [<Self::Pose as JetPose>::Jets],
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
        out: &mut [<Self::Pose as JetPose>::Jets],
    ) -> Result<(), RateError> {
        self.solve(state, inputs, ctx)?;
        self.rates_into(state, inputs, rates, accelerations, out)
    }
}

/// `poses` if every rate in them is finite, else [`RateError::Singular`]
/// (a dead point): what a run of the steps on jets returns.
pub fn checked<P: AsRef<[Pose<Jet2>]>>(poses: P) -> Result<P, RateError> {
    let finite = poses
        .as_ref()
        .iter()
        .all(|p| p.at.iter().all(|x| x.finite()) && p.rot.c.finite() && p.rot.s.finite());
    if finite {
        Ok(poses)
    } else {
        Err(RateError::Singular)
    }
}

/// Why a compiled `solve_forces` gives no forces for a frame.
#[derive(Clone, Debug, PartialEq)]
pub enum ForceError {
    /// The frame's positions or rates are not there (a break, a dead
    /// point).
    Rates(RateError),
    /// A block of the force plan is singular at this frame (a toggle, two
    /// pins in line): the equations do not fix the forces here.
    Singular,
}

impl From<crate::planar::forces::Singular> for ForceError {
    fn from(_: crate::planar::forces::Singular) -> Self {
        ForceError::Singular
    }
}
