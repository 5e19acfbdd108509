//! Planar runs: poses as (angle in degrees from the drawing, x, y).

use dofplan::interp::Interpreter;
use dofplan::model::{MarkerId, Mechanism};
use dofplan::plan::Plan;
use dofplan::simulate::planar::{kinematics::motion, marker_at, max_relative_residual_at};
use dofplan_runtime::planar::Pose;
use dofplan_runtime::{Batch, Driver, FrameStatus, Options, Solver};

use super::{driven, finish, rate_code, Drive, Rates, Rows, Run, Solved};

/// Frames enough for the batch on every core to pay (below, one core's
/// driver is as quick).
const PARALLEL_FRAMES: usize = 4096;

/// `rows` run through `plan`: on every core where that gives the driver's
/// frames (see [`on_every_core`]) and `parallel` allows it, else by the
/// driver, frame after frame (with the rates, if asked for).
pub(super) fn run(
    m: &Mechanism,
    plan: &Plan,
    rows: &Rows,
    options: Options,
    drive: Option<&Drive>,
    (parallel, check): (bool, bool),
) -> Solved {
    let interp = Interpreter::new(plan.clone());
    let run = match (parallel && drive.is_none())
        .then(|| on_every_core(&interp, rows, options))
        .flatten()
    {
        Some(run) => run,
        None => in_order(m, interp, rows, options, drive),
    };
    let markers: Vec<_> = m.all_markers().collect();
    let size = m.size();
    finish(
        run,
        (m.bodies.len(), 3),
        (markers.len(), 2),
        m.inputs.len(),
        |poses, inputs, pose_row, marker_row| {
            read_off(m, &markers, poses, pose_row, marker_row);
            // The residual is a check, asked for: it costs more than the
            // frame (an atan2 for every joint).
            if check {
                max_relative_residual_at(m, size, poses, inputs)
            } else {
                f64::NAN
            }
        },
    )
}

/// The driver's run, frame after frame; with `drive`, each solved frame's
/// rates from the state the driver left.
fn in_order(
    m: &Mechanism,
    interp: Interpreter,
    rows: &Rows,
    options: Options,
    drive: Option<&Drive>,
) -> Run<Pose> {
    let mut driver = Driver::new(interp, options);
    let (b, k) = (m.bodies.len(), m.all_markers().count());
    driven(
        &mut driver,
        rows,
        drive.map(|_| Rates::default()),
        |driver, status, rates| {
            let (Some(d), Some(r)) = (drive, rates.as_mut()) else {
                return;
            };
            // Rates only where the frame met its inputs: a held pose has none
            // of its own.
            if status != FrameStatus::Solved {
                return r.none(k * 2, b, 1);
            }
            match (driver.solver()).rates(driver.state(), driver.inputs(), &d.rates, &d.accelerations) {
                Ok(jets) => {
                    let mo = motion(m, &jets);
                    r.velocity.extend(mo.velocity.iter().flatten());
                    r.acceleration.extend(mo.acceleration.iter().flatten());
                    r.omega.extend(&mo.omega);
                    r.alpha.extend(&mo.alpha);
                    r.code.push(0);
                }
                Err(e) => r.none(k * 2, b, rate_code(&e)),
            }
        },
    )
}

/// A long run of a closed-form plan under keep-branch and limit (the
/// driver's defaults) on every core by `solve_batch_parallel`, which gives
/// the driver's frames to the bit (`tests/planar/batch.rs`). `None` where
/// that does not hold: another policy, a plan with a numeric cluster, a
/// short run, or a sweep whose first frame a sweep's driver does not meet
/// (until its first pose a sweep's frames are "unreached"; the batch
/// starts from the drawing).
fn on_every_core(interp: &Interpreter, rows: &Rows, options: Options) -> Option<Run<Pose>> {
    let defaults = Options::default();
    let driver_like = options.breaking == defaults.breaking
        && options.branch == defaults.branch
        && options.search_tolerance == defaults.search_tolerance;
    if !driver_like || !interp.independent() || rows.len() < PARALLEL_FRAMES {
        return None;
    }
    // From a pose both drivers met on, they are one.
    if options.start != defaults.start
        && !Driver::new(interp.clone(), options)
            .frame(rows.row(0))
            .is_solved()
    {
        return None;
    }
    let flat = rows.flat();
    let b = dofplan_runtime::Solver::initial_state(interp).poses.len();
    let mut poses = vec![Pose::IDENTITY; rows.len() * b];
    let mut status = vec![FrameStatus::Solved; rows.len()];
    dofplan_runtime::batch::solve_batch_parallel(interp, flat, &mut poses, &mut status);
    // The inputs of the pose reached: a frame's own where it met them, else
    // those of the pose it holds (the last it met, or the drawing's).
    let drawn = interp.initial_inputs();
    let mut at: &[f64] = drawn.as_ref();
    let mut reached = Vec::with_capacity(flat.len());
    for (requested, s) in rows.iter().zip(&status) {
        if s.is_solved() {
            at = requested;
        }
        reached.extend_from_slice(at);
    }
    Some(Run {
        poses,
        reached,
        status,
        rates: None,
    })
}

/// `marker` of `m` pinned to each of `targets` in turn, the inputs
/// released (`dofplan drag`'s solver: Newton–Raphson with the SVD
/// pseudo-inverse, the smallest motion), by the driver under `options`. The
/// inputs reached are the targets met; the residual is the joints' and
/// constraints' (the inputs are free).
pub(super) fn drag(
    m: &Mechanism,
    marker: dofplan::model::MarkerId,
    targets: &Rows,
    options: Options,
) -> Result<Solved, String> {
    let solver = dofplan::numeric::planar::drag::Drag::new(m, marker).map_err(|e| e.to_string())?;
    let run = driven(&mut Driver::new(solver, options), targets, None, |_, _, _| {});
    let b = m.bodies.len();
    let mut free = m.clone();
    free.inputs.clear();
    let markers: Vec<_> = m.all_markers().collect();
    let size = m.size();
    Ok(finish(
        run,
        (b, 3),
        (markers.len(), 2),
        2,
        |poses, _, pose_row, marker_row| {
            read_off(m, &markers, poses, pose_row, marker_row);
            max_relative_residual_at(&free, size, poses, &[])
        },
    ))
}

/// A frame's pose rows (angle in degrees from the drawing, x, y) and the
/// world positions of `markers`, written into its rows.
fn read_off(
    m: &Mechanism,
    markers: &[MarkerId],
    poses: &[Pose],
    pose_row: &mut [f64],
    marker_row: &mut [f64],
) {
    for (p, out) in poses.iter().zip(pose_row.chunks_exact_mut(3)) {
        out.copy_from_slice(&[dofplan::report::planar::frames::angle(p), p.at[0], p.at[1]]);
    }
    for (&id, out) in markers.iter().zip(marker_row.chunks_exact_mut(2)) {
        out.copy_from_slice(&marker_at(m, poses, id));
    }
}
