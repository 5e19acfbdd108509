//! `dofplan analyze --sensitivity` on a planar file: how each traced
//! marker's path depends on every design parameter over the sweep (exact
//! derivatives, [`crate::synth::planar::sensitivity`]), the parameters
//! ranked by their largest effect, and with a tolerance the worst-case
//! first-order deviation of each traced marker beside a Monte-Carlo
//! spread (the report itself: `report/sensitivity.rs`).

use std::io::Write;

use dofplan_runtime::{Driver, Options};

use crate::model::{Mechanism, Sweep};
use crate::report::sensitivity::{gather, untraced, write, Subject};
use crate::report::{Form, Outcome};
use crate::simulate::sweep_requests;
use crate::synth::planar::{monte_carlo, sensitivity, worst_case, Design};

pub use crate::report::sensitivity::Study;

/// Runs the study over `sweep` and prints it in `form` (text or JSON).
pub fn run(m: &Mechanism, sweep: &Sweep, study: Study, form: Form, out: &mut dyn Write) -> Outcome {
    if sweep.trace.is_empty() {
        return Ok(Err(untraced(&m.source.name)));
    }
    let fail = |e: crate::synth::SynthError| Ok(Err(format!("{}: error: {e}", m.source.name)));
    let design = match Design::new(m) {
        Ok(d) => d,
        Err(e) => return fail(e),
    };
    let base = match design.prepare(&design.drawn()) {
        Ok(b) => b,
        Err(e) => return fail(e),
    };
    let subject = Subject {
        mechanism: &m.name,
        traced: sweep.trace.iter().map(|id| m.marker_name(*id)).collect(),
        parameters: design.names(),
        drawn: design.drawn(),
        primary: &m.inputs[sweep.primary().input],
        primary_index: sweep.primary().input,
    };
    let requested: Vec<Vec<f64>> = sweep_requests(sweep, m.inputs.len()).collect();
    let mut driver = Driver::new(base.interpreter.clone(), Options::default());
    let frame = |inputs: &[f64]| {
        driver.frame(inputs).is_solved().then(|| {
            let poses = driver.poses();
            let at = sweep
                .trace
                .iter()
                .map(|id| poses[id.body].world(m.marker(*id).at))
                .collect();
            let s = sensitivity(&design, &base, poses, inputs);
            (
                at,
                s.map(|s| {
                    (
                        sweep.trace.iter().map(|id| s.marker(*id)).collect(),
                        s.conditioning,
                    )
                }),
            )
        })
    };
    let g = match gather(&subject, requested, study, form, worst_case, frame) {
        Ok(g) => g,
        Err(e) => return fail(e),
    };
    let spread = match (study.tolerance, study.monte_carlo) {
        (Some(t), Some(n)) => Some(monte_carlo(
            &design,
            &g.requested,
            &sweep.trace,
            &g.nominal,
            (n, t, study.seed),
        )),
        _ => None,
    };
    write(&subject, study, g, spread.as_ref(), form, out)?;
    Ok(Ok(()))
}
