//! Running a plan frame after frame under a breaking policy.
//!
//! Both back ends implement [`Solver`]: a generated plan module and the
//! compiler's interpreter. The breaking policies live here, once, on top of
//! that trait — they only need "run the plan at these inputs" and a copy of
//! the last valid state.

use crate::frame::{Break, BreakKind, BreakPolicy, Ctx, FrameStatus, Options, StartPolicy};
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

/// A borrowed plan is a plan: a driver of `&S` leaves `S` with its owner
/// (batches drive a plan they borrow).
impl<S: Solver + ?Sized> Solver for &S {
    type Pose = S::Pose;
    type State = S::State;
    type Inputs = S::Inputs;

    fn initial_state(&self) -> Self::State {
        (**self).initial_state()
    }
    fn initial_inputs(&self) -> Self::Inputs {
        (**self).initial_inputs()
    }
    fn poses(state: &Self::State) -> &[Self::Pose] {
        S::poses(state)
    }
    #[inline]
    fn solve(&self, state: &mut Self::State, inputs: &[f64], ctx: &mut Ctx) -> Result<(), Break> {
        (**self).solve(state, inputs, ctx)
    }
}

/// Drives a [`Solver`] frame after frame, keeping the last valid pose and
/// applying the breaking policy when an input cannot be met.
///
/// A mechanism stays on its circuit. Once an input has taken it past an
/// assembly limit, it is *held*: a later frame resumes only when its input
/// can be reached from the pose it left by a path of inputs along which
/// every frame assembles (the input came back into the interval it left);
/// a frame that assembles only on another circuit is
/// [`BreakKind::OtherCircuit`]. Frames on the interval run exactly as
/// before: the checks below run only while held.
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
    /// The mechanism has a pose of this run (always, under
    /// [`StartPolicy::Drawn`]; from its first assembled frame under
    /// [`StartPolicy::Sweep`]).
    placed: bool,
    /// While held: the break at the limit it passed.
    held: Option<Break>,
    /// While held (or not yet placed): the last exact pose on the circuit,
    /// and its inputs. Under the stretch policy the state moves on (relaxed)
    /// while this stays.
    anchor: S::State,
    anchor_inputs: S::Inputs,
    /// While held: inputs on the way out of the interval that do not
    /// assemble (the first request that broke, or the far end of the
    /// search's bracket).
    fail: S::Inputs,
    /// While held: a second point known not to assemble, where a way back
    /// was last seen to leave the interval (the far side of it, for a single
    /// input), so that later requests past it need no new way.
    fail_back: S::Inputs,
    /// Whether `fail_back` holds such a point.
    has_back: bool,
    /// While held: how far apart in input the frames were when the limit was
    /// passed, the resolution at which a way back is checked.
    pace: f64,
    /// Inputs to lend to a search along a way back.
    spare: Option<S::Inputs>,
}

/// The most plan executions a check of a way back takes. Each is one frame's
/// work, and the check runs only on frames that would leave a hold.
const MAX_WAY_STEPS: usize = 64;

/// A break this small is a point the mechanism passes through, not a gap in
/// its motion: two roots meeting at a dead point a hair beyond round-off, or
/// coinciding circles at a parallelogram's change point. It does not start
/// a hold, and a way back may cross it.
const PASSABLE_GAP: f64 = 1e-9;

fn passable(brk: &Break) -> bool {
    brk.gap.abs() <= PASSABLE_GAP || brk.kind == BreakKind::CirclesCoincide
}

/// The largest difference between two input vectors (the search's measure).
fn span(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()))
}

/// Whether `r` lies on the ray from `a` through `f`, at or past `f`: the
/// straight way from `a` to `r` then goes through `f`.
fn past(a: &[f64], f: &[f64], r: &[f64]) -> bool {
    let (mut ff, mut rf, mut rr) = (0.0, 0.0, 0.0);
    for ((a, f), r) in a.iter().zip(f).zip(r) {
        let (df, dr) = (f - a, r - a);
        ff += df * df;
        rf += df * dr;
        rr += dr * dr;
    }
    if ff == 0.0 || rf < ff {
        return false;
    }
    // |r − a|² − ((r − a)·(f − a))²/|f − a|²: the squared distance of r from
    // the line, which rounding leaves at a few ulps for inputs moved
    // together along a sweep.
    let off = (rr - rf * rf / ff).max(0.0);
    off <= 1e-18 * rr
}

impl<S: Solver> Driver<S> {
    /// A driver at the drawn pose.
    pub fn new(solver: S, options: Options) -> Self {
        let state = solver.initial_state();
        let last = solver.initial_inputs();
        Driver {
            trial: state.clone(),
            probe: last.clone(),
            anchor: state.clone(),
            anchor_inputs: last.clone(),
            fail: last.clone(),
            fail_back: last.clone(),
            has_back: false,
            spare: Some(last.clone()),
            state,
            last,
            solver,
            placed: options.start == StartPolicy::Drawn,
            options,
            numeric: None,
            held: None,
            pace: 0.0,
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

    /// The break at the limit the mechanism is held past, if it is: frames
    /// then resume only on the way back into the interval it left.
    pub fn held(&self) -> Option<Break> {
        self.held
    }

    /// Whether the run has a pose yet (see [`StartPolicy`]).
    pub fn placed(&self) -> bool {
        self.placed
    }

    /// Back to the drawn pose.
    pub fn reset(&mut self) {
        self.state = self.solver.initial_state();
        self.last = self.solver.initial_inputs();
        self.placed = self.options.start == StartPolicy::Drawn;
        self.held = None;
        self.has_back = false;
    }

    /// Starts at `state`, a pose the plan gives at `inputs` (a frame it
    /// solved), as if that frame had just been driven.
    pub fn place(&mut self, state: &S::State, inputs: &[f64]) {
        self.state.clone_from(state);
        self.last.as_mut().copy_from_slice(inputs);
        self.placed = true;
        self.held = None;
        self.has_back = false;
    }

    /// Moves to `inputs` (one value per input, in plan order).
    #[inline]
    pub fn frame(&mut self, inputs: &[f64]) -> FrameStatus {
        if !self.placed || self.held.is_some() {
            return self.frame_off(inputs);
        }
        if self.options.breaking == BreakPolicy::Stretch {
            return self.frame_stretch(inputs);
        }
        let mut ctx = Ctx::new(self.options.branch, false);
        let result = self.solver.solve(&mut self.state, inputs, &mut ctx);
        self.numeric = ctx.numeric;
        match result {
            Ok(()) => {
                self.last.as_mut().copy_from_slice(inputs);
                FrameStatus::Solved
            }
            Err(brk) => self.leave(inputs, brk),
        }
    }

    /// A frame under the stretch policy on the interval: solved into the
    /// trial state, so that the pose before it is still there to anchor a
    /// hold when a step has to be relaxed.
    fn frame_stretch(&mut self, inputs: &[f64]) -> FrameStatus {
        let mut ctx = Ctx::new(self.options.branch, true);
        self.trial.clone_from(&self.state);
        let result = self.solver.solve(&mut self.trial, inputs, &mut ctx);
        self.numeric = ctx.numeric;
        match (result, ctx.stretched) {
            (Ok(()), None) => {
                std::mem::swap(&mut self.state, &mut self.trial);
                self.last.as_mut().copy_from_slice(inputs);
                FrameStatus::Solved
            }
            (Ok(()), Some((step, residual))) => {
                let brk = Break {
                    step,
                    kind: ctx.stretched_kind.unwrap_or(BreakKind::NoSolution),
                    gap: residual,
                };
                if !passable(&brk) {
                    self.hold(brk, inputs, self.span_to(inputs));
                }
                std::mem::swap(&mut self.state, &mut self.trial);
                self.last.as_mut().copy_from_slice(inputs);
                FrameStatus::Stretched { step, residual }
            }
            // A step that cannot be relaxed falls back to the limit policy.
            (Err(brk), _) => {
                if !passable(&brk) {
                    self.hold(brk, inputs, self.span_to(inputs));
                }
                FrameStatus::Limited { brk }
            }
        }
    }

    fn span_to(&self, inputs: &[f64]) -> f64 {
        span(self.last.as_ref(), inputs)
    }

    /// The mechanism is leaving its interval at `requested`: the policy's
    /// answer, and the hold that keeps it on its circuit afterwards.
    #[cold]
    #[inline(never)]
    fn leave(&mut self, requested: &[f64], brk: Break) -> FrameStatus {
        let pace = self.span_to(requested);
        match self.options.breaking {
            BreakPolicy::Search => {
                let (status, hi) = self.search(requested, brk);
                if !passable(&brk) {
                    // The bracket's far end is the failing point nearest
                    // the pose.
                    self.hold_at(brk, requested, hi, pace);
                }
                status
            }
            BreakPolicy::Limit | BreakPolicy::Stretch => {
                if !passable(&brk) {
                    self.hold(brk, requested, pace);
                }
                FrameStatus::Limited { brk }
            }
        }
    }

    /// Starts a hold at the current pose: `fail` does not assemble.
    fn hold(&mut self, brk: Break, fail: &[f64], pace: f64) {
        self.anchor.clone_from(&self.state);
        self.anchor_inputs.clone_from(&self.last);
        self.fail.as_mut().copy_from_slice(fail);
        self.has_back = false;
        self.held = Some(brk);
        self.pace = pace;
    }

    /// [`Self::hold`] with the failing point the fraction `t` of the way
    /// from the current inputs to `requested`.
    fn hold_at(&mut self, brk: Break, requested: &[f64], t: f64, pace: f64) {
        self.hold(brk, requested, pace);
        let from = self.last.as_ref();
        for ((f, l), r) in self.fail.as_mut().iter_mut().zip(from).zip(requested) {
            *f = l + t * (r - l);
        }
    }

    /// A frame while held, or before the run has a pose: it resumes only if
    /// the way to it from the anchor assembles throughout.
    #[cold]
    #[inline(never)]
    fn frame_off(&mut self, requested: &[f64]) -> FrameStatus {
        let way = self.way_back(requested);
        if way.is_ok() {
            std::mem::swap(&mut self.state, &mut self.trial);
            self.last.as_mut().copy_from_slice(requested);
            self.placed = true;
            self.held = None;
            self.has_back = false;
            return FrameStatus::Solved;
        }
        // Not reachable: why, as this frame's own break where it has one.
        let brk = self.break_at(requested);
        if !self.placed {
            if self.options.breaking == BreakPolicy::Stretch {
                if let Some(status) = self.stretch_off(requested) {
                    return status;
                }
            }
            return FrameStatus::Unreached { brk };
        }
        match (self.options.breaking, way) {
            (BreakPolicy::Limit, _) => FrameStatus::Limited { brk },
            // The way leaves the interval somewhere past its start: the
            // break point there, found between the last step of the way
            // that assembled (its pose in `trial`) and the first that did
            // not.
            (BreakPolicy::Search, Err(Some((t0, t1)))) => self.search_on_way(requested, brk, t0, t1),
            // Already at the break point: no nearer one on the way.
            (BreakPolicy::Search, _) => FrameStatus::Searched { brk, reached: 0.0 },
            (BreakPolicy::Stretch, _) => self
                .stretch_off(requested)
                .unwrap_or(FrameStatus::Limited { brk }),
        }
    }

    /// The search policy on a way back that leaves the interval between the
    /// fractions `t0` (assembled, pose in `trial`) and `t1` of the way from
    /// the anchor to `requested`: moves to the break point between them.
    fn search_on_way(&mut self, requested: &[f64], brk: Break, t0: f64, t1: f64) -> FrameStatus {
        // The driver's own spare buffer, lent out for the search: no
        // allocation on this path either.
        let mut edge = self
            .spare
            .take()
            .expect("the spare inputs are back after each use");
        for (((l, e), a), r) in self
            .last
            .as_mut()
            .iter_mut()
            .zip(edge.as_mut())
            .zip(self.anchor_inputs.as_ref())
            .zip(requested)
        {
            *l = a + t0 * (r - a);
            *e = a + t1 * (r - a);
        }
        std::mem::swap(&mut self.state, &mut self.trial);
        let pace = self.pace;
        let (status, far) = self.search(edge.as_ref(), brk);
        let reached = match status {
            FrameStatus::Searched { reached, .. } => t0 + reached * (t1 - t0),
            _ => t0,
        };
        self.hold_at(brk, edge.as_ref(), far, pace);
        self.spare = Some(edge);
        FrameStatus::Searched { brk, reached }
    }

    /// A relaxed frame off the interval, if some step needs relaxing there
    /// (one that assembles exactly is on another circuit: `None`).
    fn stretch_off(&mut self, requested: &[f64]) -> Option<FrameStatus> {
        let mut ctx = Ctx::new(self.options.branch, true);
        self.trial.clone_from(&self.state);
        let result = self.solver.solve(&mut self.trial, requested, &mut ctx);
        self.numeric = ctx.numeric;
        match (result, ctx.stretched) {
            (Ok(()), Some((step, residual))) => {
                std::mem::swap(&mut self.state, &mut self.trial);
                self.last.as_mut().copy_from_slice(requested);
                Some(FrameStatus::Stretched { step, residual })
            }
            _ => None,
        }
    }

    /// Why `requested` is not met from here: the break of an exact solve
    /// there, or, where that assembles, [`BreakKind::OtherCircuit`] at the
    /// limit passed.
    fn break_at(&mut self, requested: &[f64]) -> Break {
        self.trial.clone_from(&self.state);
        let mut ctx = Ctx::new(self.options.branch, false);
        match self.solver.solve(&mut self.trial, requested, &mut ctx) {
            Err(brk) => brk,
            Ok(()) => {
                let at = self.held.unwrap_or(Break {
                    step: 0,
                    kind: BreakKind::OtherCircuit,
                    gap: 0.0,
                });
                Break {
                    kind: BreakKind::OtherCircuit,
                    ..at
                }
            }
        }
    }

    /// Whether every frame on the straight way from the anchor to
    /// `requested` assembles (passable points aside), checked at the pace
    /// the limit was passed at; the pose at `requested` is then in `trial`.
    /// Otherwise, where the way was seen to leave: between the fractions
    /// `t0` (whose pose is left in `trial`) and `t1` of it, or `None` when
    /// it goes through a point known not to assemble.
    fn way_back(&mut self, requested: &[f64]) -> Result<(), Option<(f64, f64)>> {
        let a = self.anchor_inputs.as_ref();
        if (self.held.is_some() && past(a, self.fail.as_ref(), requested))
            || (self.has_back && past(a, self.fail_back.as_ref(), requested))
        {
            return Err(None); // through a point known not to assemble
        }
        let dist = span(self.anchor_inputs.as_ref(), requested);
        let steps = if self.held.is_some() && self.pace > 0.0 {
            ((dist / self.pace).ceil() as usize).clamp(1, MAX_WAY_STEPS)
        } else if dist > 0.0 {
            MAX_WAY_STEPS
        } else {
            1
        };
        self.trial.clone_from(&self.anchor);
        let mut good = 0.0;
        for k in 1..=steps {
            let t = k as f64 / steps as f64;
            for ((p, a), r) in self
                .probe
                .as_mut()
                .iter_mut()
                .zip(self.anchor_inputs.as_ref())
                .zip(requested)
            {
                *p = if k == steps { *r } else { a + t * (r - a) };
            }
            let mut ctx = Ctx::new(self.options.branch, false);
            let result = self.solver.solve(&mut self.trial, self.probe.as_ref(), &mut ctx);
            self.numeric = ctx.numeric;
            match result {
                Ok(()) => good = t,
                Err(brk) if k < steps && passable(&brk) => {}
                Err(_) => {
                    // Remembered: a later request past this point on the
                    // same line from the anchor is refused without a way.
                    self.fail_back.clone_from(&self.probe);
                    self.has_back = true;
                    return Err(Some((good, t)));
                }
            }
        }
        Ok(())
    }

    /// Bisects between the last valid inputs and `requested` for the break
    /// point and moves there; also returns the bracket's far end (the
    /// fraction of the way at which the plan was last seen to break).
    #[cold]
    #[inline(never)]
    fn search(&mut self, requested: &[f64], brk: Break) -> (FrameStatus, f64) {
        let span = self.span_to(requested);
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
        // The far end relative to the pose the search leaves.
        let mut far = hi;
        if lo > 0.0 {
            // Re-run at the bracket's valid end; it succeeded from the same
            // warm start, so it succeeds again with the same result.
            if self.try_at(requested, lo).is_ok() {
                std::mem::swap(&mut self.state, &mut self.trial);
                self.last.clone_from(&self.probe);
                far = (hi - lo) / (1.0 - lo);
            } else {
                lo = 0.0;
            }
        }
        (FrameStatus::Searched { brk, reached: lo }, far)
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
