//! `dofplan analyze --forces` on a planar file: each frame's input forces
//! (`forces::planar::input_forces`, virtual work), joint reactions
//! (`forces::planar::reactions`) and mechanical advantage, written by the
//! shared report (`report/forces.rs`).

use std::io::Write;

use dofplan_runtime::{Driver, FrameStatus, Options};

use super::frames::{frame_json, sweep_report, Solver};
use crate::forces::planar::{advantage, force_plan, input_forces, reactions, Moving, Reactions};
use crate::interp::Interpreter;
use crate::model::{JointKind, Mechanism, Sweep};
use crate::plan::Plan;
use crate::report::forces::{no_loads, Carried, Carry, Names, Plots, Running, Solved};
use crate::report::{Form, Outcome};
use crate::simulate::Frame;

/// Runs the sweep with each frame's input forces and joint reactions:
/// statics when `running` is None (the mechanism held at each pose: no
/// inertia, dampers idle), kinetostatics at its rate and acceleration
/// when given; with `plots`, plots written there.
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
    let report = sweep_report(m, plan, sweep, Solver::Plan);
    let motion = running.map(|r| r.of(&m.inputs, sweep));
    let moving = motion
        .as_ref()
        .map(|(rates, accelerations)| Moving { rates, accelerations });
    let names = Names {
        name: &m.name,
        inputs: &m.inputs,
        // Gear pairs after the joints: their reaction is the tooth force.
        joints: (m.joints.iter().map(|j| j.name.as_str()))
            .chain(m.slots.iter().map(|s| s.name.as_str()))
            .chain(m.gears.iter().map(|g| g.name.as_str()))
            .collect(),
        moments: (m.joints.iter().map(|j| j.kind == JointKind::Prismatic))
            .chain(m.slots.iter().map(|_| false))
            .chain(m.gears.iter().map(|_| false))
            .collect(),
        driven: (0..m.joints.len())
            .map(|j| m.inputs.iter().any(|i| i.joint == j))
            .chain(m.slots.iter().map(|_| false))
            .chain(m.gears.iter().map(|_| false))
            .collect(),
        markers: m.all_markers().map(|id| m.marker_name(id)).collect(),
        dimension: 2,
        constrained: !m.constraints.is_empty(),
        polar_axes: ("fx", "fy"),
    };
    crate::report::forces::run(&names, sweep, running, form, plots, out, |_, requested, json| {
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
                    .map(carry),
            })
        });
        let json = json.then(|| {
            let frame = Frame {
                requested: requested.to_vec(),
                inputs: driver.inputs().to_vec(),
                status,
                poses: driver.poses().to_vec(),
                numeric: driver.numeric(),
            };
            frame_json(&report, &frame)
        });
        Solved {
            status,
            json,
            carried,
        }
    })
}

/// Planar reactions in the shared report's form.
fn carry(r: Reactions) -> Carry {
    // Slots, then gear pairs, after the joints (as `Names` lists them).
    let mut all = r.forces.clone();
    all.extend(&r.slots);
    all.extend(&r.teeth);
    Carry {
        forces: all.iter().map(|f| f.to_vec()).collect(),
        moments: (r.moments.iter().map(|&m| vec![m]))
            .chain(r.slots.iter().chain(&r.teeth).map(|_| vec![0.0]))
            .collect(),
        indeterminate: r.indeterminate.clone(),
        residual: r.residual,
        shaking: (r.shaking[..2].to_vec(), vec![r.shaking[2]]),
        polar: all,
    }
}
