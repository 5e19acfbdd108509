//! Spatial runs: poses as (x, y, z, qw, qx, qy, qz), the rotation from the
//! drawing as a unit quaternion with qw ≥ 0. A spatial plan's frames depend
//! on each other (each action moves a body from its last pose): always the
//! driver, frame after frame.

use dofplan::interp::spatial::Interpreter;
use dofplan::model::spatial::Mechanism;
use dofplan::model::MarkerId;
use dofplan::plan::spatial::Plan;
use dofplan::simulate::spatial::{motion, residual};
use dofplan_runtime::spatial::Pose3;
use dofplan_runtime::{Driver, FrameStatus, Options};

use super::{driven, finish, rate_code, Drive, Rates, Rows, Run, Solved};

/// `rows` run through `plan` by the driver, with the rates if asked for.
pub(super) fn run(
    m: &Mechanism,
    plan: &Plan,
    rows: &Rows,
    options: Options,
    drive: Option<&Drive>,
    check: bool,
) -> Solved {
    let markers: Vec<_> = m.all_markers().collect();
    let run = in_order(m, Interpreter::new(plan.clone()), rows, options, drive);
    finish(
        run,
        (m.bodies.len(), 7),
        (markers.len(), 3),
        m.inputs.len(),
        |poses, inputs, pose_row, marker_row| {
            read_off(m, &markers, poses, pose_row, marker_row);
            if check {
                residual(m, poses, inputs)
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
) -> Run<Pose3> {
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
            if status != FrameStatus::Solved {
                return r.none(k * 3, b * 3, 1);
            }
            match (driver.solver()).rates(driver.state(), driver.inputs(), &d.rates, &d.accelerations) {
                Ok(jets) => {
                    let mo = motion(m, &jets);
                    r.velocity.extend(mo.velocity.iter().flatten());
                    r.acceleration.extend(mo.acceleration.iter().flatten());
                    r.omega.extend(mo.omega.iter().flatten());
                    r.alpha.extend(mo.alpha.iter().flatten());
                    r.code.push(0);
                }
                Err(e) => r.none(k * 3, b * 3, rate_code(&e)),
            }
        },
    )
}

/// A frame's pose rows (x, y, z, then the rotation from the drawing as a
/// unit quaternion) and the world positions of `markers`, written into its
/// rows.
fn read_off(
    m: &Mechanism,
    markers: &[MarkerId],
    poses: &[Pose3],
    pose_row: &mut [f64],
    marker_row: &mut [f64],
) {
    for (p, out) in poses.iter().zip(pose_row.chunks_exact_mut(7)) {
        out[..3].copy_from_slice(&p.pos);
        out[3..].copy_from_slice(&quaternion(&p.rot.m));
    }
    for (&id, out) in markers.iter().zip(marker_row.chunks_exact_mut(3)) {
        out.copy_from_slice(&poses[id.body].world(m.marker(id).at));
    }
}

/// A rotation matrix (rows) as the unit quaternion (w, x, y, z), w ≥ 0.
fn quaternion(r: &[[f64; 3]; 3]) -> [f64; 4] {
    let matrix = nalgebra::Matrix3::new(
        r[0][0], r[0][1], r[0][2], r[1][0], r[1][1], r[1][2], r[2][0], r[2][1], r[2][2],
    );
    let q =
        nalgebra::UnitQuaternion::from_rotation_matrix(&nalgebra::Rotation3::from_matrix_unchecked(matrix));
    let sign = if q.w < 0.0 { -1.0 } else { 1.0 };
    [sign * q.w, sign * q.i, sign * q.j, sign * q.k]
}

/// `marker` of `m` pinned to each of `targets` in turn, the inputs released
/// (`dofplan drag`'s plan: one cluster with the marker pinned, solved by
/// task priority), by the driver under `options`. The residual is the
/// joints' and constraints'.
pub(super) fn drag(
    m: &Mechanism,
    marker: dofplan::model::MarkerId,
    targets: &Rows,
    options: Options,
) -> Result<Solved, String> {
    if m.bodies[marker.body].fixed {
        return Err(format!(
            "`{}` is on a fixed body and cannot be dragged: drag a marker of a moving body",
            m.marker_name(marker)
        ));
    }
    let free = dofplan::numeric::spatial::released(m);
    let plan = dofplan::numeric::spatial::drag_plan(m, marker);
    let run = driven(
        &mut Driver::new(Interpreter::new(plan), options),
        targets,
        None,
        |_, _, _| {},
    );
    let b = m.bodies.len();
    let markers: Vec<_> = m.all_markers().collect();
    Ok(finish(
        run,
        (b, 7),
        (markers.len(), 3),
        3,
        |poses, inputs, pose_row, marker_row| {
            read_off(m, &markers, poses, pose_row, marker_row);
            residual(&free, poses, inputs)
        },
    ))
}
