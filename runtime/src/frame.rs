//! What one frame reports, the policies that shape it, and the context the
//! steps of one plan execution share.

use crate::scalar::Real;

/// Index of a step in its plan (the plan IR's numbering, shown by
/// `dofplan plan`), so a break can name the step that could not be met.
pub type StepId = u32;

/// Which of the (at most two) roots of an intersection a step takes.
///
/// The sign is geometric, not an index into a sorted list: for two circles
/// it is the side of the centre line the point lies on, for a circle and a
/// line it is the direction along the line. A smooth motion away from
/// singular poses therefore never changes the sign, which is what makes
/// "keep the branch" flip-free.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum Branch {
    /// The root on the positive side.
    Plus,
    /// The root on the negative side.
    Minus,
}

impl Branch {
    /// +1.0 or −1.0.
    #[inline]
    pub fn sign(self) -> f64 {
        match self {
            Branch::Plus => 1.0,
            Branch::Minus => -1.0,
        }
    }

    /// "+" or "−" for explanations.
    pub fn symbol(self) -> &'static str {
        match self {
            Branch::Plus => "+",
            Branch::Minus => "-",
        }
    }
}

/// How a step picks its root at move time.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum BranchPolicy {
    /// Keep the branch chosen at plan time (the one of the drawn pose).
    #[default]
    Keep,
    /// Take the root nearest the previous frame's and remember its branch.
    Nearest,
}

/// What to do when an input value cannot be met (Brunkhart §3.3.5).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum BreakPolicy {
    /// Stay at the last valid pose and report the step that broke.
    #[default]
    Limit,
    /// Bisect between the last valid input and the requested one to find the
    /// break point (to [`Options::search_tolerance`]) and move there.
    Search,
    /// Relax the failing step: place the markers as close as possible and
    /// report the residual.
    Stretch,
}

/// Where a run of frames starts from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum StartPolicy {
    /// The drawn pose is the first pose: a frame that cannot be met from it
    /// holds it, as any later frame holds the last pose (an editor, a drag).
    #[default]
    Drawn,
    /// The frames are a sweep of their own, and the drawn pose is not one of
    /// them: until a frame assembles on the drawn pose's circuit, frames are
    /// [`FrameStatus::Unreached`] (there is no pose of the sweep to hold
    /// yet); the first that does starts the motion there.
    Sweep,
}

/// Move-time options of a frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Options {
    /// Branch policy.
    pub branch: BranchPolicy,
    /// Breaking policy.
    pub breaking: BreakPolicy,
    /// Search stops when the bracket around the break point is this narrow
    /// in every input (degrees or length units).
    pub search_tolerance: f64,
    /// Where the frames start from.
    pub start: StartPolicy,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            branch: BranchPolicy::Keep,
            breaking: BreakPolicy::Limit,
            search_tolerance: 1e-9,
            start: StartPolicy::Drawn,
        }
    }
}

/// Why a step could not be met.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum BreakKind {
    /// Two circles are too far apart or one lies inside the other.
    CirclesApart,
    /// Two circles coincide (same centre, same radius), as the links of a
    /// parallelogram do at its change point: every point of the circle
    /// closes the loop, so the position is not determined there.
    CirclesCoincide,
    /// A line misses a circle.
    LineMissesCircle,
    /// Two lines are parallel.
    ParallelLines,
    /// A line turning about a pivot cannot reach a point.
    LineCannotReach,
    /// Newton–Raphson reached a least-squares minimum with a residual left:
    /// no solution within reach of the last pose.
    NoSolution,
    /// Newton–Raphson ran out of iterations while still improving.
    NotConverged,
    /// A redundant equation does not hold: the mechanism is over-constrained
    /// and inconsistent at this input.
    Inconsistent,
    /// A pin would run past an end of its slot.
    PastSlotEnd,
    /// Frames solved together in lanes took different paths through a step
    /// (one at a dead point, one apart, …). Batch solving then solves them
    /// one at a time, so this never reaches a caller of
    /// [`Batch::solve_batch`](crate::batch::Batch::solve_batch).
    LanesDiffer,
    /// The input assembles here, but only on another circuit than the one
    /// the mechanism is on: it left its assembly interval at a limit, and
    /// could only get here by being taken apart. The pose stays held until
    /// the input comes back into the interval it left. The break's step and
    /// gap are those of the limit it passed.
    OtherCircuit,
    /// A frame solved on its own beside a dead point
    /// ([`Batch::solve_frames`](crate::batch::Batch::solve_frames)): whether
    /// the way to it from the frame before crosses a gap narrower than the
    /// step between them is for [`settle`](crate::batch::settle) to find
    /// out, driving the frames there in order. This never reaches a caller
    /// of [`Batch::solve_batch`](crate::batch::Batch::solve_batch).
    NearDeadPoint,
}

impl BreakKind {
    /// A short description for reports.
    pub fn describe(self) -> &'static str {
        match self {
            BreakKind::CirclesApart => "the circles do not meet",
            BreakKind::CirclesCoincide => {
                "the circles coincide: every point of them closes the loop, so the position is not determined here"
            }
            BreakKind::LineMissesCircle => "the line misses the circle",
            BreakKind::ParallelLines => "the lines are parallel",
            BreakKind::LineCannotReach => "the line cannot reach the point",
            BreakKind::NoSolution => "no solution within reach (least-squares minimum)",
            BreakKind::NotConverged => "Newton-Raphson did not converge within its iterations",
            BreakKind::Inconsistent => "a redundant joint does not hold (over-constrained and inconsistent)",
            BreakKind::PastSlotEnd => "the pin would run past an end of its slot",
            BreakKind::LanesDiffer => {
                "frames solved together took different paths (solved one at a time instead)"
            }
            BreakKind::NearDeadPoint => "beside a dead point, not yet driven in order",
            BreakKind::OtherCircuit => {
                "past a limit: the input assembles here only on another circuit, which the mechanism cannot reach without being taken apart"
            }
        }
    }
}

/// A step that could not be met.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Break {
    /// The step, numbered as in the plan.
    pub step: StepId,
    /// What went wrong.
    pub kind: BreakKind,
    /// How far from being met (a distance in length units).
    pub gap: f64,
}

/// On lanes, gives up on the frames of a step that is about to leave its
/// usual path (see [`Real::LANES`]); nothing otherwise.
#[inline(always)]
pub fn lanes_differ<T: Real>(step: StepId) -> Result<(), Break> {
    if T::LANES {
        Err(lanes_break(step))
    } else {
        Ok(())
    }
}

/// The break by which frames in lanes give up on step `step`.
#[cold]
pub fn lanes_break(step: StepId) -> Break {
    Break {
        step,
        kind: BreakKind::LanesDiffer,
        gap: f64::NAN,
    }
}

/// What happened in one frame.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(tag = "status", rename_all = "snake_case"))]
pub enum FrameStatus {
    /// Every step met exactly.
    Solved,
    /// The input could not be met; the pose stayed at the last valid frame.
    Limited {
        /// The step that broke.
        brk: Break,
    },
    /// The input could not be met; the pose moved to the break point, the
    /// fraction `reached` of the way from the last valid input to the
    /// requested one.
    Searched {
        /// The step that broke at the requested input.
        brk: Break,
        /// 0 = stayed at the last valid input, 1 = reached the request.
        reached: f64,
    },
    /// The frame is not reachable: the run has no pose yet (it started out
    /// of the mechanism's reach under [`StartPolicy::Sweep`], and no frame
    /// has assembled since). The poses are the drawn ones, which are not a
    /// pose of the run.
    Unreached {
        /// Why the frame cannot be met.
        brk: Break,
    },
    /// The input was applied but steps were relaxed.
    Stretched {
        /// The first relaxed step.
        step: StepId,
        /// The largest gap left by a relaxed step.
        residual: f64,
    },
}

impl FrameStatus {
    /// The break of a frame that did not meet its input (limited, searched
    /// or unreached).
    pub fn brk(&self) -> Option<Break> {
        match *self {
            FrameStatus::Limited { brk }
            | FrameStatus::Searched { brk, .. }
            | FrameStatus::Unreached { brk } => Some(brk),
            FrameStatus::Solved | FrameStatus::Stretched { .. } => None,
        }
    }

    /// True when the requested input was met exactly.
    pub fn is_solved(&self) -> bool {
        matches!(self, FrameStatus::Solved)
    }

    /// A one-word name: solved, limited, searched, unreached or stretched.
    pub fn name(&self) -> &'static str {
        match self {
            FrameStatus::Solved => "solved",
            FrameStatus::Limited { .. } => "limited",
            FrameStatus::Searched { .. } => "searched",
            FrameStatus::Unreached { .. } => "unreached",
            FrameStatus::Stretched { .. } => "stretched",
        }
    }
}

/// State shared by the steps of one plan execution.
#[derive(Clone, Copy, Debug)]
pub struct Ctx {
    /// How roots are chosen.
    pub branch: BranchPolicy,
    /// Relax failing steps instead of breaking.
    pub stretch: bool,
    /// The first step relaxed in this execution and the largest gap so far.
    pub stretched: Option<(StepId, f64)>,
    /// Why the first relaxed step could not be met.
    pub stretched_kind: Option<BreakKind>,
    /// The report of the numeric solve of this execution, if there was one.
    pub numeric: Option<crate::numeric::NewtonReport>,
    /// How close the two roots of a branching step came in this execution,
    /// at the closest step, where that is nearer than [`NEAR_DEAD_POINT`]
    /// ([`watch`]); infinite otherwise.
    pub near: f64,
    /// Record every branching step's closeness in [`Ctx::near`], however
    /// far from a dead point (while looking for a gap, which fits a curve
    /// through them).
    pub measure: bool,
}

/// Two roots of a branching step closer than this (the squared
/// half-separation relative to the squared sizes of the loci it
/// intersects, 1/4 where two equal circles cross at right angles) put the
/// frame beside a dead point: a [`Driver`](crate::drive::Driver) then looks
/// between it and its neighbours for a gap narrower than the step between
/// them, which a mechanism cannot cross without being taken apart.
pub const NEAR_DEAD_POINT: f64 = 2e-2;

/// Records how close a branching step's two roots are: `disc` is the
/// squared half-separation that the step takes the square root of, and
/// `size()` what makes it dimensionless (see [`NEAR_DEAD_POINT`]).
///
/// On lanes, a group with a frame beside a dead point gives up (each frame
/// is then solved on its own and marked [`BreakKind::NearDeadPoint`]), so
/// the closeness of each is known.
#[inline(always)]
pub fn watch<T: Real>(ctx: &mut Ctx, step: StepId, disc: T, size: impl Fn() -> T) -> Result<(), Break> {
    if T::LANES {
        if (disc - size().mul_f64(NEAR_DEAD_POINT)).any(|v| v < 0.0) {
            return Err(lanes_break(step));
        }
    } else {
        let (d, s) = (disc.value(), size().value());
        if d < NEAR_DEAD_POINT * s || ctx.measure {
            ctx.saw_near(d / s);
        }
    }
    Ok(())
}

impl Ctx {
    /// A fresh context for one plan execution.
    pub fn new(branch: BranchPolicy, stretch: bool) -> Ctx {
        Ctx {
            branch,
            stretch,
            stretched: None,
            stretched_kind: None,
            numeric: None,
            near: f64::INFINITY,
            measure: false,
        }
    }

    /// A step's roots came `margin` close (see [`watch`]).
    #[cold]
    #[inline(never)]
    pub fn saw_near(&mut self, margin: f64) {
        self.near = self.near.min(margin.max(0.0));
    }

    /// Either records a relaxation (stretch policy) or returns the break.
    /// Every step that can fail reports through here.
    #[inline]
    pub fn fail(&mut self, step: StepId, kind: BreakKind, gap: f64) -> Result<(), Break> {
        if self.stretch {
            self.stretched_kind.get_or_insert(kind);
            self.stretched = Some(match self.stretched {
                None => (step, gap),
                Some((first, worst)) => (first, worst.max(gap)),
            });
            Ok(())
        } else {
            Err(Break { step, kind, gap })
        }
    }
}
