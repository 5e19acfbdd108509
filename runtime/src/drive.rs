//! Running a plan frame after frame under a breaking policy.
//!
//! Both back ends implement [`Solver`]: a generated plan module and the
//! compiler's interpreter. The breaking policies live here, once, on top of
//! that trait — they only need "run the plan at these inputs" and a copy of
//! the last valid state.

use crate::frame::{
    BranchPolicy, Break, BreakKind, BreakPolicy, Ctx, FrameStatus, Options, StartPolicy, NEAR_DEAD_POINT,
};
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
    /// How close the current pose is to a dead point ([`Ctx::near`]).
    near: f64,
    /// The same for the anchor.
    anchor_near: f64,
    /// Scratch for the look for a gap between two frames ([`Gaps`]).
    gaps: Gaps<S>,
}

/// Scratch for looking between two frames beside a dead point for a gap
/// narrower than the step between them: the look bisects the way, and
/// keeps the pose at the near end of the part it looks at next.
struct Gaps<S: Solver> {
    /// Where a way's step starts (see [`Driver::gap_on_way`]).
    from: S::Inputs,
    scratch: Scratch<S>,
}

/// What [`gap_between`] writes. The states are boxed: a generated plan's
/// state is a fixed-size array, hundreds of kilobytes for a chain of
/// thousands of loops, and a driver is often built on a thread's stack.
struct Scratch<S: Solver> {
    near_end: Box<S::State>,
    mid: Box<S::State>,
    probe: S::Inputs,
}

/// A copy of `x` on the heap, made in a frame of its own so that the copy
/// does not stay on its caller's stack.
#[inline(never)]
fn boxed<T: Clone>(x: &T) -> Box<T> {
    Box::new(x.clone())
}

/// Where the parabola through a step's closeness at the start (`m0`), the
/// middle (`m1`) and the end (`m2`) of a part of the way dips lowest, as a
/// fraction of that part, if it may dip to a gap there: below half the
/// smallest sample. Failing that, an end whose closeness is a small part of
/// the middle's (a gap too narrow for three samples to show may lie beside
/// it). `None` otherwise: the curve stays above the samples.
fn dip(m0: f64, m1: f64, m2: f64) -> Option<f64> {
    let lowest = m0.min(m1).min(m2);
    // p(t) = α t² + β t + m0 through (0, m0), (½, m1), (1, m2).
    let alpha = 2.0 * (m0 + m2 - 2.0 * m1);
    let beta = m2 - m0 - alpha;
    if alpha > 0.0 {
        let v = (-beta / (2.0 * alpha)).clamp(0.0, 1.0);
        let low = (alpha * v + beta) * v + m0;
        if low <= 0.5 * lowest {
            return Some(v);
        }
    }
    if m2 == lowest && m2 <= 0.25 * m1 {
        Some(1.0)
    } else if m0 == lowest && m0 <= 0.25 * m1 {
        Some(0.0)
    } else {
        None
    }
}

/// Where between the inputs `a` and `b` (closeness `near.0` and `near.1`,
/// see [`Ctx::near`]) the plan breaks, as a fraction of the way, if it
/// does: a gap narrower than the step from `a` to `b`, both of whose ends
/// assemble. Probes are warm-started from `base`, a pose at either end.
///
/// Beside a dead point, the squared separation of a branching step's two
/// roots is a smooth function of the input, which a gap takes below zero.
/// The look fits a parabola through it at the ends and the middle, and goes
/// on into the half where the parabola dips lowest while it may dip to
/// zero: one plan execution per halving, to the search tolerance at most.
#[allow(clippy::too_many_arguments)]
fn gap_between<S: Solver>(
    solver: &S,
    branch: BranchPolicy,
    tolerance: f64,
    base: &S::State,
    a: &[f64],
    b: &[f64],
    gaps: &mut Scratch<S>,
) -> Option<(f64, Break)> {
    let width = span(a, b);
    let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
    (*gaps.near_end).clone_from(base);
    // The closeness at `t` of the way, every step's counted; the pose there
    // left in `near_end` (if it assembles).
    let probe = |t: f64, gaps: &mut Scratch<S>| -> Result<f64, Break> {
        for ((p, a), b) in gaps.probe.as_mut().iter_mut().zip(a).zip(b) {
            *p = if t == 1.0 { *b } else { a + t * (b - a) };
        }
        (*gaps.mid).clone_from(&gaps.near_end);
        let mut ctx = Ctx::new(branch, false);
        ctx.measure = true;
        match solver.solve(&mut gaps.mid, gaps.probe.as_ref(), &mut ctx) {
            Ok(()) => {
                // The pose nearest the part looked at next, to warm-start
                // the next probe from.
                std::mem::swap(&mut gaps.near_end, &mut gaps.mid);
                Ok(ctx.near)
            }
            Err(brk) if passable(&brk) => Ok(0.0),
            Err(brk) => Err(brk),
        }
    };
    // The ends' closeness as the curve needs it: every step's, not only the
    // near ones' that a frame records. (Both ends assembled.)
    let mut m_lo = probe(0.0, gaps).unwrap_or(0.0);
    let mut m_hi = probe(1.0, gaps).unwrap_or(0.0);
    while (hi - lo) * width > tolerance {
        let mid = 0.5 * (lo + hi);
        let m_mid = match probe(mid, gaps) {
            Ok(m) => m,
            Err(brk) => return Some((mid, brk)),
        };
        let v = dip(m_lo, m_mid, m_hi)?;
        if v < 0.5 {
            (hi, m_hi) = (mid, m_mid);
        } else {
            (lo, m_lo) = (mid, m_mid);
        }
    }
    None
}

/// The closeness to a dead point of a pose the driver did not solve (the
/// drawing, a placed pose): taken as away from one, so the next frame is
/// looked at only if it is itself beside one. A frame from such a pose is
/// then what it is in a batch, where frames are solved each on its own and
/// only those beside a dead point are driven in order
/// ([`crate::batch::settle`]).
const UNMEASURED: f64 = f64::INFINITY;

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
    // the line, which rounding leaves at a few ulps of |r − a|² for inputs
    // moved together along a sweep (a single input included: its distance
    // is 0, left as the difference of two equal squares).
    let off = (rr - rf * rf / ff).max(0.0);
    off <= 1e-12 * rr
}

impl<S: Solver> Driver<S> {
    /// A driver at the drawn pose.
    pub fn new(solver: S, options: Options) -> Self {
        let state = solver.initial_state();
        let last = solver.initial_inputs();
        let solver_inputs = last.clone();
        let scratch = (boxed(&state), boxed(&state));
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
            near: UNMEASURED,
            gaps: Gaps {
                from: solver_inputs.clone(),
                scratch: Scratch {
                    near_end: scratch.0,
                    mid: scratch.1,
                    probe: solver_inputs,
                },
            },
            anchor_near: f64::INFINITY,
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

    /// Whether the pose is beside a dead point (see
    /// [`NEAR_DEAD_POINT`]): the next frame looks for a gap on its way.
    pub fn near_dead_point(&self) -> bool {
        self.near < NEAR_DEAD_POINT
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
        self.near = UNMEASURED;
    }

    /// Starts at `state`, a pose the plan gives at `inputs` (a frame it
    /// solved), as if that frame had just been driven.
    pub fn place(&mut self, state: &S::State, inputs: &[f64]) {
        self.state.clone_from(state);
        self.last.as_mut().copy_from_slice(inputs);
        self.placed = true;
        self.held = None;
        self.has_back = false;
        self.near = UNMEASURED;
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
                if ctx.near < NEAR_DEAD_POINT || self.near < NEAR_DEAD_POINT {
                    if let Some(status) = self.beside_dead_point(inputs, true) {
                        return status;
                    }
                }
                self.near = ctx.near;
                self.last.as_mut().copy_from_slice(inputs);
                FrameStatus::Solved
            }
            Err(brk) => self.leave(inputs, brk),
        }
    }

    /// A frame beside a dead point assembled at `inputs`, its pose in
    /// `state` if `committed`, in `trial` otherwise: if the way to it from
    /// the last pose crosses a gap, the mechanism is leaving its interval
    /// there (the far side of a gap is another circuit), and this is the
    /// frame's status.
    #[cold]
    #[inline(never)]
    fn beside_dead_point(&mut self, inputs: &[f64], committed: bool) -> Option<FrameStatus> {
        let base = if committed { &self.state } else { &self.trial };
        let (t, brk) = gap_between(
            &self.solver,
            self.options.branch,
            self.options.search_tolerance,
            base,
            self.last.as_ref(),
            inputs,
            &mut self.gaps.scratch,
        )?;
        if committed {
            // Back to the pose before: the plan at its inputs, warm-started
            // from the far side (under keep-branch, the same pose to the
            // bit; a break there cannot be, the frame before assembled).
            self.trial.clone_from(&self.state);
            let mut ctx = Ctx::new(self.options.branch, false);
            if self
                .solver
                .solve(&mut self.trial, self.last.as_ref(), &mut ctx)
                .is_ok()
            {
                std::mem::swap(&mut self.state, &mut self.trial);
            }
        }
        Some(self.leave_at(inputs, brk, t))
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
                if ctx.near < NEAR_DEAD_POINT || self.near < NEAR_DEAD_POINT {
                    if let Some(status) = self.beside_dead_point(inputs, false) {
                        return status;
                    }
                }
                std::mem::swap(&mut self.state, &mut self.trial);
                self.near = ctx.near;
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
        self.leave_at(requested, brk, 1.0)
    }

    /// [`Self::leave`] where the way to `requested` breaks the fraction `t`
    /// of the way there (before it, for a gap that `requested` is past).
    fn leave_at(&mut self, requested: &[f64], brk: Break, t: f64) -> FrameStatus {
        let pace = self.span_to(requested);
        match self.options.breaking {
            BreakPolicy::Search => {
                let mut edge = self
                    .spare
                    .take()
                    .expect("the spare inputs are back after each use");
                for ((e, l), r) in edge.as_mut().iter_mut().zip(self.last.as_ref()).zip(requested) {
                    *e = if t == 1.0 { *r } else { l + t * (r - l) };
                }
                let (status, hi) = self.search(edge.as_ref(), brk);
                if !passable(&brk) {
                    // The bracket's far end is the failing point nearest
                    // the pose.
                    self.hold_at(brk, edge.as_ref(), hi, pace);
                }
                self.spare = Some(edge);
                match status {
                    FrameStatus::Searched { brk, reached } => FrameStatus::Searched {
                        brk,
                        reached: reached * t,
                    },
                    other => other,
                }
            }
            BreakPolicy::Limit | BreakPolicy::Stretch => {
                if !passable(&brk) {
                    if t == 1.0 {
                        self.hold(brk, requested, pace);
                    } else {
                        self.hold_at(brk, requested, t, pace);
                    }
                }
                FrameStatus::Limited { brk }
            }
        }
    }

    /// Starts a hold at the current pose: `fail` does not assemble.
    fn hold(&mut self, brk: Break, fail: &[f64], pace: f64) {
        self.anchor.clone_from(&self.state);
        self.anchor_inputs.clone_from(&self.last);
        self.anchor_near = self.near;
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
        if let Ok(near) = way {
            std::mem::swap(&mut self.state, &mut self.trial);
            self.near = near;
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
    fn way_back(&mut self, requested: &[f64]) -> Result<f64, Option<(f64, f64)>> {
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
        let mut near = self.anchor_near;
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
                Ok(()) if ctx.near < NEAR_DEAD_POINT || near < NEAR_DEAD_POINT => {
                    if let Some(s) = self.gap_on_way(requested, good, t) {
                        return Err(Some((good, good + s * (t - good))));
                    }
                    (good, near) = (t, ctx.near);
                }
                Ok(()) => (good, near) = (t, ctx.near),
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
        Ok(near)
    }

    /// On a way back from the anchor to `requested`, the step from the
    /// fraction `t0` to `t1` (whose pose is in `trial`) beside a dead point:
    /// where a gap crosses it, as a fraction
    /// of the step, remembered as a point that does not assemble, with the
    /// pose at `t0` back in `trial`.
    #[cold]
    #[inline(never)]
    fn gap_on_way(&mut self, requested: &[f64], t0: f64, t1: f64) -> Option<f64> {
        let a = self.anchor_inputs.as_ref();
        for (((f, p), a), r) in self
            .gaps
            .from
            .as_mut()
            .iter_mut()
            .zip(self.probe.as_mut())
            .zip(a)
            .zip(requested)
        {
            *f = a + t0 * (r - a);
            *p = if t1 == 1.0 { *r } else { a + t1 * (r - a) };
        }
        let (s, _) = gap_between(
            &self.solver,
            self.options.branch,
            self.options.search_tolerance,
            &self.trial,
            self.gaps.from.as_ref(),
            self.probe.as_ref(),
            &mut self.gaps.scratch,
        )?;
        let from = self.gaps.from.as_ref();
        for ((f, a), b) in self
            .fail_back
            .as_mut()
            .iter_mut()
            .zip(from)
            .zip(self.probe.as_ref())
        {
            *f = a + s * (b - a);
        }
        self.has_back = true;
        // The pose at the step's start again: the plan there, from its end
        // (under keep-branch, the same pose to the bit).
        let mut ctx = Ctx::new(self.options.branch, false);
        let _ = self.solver.solve(&mut self.trial, from, &mut ctx);
        Some(s)
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
