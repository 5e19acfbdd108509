//! Many frames in one call: a sweep for a design study or a plot, solved
//! with the results a [`Driver`](crate::Driver) gives frame after frame
//! (keep-branch policy, limit policy, from the drawn pose), faster.
//!
//! Under keep-branch, a closed-form plan's frames do not depend on each
//! other (each step's root is the branch chosen at plan time, and nothing
//! a frame writes is read by the next), so compiled closed-form plans solve
//! them [`LANES`] at a time ([`lane_groups`]), and with the `rayon` feature
//! [`solve_batch_parallel`] splits a long sweep over every core. A plan
//! with numeric clusters warm-starts each frame's Newton solve from the
//! last one, so its frames are solved in order ([`in_order`]); so are the
//! interpreter's.
//!
//! A frame that does not assemble gets [`FrameStatus::Limited`] with the
//! step that broke, and the poses of the last frame that did (the drawn
//! pose before the first), as the driver's limit policy keeps them.

use crate::drive::Solver;
use crate::frame::{BranchPolicy, Ctx, FrameStatus};
use crate::lanes::{Lanes, LANES};
use crate::planar::{Pose, Rot};

/// A plan that solves many frames in one call.
pub trait Batch: Solver {
    /// Whether frames are independent of each other under keep-branch, so
    /// that they may be solved in any order, in lanes or on several cores.
    fn independent(&self) -> bool {
        false
    }

    /// Solves one frame per entry of `status`: frame `k`'s inputs are
    /// `inputs[k * n..(k + 1) * n]` (`n` inputs, in plan order) and its
    /// poses go to `out[k * b..(k + 1) * b]` (`b` bodies, in plan order),
    /// each as the driver would leave them after that frame (keep-branch
    /// policy, limit policy, starting from the drawn pose).
    ///
    /// # Panics
    /// If `inputs` or `out` is not `status.len()` frames long.
    fn solve_batch(&self, inputs: &[f64], out: &mut [Self::Pose], status: &mut [FrameStatus]) {
        in_order(self, inputs, out, status)
    }
}

/// The inputs per frame and bodies of `solver`, after checking that the
/// buffers hold `frames` frames.
fn shape<S: Solver + ?Sized>(solver: &S, inputs: &[f64], out: &[S::Pose], frames: usize) -> (usize, usize) {
    let n = solver.initial_inputs().as_ref().len();
    let b = S::poses(&solver.initial_state()).len();
    assert_eq!(
        inputs.len(),
        frames * n,
        "solve_batch: {frames} frames of {n} inputs each"
    );
    assert_eq!(
        out.len(),
        frames * b,
        "solve_batch: {frames} frames of {b} poses each"
    );
    (n, b)
}

/// Frame `k` of a limited run keeps the poses of the frame before it (the
/// drawn pose for the first): the driver's limit policy, applied after the
/// frames were solved out of order.
fn hold_limited<P: Copy>(drawn: &[P], out: &mut [P], status: &[FrameStatus]) {
    let b = drawn.len();
    for (k, st) in status.iter().enumerate() {
        if matches!(st, FrameStatus::Limited { .. }) {
            if k == 0 {
                out[..b].copy_from_slice(drawn);
            } else {
                out.copy_within((k - 1) * b..k * b, k * b);
            }
        }
    }
}

/// One frame on `state` (keep-branch, limit): its status, and its poses
/// into `out` when it assembles.
#[inline]
fn one<S: Solver + ?Sized>(
    solver: &S,
    state: &mut S::State,
    inputs: &[f64],
    out: &mut [S::Pose],
) -> FrameStatus {
    let mut ctx = Ctx::new(BranchPolicy::Keep, false);
    match solver.solve(state, inputs, &mut ctx) {
        Ok(()) => {
            out.copy_from_slice(S::poses(state));
            FrameStatus::Solved
        }
        Err(brk) => FrameStatus::Limited { brk },
    }
}

/// [`Batch::solve_batch`] frame after frame, each warm-started from the
/// last that assembled: exactly a driver's run.
pub fn in_order<S: Solver + ?Sized>(
    solver: &S,
    inputs: &[f64],
    out: &mut [S::Pose],
    status: &mut [FrameStatus],
) {
    let (n, b) = shape(solver, inputs, out, status.len());
    let mut state = solver.initial_state();
    let drawn: Vec<S::Pose> = S::poses(&state).to_vec();
    for (k, st) in status.iter_mut().enumerate() {
        *st = one(
            solver,
            &mut state,
            &inputs[k * n..(k + 1) * n],
            &mut out[k * b..(k + 1) * b],
        );
    }
    hold_limited(&drawn, out, status);
}

/// The lane groups of a batch for a compiled closed-form plan, which runs
/// [`Batch::solve_batch`] as
///
/// ```text
/// for g in 0..lane_groups(..) {
///     match solve_lanes(&group_inputs(inputs, g)) {
///         Ok(poses) => put_group(&poses, g, out, status),
///         Err(_) => one_at_a_time(.., g * LANES..(g + 1) * LANES, ..),
///     }
/// }
/// finish(.., lane_groups * LANES, ..)
/// ```
///
/// — [`LANES`] frames at a time through its steps on [`Lanes`]; a group
/// whose frames part ways at some step, and the frames left over, one at a
/// time. The loop is written out in the generated module (not a function
/// taking `solve_lanes` as an argument) so that a copy compiled for wider
/// vector registers inlines the steps. This checks the buffers' lengths
/// and returns the number of whole groups.
#[inline(always)]
pub fn lane_groups<S: Solver + ?Sized>(
    solver: &S,
    inputs: &[f64],
    out: &[S::Pose],
    status: &[FrameStatus],
) -> usize {
    shape(solver, inputs, out, status.len());
    status.len() / LANES
}

/// The inputs of lane group `g`: lane `l` of input `i` is frame
/// `g·LANES + l`'s value of input `i`.
#[inline(always)]
pub fn group_inputs<const N: usize>(inputs: &[f64], g: usize) -> [Lanes; N] {
    let rows = &inputs[g * LANES * N..(g + 1) * LANES * N];
    let mut group = [Lanes::splat(0.0); N];
    for (l, row) in rows.chunks_exact(N).enumerate() {
        for (i, x) in row.iter().enumerate() {
            group[i].0[l] = *x;
        }
    }
    group
}

/// Lane group `g`'s poses into its frames' rows of `out`, all solved.
#[inline(always)]
pub fn put_group<const B: usize>(
    poses: &[Pose<Lanes>; B],
    g: usize,
    out: &mut [Pose],
    status: &mut [FrameStatus],
) {
    let rows = &mut out[g * LANES * B..(g + 1) * LANES * B];
    for (l, row) in rows.chunks_exact_mut(B).enumerate() {
        for (o, p) in row.iter_mut().zip(poses) {
            *o = Pose {
                at: [p.at[0].0[l], p.at[1].0[l]],
                rot: Rot {
                    c: p.rot.c.0[l],
                    s: p.rot.s.0[l],
                },
            };
        }
    }
    status[g * LANES..(g + 1) * LANES].fill(FrameStatus::Solved);
}

/// The frames `frames` solved one at a time (each from the drawn pose: the
/// plan's frames are independent).
#[inline(never)]
pub fn one_at_a_time<S: Solver + ?Sized>(
    solver: &S,
    frames: std::ops::Range<usize>,
    inputs: &[f64],
    out: &mut [S::Pose],
    status: &mut [FrameStatus],
) {
    let (n, b) = (
        inputs.len() / status.len().max(1),
        out.len() / status.len().max(1),
    );
    let mut state = solver.initial_state();
    for k in frames {
        status[k] = one(
            solver,
            &mut state,
            &inputs[k * n..(k + 1) * n],
            &mut out[k * b..(k + 1) * b],
        );
    }
}

/// The frames from `first` on, left over after the lane groups, one at a
/// time; then every limited frame holds the poses of the frame before it.
#[inline(never)]
pub fn finish<S: Solver + ?Sized>(
    solver: &S,
    first: usize,
    inputs: &[f64],
    out: &mut [S::Pose],
    status: &mut [FrameStatus],
) {
    one_at_a_time(solver, first..status.len(), inputs, out, status);
    let drawn: Vec<S::Pose> = S::poses(&solver.initial_state()).to_vec();
    hold_limited(&drawn, out, status);
}

/// [`Batch::solve_batch`] on every core: a plan whose frames are
/// independent is split into blocks solved in parallel; any other is
/// solved in order on this thread. The results are `solve_batch`'s.
#[cfg(feature = "rayon")]
pub fn solve_batch_parallel<S>(solver: &S, inputs: &[f64], out: &mut [S::Pose], status: &mut [FrameStatus])
where
    S: Batch + Sync + ?Sized,
    S::Pose: Send,
{
    use rayon::prelude::*;
    /// Frames per block: enough to keep a thread busy for tens of
    /// microseconds, few enough to balance the cores.
    const BLOCK: usize = 64 * LANES;
    let frames = status.len();
    let (n, b) = shape(solver, inputs, out, frames);
    if !solver.independent() || frames <= BLOCK {
        return solver.solve_batch(inputs, out, status);
    }
    inputs
        .par_chunks(BLOCK * n)
        .zip(out.par_chunks_mut(BLOCK * b))
        .zip(status.par_chunks_mut(BLOCK))
        .for_each(|((i, o), s)| solver.solve_batch(i, o, s));
    // A block that starts limited held the drawn pose; hold the last
    // frame of the block before it instead.
    let drawn: Vec<S::Pose> = S::poses(&solver.initial_state()).to_vec();
    hold_limited(&drawn, out, status);
}
