//! `dofplan analyze --sensitivity` on a spatial file: as on a planar one
//! (`report/planar/sensitivity.rs`), with the spatial derivatives
//! ([`crate::synth::spatial::sensitivity`]), the exact worst case of a
//! point in space and spatial candidates for the Monte-Carlo spread. A
//! traced point that an idle spin turns (a point of an RSSR's coupler off
//! its axis) has no derivatives the input decides: refused, by name.

use std::io::Write;

use dofplan_runtime::{Driver, Options};

use crate::model::spatial::Mechanism;
use crate::model::Sweep;
use crate::report::sensitivity::{gather, untraced, write, Study, Subject};
use crate::report::{Form, Outcome};
use crate::simulate::sweep_requests;
use crate::synth::spatial::{monte_carlo, sensitivity, worst_case, Design, Sensitivity};
use crate::synth::SynthError;

/// Runs the study over `sweep` and prints it in `form` (text or JSON).
pub fn run(m: &Mechanism, sweep: &Sweep, study: Study, form: Form, out: &mut dyn Write) -> Outcome {
    if sweep.trace.is_empty() {
        return Ok(Err(untraced(&m.source.name)));
    }
    let fail = |e: SynthError| Ok(Err(format!("{}: error: {e}", m.source.name)));
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
    let spun = |s: &Sensitivity| sweep.trace.iter().find(|id| !s.determined(**id)).copied();
    let mut driver = Driver::new(base.interpreter.clone(), Options::default());
    let mut idle = None;
    let frame = |inputs: &[f64]| {
        driver.frame(inputs).is_solved().then(|| {
            let poses = driver.poses();
            let at = sweep
                .trace
                .iter()
                .map(|id| poses[id.body].world(m.marker(*id).at))
                .collect();
            let s = sensitivity(&design, &base, poses, inputs);
            if let Some(id) = s.as_ref().ok().and_then(spun) {
                idle = Some(id);
            }
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
    if let Some(id) = idle {
        return Ok(Err(format!(
            "{}: error: traced marker {} moves with an idle spin of its body (a spin no input drives), so how it depends on the dimensions is not determined; trace a point on the spin's axis, or on another body",
            m.source.name,
            m.marker_name(id)
        )));
    }
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
