//! Batch solving (`solve_batch`, in lanes of frames for closed-form plans,
//! and `solve_batch_parallel` on every core) gives the frame-by-frame
//! driver's results: the same statuses, and poses to 1e-12 of the
//! mechanism's size, on every bundled mechanism's sweep, on sweeps driven
//! past their limits, and on frames in shuffled order; every solved frame
//! holds its joints. Compiled spatial plans solve their batches in order
//! (a frame is warm-started from the last: see
//! `compiled_spatial_batches_equal_the_driver`), with the driver's results
//! to the bit.

use dofplan::interp::Interpreter;
use dofplan::model::Mechanism;
use dofplan::plan::spatial::StepKind;
use dofplan::simulate::sweep_requests;
use dofplan::simulate::{max_relative_residual, sweep_inputs};
use dofplan_runtime::batch::solve_batch_parallel;
use dofplan_runtime::planar::Pose;
use dofplan_runtime::spatial::Pose3;
use dofplan_runtime::{Batch, Driver, FrameStatus, Options, Solver};
use dofplan_runtime::{BranchPolicy, Ctx};
use dofplan_tests::{bundled, bundled_spatial, load, load_spatial, plan, plan_spatial, spatial_fixtures};

/// Poses and statuses of `rows` through a driver (keep-branch, limit).
fn driven<S: Solver<Pose = Pose>>(solver: S, rows: &[Vec<f64>]) -> (Vec<Pose>, Vec<FrameStatus>) {
    let mut d = Driver::new(solver, Options::default());
    let mut poses = Vec::new();
    let mut status = Vec::new();
    for r in rows {
        status.push(d.frame(r));
        poses.extend_from_slice(d.poses());
    }
    (poses, status)
}

/// Poses and statuses of `rows` through `batch`.
fn batched(
    rows: &[Vec<f64>],
    bodies: usize,
    batch: impl Fn(&[f64], &mut [Pose], &mut [FrameStatus]),
) -> (Vec<Pose>, Vec<FrameStatus>) {
    let flat: Vec<f64> = rows.iter().flatten().copied().collect();
    let mut out = vec![Pose::IDENTITY; rows.len() * bodies];
    let mut status = vec![FrameStatus::Solved; rows.len()];
    batch(&flat, &mut out, &mut status);
    (out, status)
}

/// `got` equals `want`: statuses exactly (the same break at the same
/// step), poses to 1e-12 of the size, and each solved frame's joints hold.
fn agree(
    name: &str,
    what: &str,
    m: &Mechanism,
    rows: &[Vec<f64>],
    want: &(Vec<Pose>, Vec<FrameStatus>),
    got: &(Vec<Pose>, Vec<FrameStatus>),
) {
    let b = m.bodies.len();
    let tol = 1e-12 * m.size();
    if let Some(k) = (0..got.1.len()).find(|&k| got.1[k] != want.1[k]) {
        panic!(
            "{name} ({what}): frame {k} of {}: {:?} vs the driver's {:?}; before: {:?}; inputs {:?}",
            got.1.len(),
            got.1[k],
            want.1[k],
            &want.1[k.saturating_sub(3)..k],
            &rows[k.saturating_sub(3)..=k]
        );
    }
    for (k, (g, w)) in got.0.chunks(b).zip(want.0.chunks(b)).enumerate() {
        for (j, (p, q)) in g.iter().zip(w).enumerate() {
            let d = (p.at[0] - q.at[0]).abs().max((p.at[1] - q.at[1]).abs());
            let r = (p.rot.c - q.rot.c).abs().max((p.rot.s - q.rot.s).abs());
            assert!(
                d <= tol && r <= 1e-12,
                "{name} ({what}) frame {k} body {}: {p:?} vs {q:?}",
                m.bodies[j].name
            );
        }
        if got.1[k].is_solved() {
            let res = max_relative_residual(m, g, &rows[k]);
            assert!(
                res <= 1e-9,
                "{name} ({what}) frame {k}: relative residual {res:e}"
            );
        }
    }
}

/// The sweep, and the same inputs driven past every limit: each input
/// swept over twice its sweep's span, so the plans that break do.
fn sweeps(m: &Mechanism) -> Vec<(&'static str, Vec<Vec<f64>>)> {
    let sweep = sweep_inputs(m, None);
    let wide: Vec<Vec<f64>> = sweep
        .iter()
        .map(|r| r.iter().map(|x| 2.0 * x - 7.0).collect())
        .collect();
    // A fixed shuffle (a multiplicative step coprime to the length):
    // frames far apart side by side in a lane group.
    let n = sweep.len();
    let step = (1..n)
        .rev()
        .find(|s| gcd(*s, n) == 1 && *s * 3 < n * 2)
        .unwrap_or(1);
    let shuffled: Vec<Vec<f64>> = (0..n).map(|i| sweep[(i * step) % n].clone()).collect();
    vec![
        ("sweep", sweep),
        ("past its limits", wide),
        ("shuffled", shuffled),
    ]
}

fn gcd(a: usize, b: usize) -> usize {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

#[test]
fn compiled_batches_equal_the_driver() {
    for name in bundled() {
        let m = load(&name);
        // Every closed-form plan runs in lanes; a plan with a numeric
        // cluster (warm-started from the last frame) in order.
        let closed_form = plan(&m).clusters() == 0;
        for (what, rows) in sweeps(&m) {
            dofplan_generated::with_plan!(name.as_str(), |plan| {
                assert_eq!(plan.independent(), closed_form, "{name}: in lanes");
                let want = driven(plan, &rows);
                let got = batched(&rows, m.bodies.len(), |i, o, s| plan.solve_batch(i, o, s));
                agree(&name, what, &m, &rows, &want, &got);
            })
            .expect("compiled");
        }
    }
}

#[test]
fn interpreted_batches_equal_the_driver() {
    for name in bundled() {
        let m = load(&name);
        let (what, rows) = sweeps(&m).swap_remove(1);
        let interp = Interpreter::new(plan(&m));
        let want = driven(interp.clone(), &rows);
        let got = batched(&rows, m.bodies.len(), |i, o, s| interp.solve_batch(i, o, s));
        agree(&name, what, &m, &rows, &want, &got);
    }
}

/// Long sweeps on every core: the blocks' results are one core's, to the
/// bit, with a limited frame at a block's start holding the previous
/// block's last pose.
#[test]
fn parallel_batches_equal_one_core() {
    for name in ["fourbar", "rocker_rocker", "stress_10", "chain_4"] {
        let m = load(name);
        let sweep = sweeps(&m).swap_remove(1).1;
        let rows: Vec<Vec<f64>> = sweep.iter().cycle().take(5_000).cloned().collect();
        dofplan_generated::with_plan!(name, |plan| {
            let one = batched(&rows, m.bodies.len(), |i, o, s| plan.solve_batch(i, o, s));
            let all = batched(&rows, m.bodies.len(), |i, o, s| {
                solve_batch_parallel(&plan, i, o, s)
            });
            assert_eq!(all.1, one.1, "{name}: statuses");
            assert!(
                all.0.iter().zip(&one.0).all(|(a, b)| a == b),
                "{name}: poses on every core differ from one core's"
            );
            if name == "rocker_rocker" {
                assert!(one.1.iter().any(|s| !s.is_solved()), "the wide sweep breaks");
            }
        })
        .expect("compiled");
    }
}

/// The interpreter's batches on every core (what the Python package runs
/// for long sweeps) are the driver's frames, to the bit: a closed-form
/// plan's frames are solved each on its own in blocks, then settled in
/// order; a plan with a numeric cluster runs in order.
#[test]
fn interpreted_parallel_batches_equal_the_driver_to_the_bit() {
    for name in ["fourbar", "rocker_rocker", "stress_10", "chain_4", "sixbar_a"] {
        let m = load(name);
        let interp = Interpreter::new(plan(&m));
        assert_eq!(interp.independent(), plan(&m).clusters() == 0, "{name}");
        let sweep = sweeps(&m).swap_remove(1).1;
        let rows: Vec<Vec<f64>> = sweep.iter().cycle().take(5_000).cloned().collect();
        let want = driven(interp.clone(), &rows);
        let all = batched(&rows, m.bodies.len(), |i, o, s| {
            solve_batch_parallel(&interp, i, o, s)
        });
        assert_eq!(all.1, want.1, "{name}: statuses");
        assert!(
            all.0.iter().zip(&want.0).all(|(a, b)| a == b),
            "{name}: poses on every core differ from the driver's"
        );
    }
}

/// Bad buffers are the caller's bug: a panic that says what was expected.
#[test]
#[should_panic(expected = "solve_batch: 3 frames of 1 inputs each")]
fn a_short_input_buffer_is_named() {
    let mut out = vec![Pose::IDENTITY; 3 * 4];
    let mut status = vec![FrameStatus::Solved; 3];
    dofplan_generated::fourbar::Plan.solve_batch(&[0.0, 1.0], &mut out, &mut status);
}

/// The frames of a spatial mechanism's sweep (at most `max`), with its
/// ranges stretched by `reach` (more than 1 drives the inputs past where the
/// mechanism assembles).
fn spatial_rows(m: &dofplan::model::spatial::Mechanism, max: usize, reach: f64) -> Vec<Vec<f64>> {
    let mut sweep = m.sweep.clone().expect("every spatial file has a sweep");
    sweep.steps = sweep.steps.min(max);
    for s in &mut sweep.inputs {
        s.to = s.from + reach * (s.to - s.from);
    }
    sweep_requests(&sweep, m.inputs.len()).collect()
}

/// Every compiled spatial plan's `solve_batch` (the module's, through the
/// `Batch` impl) is the driver's run frame by frame, to the bit, and the
/// interpreter's batch the same to round-off: every
/// status and every pose, on its sweep and, for the plans in closed form,
/// on the sweep stretched past its limits. A spatial frame moves each body
/// from its last pose (idle freedoms and composed rotations carry over),
/// so its frames are not independent and are solved in order, not in
/// lanes: solved from the drawn pose instead, some frames differ.
#[test]
fn compiled_spatial_batches_equal_the_driver() {
    let mut names = bundled_spatial();
    names.extend(spatial_fixtures());
    let (mut limited, mut cold_differs) = (0, 0);
    for name in names {
        let m = load_spatial(&name);
        let closed_form = !(plan_spatial(&m).steps.iter()).any(|s| matches!(s.kind, StepKind::Cluster(_)));
        let max = if name.starts_with("spatial_stress_") {
            12
        } else {
            60
        };
        let mut runs = vec![("sweep", spatial_rows(&m, max, 1.0))];
        if closed_form {
            runs.push(("past its limits", spatial_rows(&m, max, 2.5)));
        }
        for (what, rows) in runs {
            dofplan_generated::with_spatial_plan!(name.as_str(), |plan| {
                assert!(!plan.independent(), "{name}: frames in order");
                let mut d = Driver::new(plan, Options::default());
                let (mut want, mut want_status) = (Vec::new(), Vec::new());
                for r in &rows {
                    want_status.push(d.frame(r));
                    want.extend_from_slice(d.poses());
                }
                let flat: Vec<f64> = rows.iter().flatten().copied().collect();
                let mut out = vec![Pose3::IDENTITY; want.len()];
                let mut status = vec![FrameStatus::Solved; rows.len()];
                plan.solve_batch(&flat, &mut out, &mut status);
                assert_eq!(status, want_status, "{name} ({what}): statuses");
                assert!(out == want, "{name} ({what}): poses differ from the driver's");
                // The interpreter's batch is the compiled one's, to 1e-12
                // of the size (the two back ends agree to round-off).
                let interp = dofplan::interp::spatial::Interpreter::new(plan_spatial(&m));
                let mut again = vec![Pose3::IDENTITY; want.len()];
                let mut again_status = vec![FrameStatus::Solved; rows.len()];
                interp.solve_batch(&flat, &mut again, &mut again_status);
                assert_eq!(
                    again_status, status,
                    "{name} ({what}): the interpreter's statuses"
                );
                // Each pose by its origin and two of its axes, scaled.
                let size = m.size().max(1.0);
                let gap = (again.iter().zip(&out))
                    .flat_map(|(a, b)| {
                        let (ex, ey) = (a.dir([1.0, 0.0, 0.0]), a.dir([0.0, 1.0, 0.0]));
                        let (fx, fy) = (b.dir([1.0, 0.0, 0.0]), b.dir([0.0, 1.0, 0.0]));
                        (0..3).map(move |k| {
                            ((a.pos[k] - b.pos[k]).abs())
                                .max(size * (ex[k] - fx[k]).abs())
                                .max(size * (ey[k] - fy[k]).abs())
                        })
                    })
                    .fold(0.0_f64, f64::max);
                assert!(gap <= 1e-12 * size, "{name} ({what}): interpreter off by {gap:e}");
                limited += status.iter().filter(|s| !s.is_solved()).count();
                // Each solved frame again from the drawn pose.
                let b = want.len() / rows.len().max(1);
                for (k, r) in rows.iter().enumerate() {
                    let mut s = plan.initial_state();
                    let ctx = &mut Ctx::new(BranchPolicy::Keep, false);
                    if status[k].is_solved()
                        && plan.solve(&mut s, r, ctx).is_ok()
                        && s.poses[..] != want[k * b..(k + 1) * b]
                    {
                        cold_differs += 1;
                    }
                }
            })
            .expect("compiled");
        }
    }
    assert!(limited > 0, "some frames break past the limits");
    assert!(
        cold_differs > 0,
        "spatial frames solved from the drawn pose are the driver's: they could run in lanes"
    );
}
