//! Many frames in one call: a sweep for a design study or a plot, solved
//! with the results a [`Driver`] gives frame after frame
//! (keep-branch policy, limit policy, from the drawn pose), faster.
//!
//! Under keep-branch, a closed-form plan's frames do not depend on each
//! other (each step's root is the branch chosen at plan time, and nothing
//! a frame writes is read by the next), so compiled closed-form plans solve
//! them [`LANES`] at a time ([`lane_groups`]), and with the `rayon` feature
//! `solve_batch_parallel` (feature `rayon`) splits a long sweep over every core. A plan
//! with numeric clusters warm-starts each frame's Newton solve from the
//! last one, so its frames are solved in order ([`in_order`]); so are the
//! interpreter's.
//!
//! A frame that does not assemble gets [`FrameStatus::Limited`] with the
//! step that broke, and the poses of the last frame that did (the drawn
//! pose before the first), as the driver's limit policy keeps them. Past a
//! limit the frames depend on each other again (the mechanism stays on the
//! circuit it left until the input comes back into its interval, see
//! [`Driver`]): [`settle`] drives those frames in order, with a driver.

use crate::drive::{Driver, Solver};
use crate::frame::{BranchPolicy, Break, BreakKind, Ctx, FrameStatus, Options, NEAR_DEAD_POINT};
use crate::lanes::{Lanes, LANES};
use crate::planar::{Pose, Rot};

/// A plan that solves many frames in one call.
pub trait Batch: Solver {
    /// Whether frames are independent of each other under keep-branch, so
    /// that they may be solved in any order, in lanes or on several cores.
    fn independent(&self) -> bool {
        false
    }

    /// For a plan whose frames are [`independent`](Batch::independent):
    /// solves each frame of the batch on its own, from the drawn pose, with
    /// no hold past a limit ([`settle`] applies those afterwards). Any other
    /// plan solves them as [`Batch::solve_batch`] does.
    ///
    /// # Panics
    /// If `inputs` or `out` is not `status.len()` frames long.
    fn solve_frames(&self, inputs: &[f64], out: &mut [Self::Pose], status: &mut [FrameStatus]) {
        in_order(self, inputs, out, status)
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

/// Frames solved each on its own ([`Batch::solve_frames`]) made the
/// driver's: from each frame that breaks, the frames are driven in order by
/// a [`Driver`] placed at the pose before it (the drawn pose before the
/// first frame), until the driver is no longer held past a limit nor beside
/// a dead point. A limited frame then holds the pose before it, a frame
/// that assembles only on another circuit is held too, and so is one that
/// assembles past a gap narrower than the step from the frame before
/// (frames beside a dead point come from [`Batch::solve_frames`] marked
/// [`BreakKind::NearDeadPoint`] for this). The frames of an independent plan between
/// the holds are the driver's already, to the bit.
pub fn settle<S: Solver + ?Sized>(
    solver: &S,
    inputs: &[f64],
    out: &mut [S::Pose],
    status: &mut [FrameStatus],
) {
    let (n, b) = shape(solver, inputs, out, status.len());
    let mut k = 0;
    while k < status.len() {
        if status[k].is_solved() {
            k += 1;
            continue;
        }
        let mut driver = Driver::new(solver, Options::default());
        if k > 0 {
            let before = &inputs[(k - 1) * n..k * n];
            let mut state = solver.initial_state();
            let mut ctx = Ctx::new(BranchPolicy::Keep, false);
            if solver.solve(&mut state, before, &mut ctx).is_ok() {
                driver.place(&state, before);
            }
        }
        loop {
            status[k] = driver.frame(&inputs[k * n..(k + 1) * n]);
            out[k * b..(k + 1) * b].copy_from_slice(driver.poses());
            k += 1;
            // A frame beside a dead point is followed by the next: the gap
            // may lie between them.
            if (driver.held().is_none() && !driver.near_dead_point()) || k == status.len() {
                break;
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
        Ok(()) if ctx.near < NEAR_DEAD_POINT => {
            // Whether the way here from the frame before crosses a gap is
            // for `settle` to find out, in order.
            out.copy_from_slice(S::poses(state));
            FrameStatus::Limited {
                brk: Break {
                    step: 0,
                    kind: BreakKind::NearDeadPoint,
                    gap: ctx.near,
                },
            }
        }
        Ok(()) => {
            out.copy_from_slice(S::poses(state));
            FrameStatus::Solved
        }
        Err(brk) => FrameStatus::Limited { brk },
    }
}

/// [`Batch::solve_batch`] frame after frame by a [`Driver`], each frame
/// warm-started from the last that assembled: exactly a driver's run.
pub fn in_order<S: Solver + ?Sized>(
    solver: &S,
    inputs: &[f64],
    out: &mut [S::Pose],
    status: &mut [FrameStatus],
) {
    let (n, b) = shape(solver, inputs, out, status.len());
    let mut driver = Driver::new(solver, Options::default());
    for (k, st) in status.iter_mut().enumerate() {
        *st = driver.frame(&inputs[k * n..(k + 1) * n]);
        out[k * b..(k + 1) * b].copy_from_slice(driver.poses());
    }
}

/// The lane groups of a batch for a compiled closed-form plan, which runs
/// [`Batch::solve_batch`] as
///
/// ```text
/// for g in 0..lane_groups(..) {
///     match solve_lanes(&group_inputs(inputs, g), group_rows(out, g)) {
///         Ok(()) => solved(status, g),
///         Err(_) => one_at_a_time(.., g * LANES..(g + 1) * LANES, ..),
///     }
/// }
/// finish(.., lane_groups * LANES, ..)
/// ```
///
/// — [`LANES`] frames at a time through its steps on [`Lanes`], each body's
/// poses written to the group's rows ([`put_body`]) as soon as its last
/// step has placed it; a group whose frames part ways at some step, and the
/// frames left over, one at a time. The loop is written out in the
/// generated module (not a function taking `solve_lanes` as an argument)
/// so that a copy compiled for wider vector registers inlines the steps.
/// This checks the buffers' lengths and returns the number of whole groups.
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

/// The rows of `out` that lane group `g` fills: one row of `B` poses for
/// each of its [`LANES`] frames (a fixed-size array, so that the stores
/// into it need no bounds checks).
#[inline(always)]
pub fn group_rows<const B: usize>(out: &mut [Pose], g: usize) -> &mut [[Pose; B]; LANES] {
    let rows = &mut out[g * LANES * B..(g + 1) * LANES * B];
    // SAFETY: `rows` is LANES·B poses in a row (the slicing checked it),
    // which is the layout of `[[Pose; B]; LANES]`, and it is borrowed
    // mutably for as long as the result.
    unsafe { &mut *rows.as_mut_ptr().cast::<[[Pose; B]; LANES]>() }
}

/// Body `b`'s poses of a lane group into its frames' rows: lane `l` goes
/// to `rows[l][b]`. Generated `solve_lanes` calls it right after the
/// body's last step, so that these stores overlap the steps that follow
/// rather than wait in a burst at the end of the group (on a long sweep
/// each row goes out to main memory).
#[inline(always)]
pub fn put_body<const B: usize>(pose: &Pose<Lanes>, rows: &mut [[Pose; B]; LANES], b: usize) {
    // The stores stay here, between the steps before and after, with the
    // steps' own loads and stores on their side. Left free, the compiler
    // moves memory operations across this point, and its order ran the
    // stress chains 10–30% slower: stress_50 164–169 against 114–122
    // ns/frame on its sweep and 183–187 against 134–152 on 20,000 frames,
    // the same code otherwise (a prefetch of the next group's rows, tried
    // first, won back part of it on the shorter chains only, and nothing
    // more once this fence was in). Which of the compiler's moves cost was
    // not pinned down. A fence for the compiler only: no instruction.
    core::sync::atomic::compiler_fence(core::sync::atomic::Ordering::SeqCst);
    // Two frames at a time: (x, x'), (y, y') → (x, y), (x', y') is one
    // unpack each (SSE2, every x86-64 CPU has it), not four lone stores
    // per pose.
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_loadu_pd, _mm_storeu_pd, _mm_unpackhi_pd, _mm_unpacklo_pd};
        for l in (0..LANES).step_by(2) {
            let (first, second) = rows[l..l + 2].split_at_mut(1);
            let (p0, p1) = (&mut first[0][b], &mut second[0][b]);
            // SAFETY: each load reads lanes l and l + 1 of a `[f64; LANES]`
            // (l + 1 < LANES, LANES even); each store writes two adjacent
            // f64s of one `Pose`, `at` (an array) or `rot` (`#[repr(C)]`:
            // c then s), through a pointer to the whole of it.
            unsafe {
                let x = _mm_loadu_pd(pose.at[0].0.as_ptr().add(l));
                let y = _mm_loadu_pd(pose.at[1].0.as_ptr().add(l));
                let c = _mm_loadu_pd(pose.rot.c.0.as_ptr().add(l));
                let s = _mm_loadu_pd(pose.rot.s.0.as_ptr().add(l));
                _mm_storeu_pd(p0.at.as_mut_ptr(), _mm_unpacklo_pd(x, y));
                _mm_storeu_pd((&mut p0.rot as *mut Rot).cast(), _mm_unpacklo_pd(c, s));
                _mm_storeu_pd(p1.at.as_mut_ptr(), _mm_unpackhi_pd(x, y));
                _mm_storeu_pd((&mut p1.rot as *mut Rot).cast(), _mm_unpackhi_pd(c, s));
            }
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    for (l, row) in rows.iter_mut().enumerate() {
        row[b] = Pose {
            at: [pose.at[0].0[l], pose.at[1].0[l]],
            rot: Rot {
                c: pose.rot.c.0[l],
                s: pose.rot.s.0[l],
            },
        };
    }
}

/// Lane group `g`'s frames are solved (its rows all written).
#[inline(always)]
pub fn solved(status: &mut [FrameStatus], g: usize) {
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
/// time (holds past limits are [`settle`]'s).
#[inline(never)]
pub fn finish<S: Solver + ?Sized>(
    solver: &S,
    first: usize,
    inputs: &[f64],
    out: &mut [S::Pose],
    status: &mut [FrameStatus],
) {
    one_at_a_time(solver, first..status.len(), inputs, out, status);
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
        .for_each(|((i, o), s)| solver.solve_frames(i, o, s));
    // The holds past limits run across the blocks, in order.
    settle(solver, inputs, out, status);
}
