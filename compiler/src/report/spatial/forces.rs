//! `dofplan analyze --forces` on a spatial file: each frame's input forces
//! (`forces::spatial::input_forces`, virtual work) and joint reactions
//! (`forces::spatial::reactions`), written by the shared report
//! (`report/forces.rs`).

use std::io::Write;

use dofplan_runtime::{Driver, FrameStatus, Options};

use super::frames::frame_value;
use crate::forces::spatial::{advantage, force_plan, input_forces, joint_axes, reactions, Moving, Reactions};
use crate::interp::spatial::Interpreter;
use crate::model::spatial::{JointKind, Mechanism};
use crate::model::Sweep;
use crate::plan::spatial::Plan;
use crate::report::forces::{no_loads, Carried, Carry, Names, Plots, Running, Solved};
use crate::report::{Form, Outcome};
use crate::simulate::spatial::{marker_positions, residual};
use dofplan_runtime::spatial::{dot, Pose3};

/// Runs the sweep with each frame's input forces and joint reactions:
/// statics when `running` is None, kinetostatics at its rate and
/// acceleration when given; with `plots`, plots written there.
#[allow(clippy::too_many_arguments)]
pub fn run(
    m: &Mechanism,
    plan: &Plan,
    sweep: &Sweep,
    running: Option<Running>,
    form: Form,
    plots: Option<Plots>,
    out: &mut dyn Write,
) -> Outcome {
    if m.loads.is_empty() {
        return Ok(Err(no_loads(&m.source.name)));
    }
    let interp = Interpreter::new(plan.clone());
    // Made once: which equations fix which reaction unknowns.
    let forces_plan = force_plan(m);
    let mut driver = Driver::new(interp.clone(), Options::default());
    let motion = running.map(|r| r.of(&m.inputs, sweep));
    let moving = motion
        .as_ref()
        .map(|(rates, accelerations)| Moving { rates, accelerations });
    let markers: Vec<String> = m.all_markers().map(|id| m.marker_name(id)).collect();
    let input_names: Vec<String> = m.inputs.iter().map(|i| i.name.clone()).collect();
    let names = Names {
        name: &m.name,
        inputs: &m.inputs,
        joints: m.joints.iter().map(|j| j.name.as_str()).collect(),
        moments: m.joints.iter().map(|j| j.kind != JointKind::Spherical).collect(),
        driven: (0..m.joints.len())
            .map(|j| m.inputs.iter().any(|i| i.joint == j))
            .collect(),
        markers: markers.clone(),
        dimension: 3,
        constrained: !m.constraints.is_empty(),
        polar_axes: ("along the joint's x", "along its y"),
    };
    crate::report::forces::run(&names, sweep, running, form, plots, out, |i, requested, json| {
        let status = driver.frame(requested);
        let carried = (status == FrameStatus::Solved).then(|| {
            let q = input_forces(m, &interp, driver.state(), driver.inputs(), moving)?;
            let actual = match moving {
                Some(mv) => {
                    Some(interp.rates(driver.state(), driver.inputs(), mv.rates, mv.accelerations)?)
                }
                None => None,
            };
            Ok(Carried {
                inputs: q,
                advantage: advantage(m, &interp, driver.state(), driver.inputs()).and_then(Result::ok),
                reactions: forces_plan
                    .as_ref()
                    .and_then(|plan| reactions(m, plan, driver.poses(), actual.as_deref()))
                    .map(|r| carry(m, driver.poses(), r)),
            })
        });
        let json = json.then(|| {
            let poses = driver.poses();
            let reached = driver.inputs();
            frame_value(
                m,
                &markers,
                &input_names,
                i,
                status,
                requested,
                reached,
                poses,
                &marker_positions(m, poses),
                residual(m, poses, reached),
            )
        });
        Solved {
            status,
            json,
            carried,
        }
    })
}

/// Spatial reactions in the shared report's form; a joint's polar
/// components are along its first marker's x and y (across its axis).
fn carry(m: &Mechanism, poses: &[Pose3], r: Reactions) -> Carry {
    let polar = (0..m.joints.len())
        .map(|j| {
            let [x, y, _] = joint_axes(m, j, poses);
            [dot(r.forces[j], x), dot(r.forces[j], y)]
        })
        .collect();
    Carry {
        forces: r.forces.iter().map(|f| f.to_vec()).collect(),
        moments: r.moments.iter().map(|m| m.to_vec()).collect(),
        indeterminate: r.indeterminate,
        residual: r.residual,
        shaking: (r.shaking[..3].to_vec(), r.shaking[3..].to_vec()),
        polar,
    }
}
