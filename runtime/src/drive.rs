//! Running a plan frame after frame under a breaking policy.
//!
//! Both back ends implement [`Solver`]: a generated plan module and the
//! compiler's interpreter. The breaking policies live here, once, on top of
//! that trait — they only need "run the plan at these inputs" and a copy of
//! the last valid state.

use crate::frame::{Break, BreakPolicy, Ctx, FrameStatus, Options};
use crate::numeric::NewtonReport;
use crate::planar::Pose;

/// A plan that can be executed: one execution places every body for one set
/// of input values.
pub trait Solver {
    /// A body's pose: [`Pose`] in the plane, [`crate::spatial::Pose3`] in
    /// space.
    type Pose: Copy;
    /// Everything a plan execution reads from the previous frame and writes:
    /// body poses, the last point of every branching step, branch signs.
    /// Generated plans use fixed-size arrays, so cloning never allocates.
    type State: Clone;
    /// Input values, one per input in plan order.
    type Inputs: Clone + AsRef<[f64]> + AsMut<[f64]>;

    /// The drawn pose (every input at 0).
    fn initial_state(&self) -> Self::State;
    /// All inputs at 0.
    fn initial_inputs(&self) -> Self::Inputs;
    /// The body poses held by a state, in the mechanism's body order.
    fn poses(state: &Self::State) -> &[Self::Pose];
    /// Executes every step of the plan for `inputs`, warm-started from
    /// `state`. On error `state` must be left as it was (a break is a
    /// transaction that did not commit), so drivers need no copy per frame.
    fn solve(&self, state: &mut Self::State, inputs: &[f64], ctx: &mut Ctx) -> Result<(), Break>;
}

/// Drives a [`Solver`] frame after frame, keeping the last valid pose and
/// applying the breaking policy when an input cannot be met.
///
/// A frame allocates nothing: the driver owns every buffer it needs.
pub struct Driver<S: Solver> {
    solver: S,
    options: Options,
    state: S::State,
    trial: S::State,
    last: S::Inputs,
    probe: S::Inputs,
    numeric: Option<NewtonReport>,
}

impl<S: Solver> Driver<S> {
    /// A driver at the drawn pose.
    pub fn new(solver: S, options: Options) -> Self {
        let state = solver.initial_state();
        let last = solver.initial_inputs();
        Driver {
            trial: state.clone(),
            probe: last.clone(),
            state,
            last,
            solver,
            options,
            numeric: None,
        }
    }

    /// The plan being driven.
    pub fn solver(&self) -> &S {
        &self.solver
    }

    /// The options in force.
    pub fn options(&self) -> &Options {
        &self.options
    }

    /// The current (last valid) state.
    pub fn state(&self) -> &S::State {
        &self.state
    }

    /// The body poses of the current (last valid) frame.
    pub fn poses(&self) -> &[S::Pose] {
        S::poses(&self.state)
    }

    /// The Newton–Raphson report of the last frame's numeric solve (at the
    /// requested inputs), if the plan has one.
    pub fn numeric(&self) -> Option<NewtonReport> {
        self.numeric
    }

    /// The input values of the current pose (differs from the last request
    /// after a break).
    pub fn inputs(&self) -> &[f64] {
        self.last.as_ref()
    }

    /// Back to the drawn pose.
    pub fn reset(&mut self) {
        self.state = self.solver.initial_state();
        self.last = self.solver.initial_inputs();
    }

    /// Moves to `inputs` (one value per input, in plan order).
    #[inline]
    pub fn frame(&mut self, inputs: &[f64]) -> FrameStatus {
        let stretch = self.options.breaking == BreakPolicy::Stretch;
        let mut ctx = Ctx::new(self.options.branch, stretch);
        let result = self.solver.solve(&mut self.state, inputs, &mut ctx);
        self.numeric = ctx.numeric;
        match result {
            Ok(()) => {
                self.last.as_mut().copy_from_slice(inputs);
                match ctx.stretched {
                    None => FrameStatus::Solved,
                    Some((step, residual)) => FrameStatus::Stretched { step, residual },
                }
            }
            Err(brk) => match self.options.breaking {
                BreakPolicy::Search => self.search(inputs, brk),
                // Stretch relaxes every step it can; a step that cannot be
                // relaxed falls back to the limit policy.
                BreakPolicy::Limit | BreakPolicy::Stretch => FrameStatus::Limited { brk },
            },
        }
    }

    /// Bisects between the last valid inputs and `requested` for the break
    /// point and moves there.
    #[cold]
    #[inline(never)]
    fn search(&mut self, requested: &[f64], brk: Break) -> FrameStatus {
        let span = requested
            .iter()
            .zip(self.last.as_ref())
            .fold(0.0_f64, |m, (r, l)| m.max((r - l).abs()));
        let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
        while (hi - lo) * span > self.options.search_tolerance {
            let mid = 0.5 * (lo + hi);
            if mid <= lo || mid >= hi {
                break; // the bracket is as narrow as f64 allows
            }
            if self.try_at(requested, mid).is_ok() {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        if lo > 0.0 {
            // Re-run at the bracket's valid end; it succeeded from the same
            // warm start, so it succeeds again with the same result.
            if self.try_at(requested, lo).is_ok() {
                std::mem::swap(&mut self.state, &mut self.trial);
                self.last.clone_from(&self.probe);
            } else {
                lo = 0.0;
            }
        }
        FrameStatus::Searched { brk, reached: lo }
    }

    /// Solves into `trial` at the fraction `t` from the last inputs toward
    /// `requested` (the probe inputs are left in `probe`).
    fn try_at(&mut self, requested: &[f64], t: f64) -> Result<(), Break> {
        for ((p, l), r) in self
            .probe
            .as_mut()
            .iter_mut()
            .zip(self.last.as_ref())
            .zip(requested)
        {
            *p = l + t * (r - l);
        }
        self.trial.clone_from(&self.state);
        let mut ctx = Ctx::new(self.options.branch, false);
        self.solver.solve(&mut self.trial, self.probe.as_ref(), &mut ctx)
    }
}

/// A driven plan behind a trait object, for callers that pick a compiled
/// mechanism by name at run time (each generated plan has its own state
/// type, so [`Driver`] itself cannot be named without it).
pub trait Animate<P = Pose> {
    /// Moves to `inputs`; see [`Driver::frame`].
    fn frame(&mut self, inputs: &[f64]) -> FrameStatus;
    /// The body poses of the current frame.
    fn poses(&self) -> &[P];
    /// The input values of the current frame.
    fn inputs(&self) -> &[f64];
    /// The last frame's Newton–Raphson report, if any.
    fn numeric(&self) -> Option<NewtonReport>;
    /// Back to the drawn pose.
    fn reset(&mut self);
}

impl<S: Solver> Animate<S::Pose> for Driver<S> {
    fn frame(&mut self, inputs: &[f64]) -> FrameStatus {
        Driver::frame(self, inputs)
    }
    fn poses(&self) -> &[S::Pose] {
        Driver::poses(self)
    }
    fn inputs(&self) -> &[f64] {
        Driver::inputs(self)
    }
    fn numeric(&self) -> Option<NewtonReport> {
        Driver::numeric(self)
    }
    fn reset(&mut self) {
        Driver::reset(self)
    }
}
