//! Running a plan over a sweep and reading the result: marker positions and
//! the residual of every joint, constraint and input.

pub mod planar;
pub mod spatial;

pub use planar::{marker_at, marker_positions, max_relative_residual, residuals, Residual};

use dofplan_runtime::numeric::NewtonReport;
use dofplan_runtime::planar::Pose;
use dofplan_runtime::{Animate, Driver, FrameStatus, Options, Solver};

use crate::model::{Input, InputKind, Mechanism, Sweep};

/// One solved (or broken) frame.
#[derive(Clone, Debug)]
pub struct Frame {
    /// The requested input values, in mechanism order.
    pub requested: Vec<f64>,
    /// The input values of the pose reached (differ after a break).
    pub inputs: Vec<f64>,
    /// What happened.
    pub status: FrameStatus,
    /// Every body's pose, in mechanism order.
    pub poses: Vec<Pose>,
    /// The Newton–Raphson report, when a numeric solver placed the frame.
    pub numeric: Option<NewtonReport>,
}

/// The requested inputs of every frame of the mechanism's sweep (the swept
/// input takes the sweep's values, the others stay at 0). `steps` overrides
/// the sweep's step count.
pub fn sweep_inputs(m: &Mechanism, steps: Option<usize>) -> Vec<Vec<f64>> {
    let Some(sweep) = &m.sweep else {
        return Vec::new();
    };
    let mut sweep = sweep.clone();
    if let Some(n) = steps {
        sweep.steps = n.max(1);
    }
    sweep_requests(&sweep, m.inputs.len()).collect()
}

/// The requested inputs of every frame of `sweep` for a mechanism with
/// `inputs` inputs (the swept one takes the sweep's values, the others stay
/// at 0), made one at a time: a long sweep streams without holding them all.
pub fn sweep_requests(sweep: &Sweep, inputs: usize) -> impl ExactSizeIterator<Item = Vec<f64>> {
    let sweep = sweep.clone();
    (0..sweep.steps).map(move |i| {
        let mut requested = vec![0.0; inputs];
        sweep.set(i, &mut requested);
        requested
    })
}

/// Drives any solver through `requested` frames.
pub fn run<S: Solver<Pose = Pose>>(solver: S, options: Options, requested: &[Vec<f64>]) -> Vec<Frame> {
    let mut driver = Driver::new(solver, options);
    frames(&mut driver, requested).collect()
}

/// Drives a trait-object driver (e.g. a compiled plan picked by name).
pub fn run_animate(driver: &mut dyn Animate, requested: &[Vec<f64>]) -> Vec<Frame> {
    frames(driver, requested).collect()
}

/// The frames of `driver` driven through `requested`, solved one at a time
/// as the iterator is advanced: a caller that writes each frame out and
/// drops it runs a sweep of any length in constant memory, and stops the
/// solving by stopping the iteration.
pub fn frames<D, I>(driver: &mut D, requested: I) -> Frames<'_, D, I::IntoIter>
where
    D: Animate + ?Sized,
    I: IntoIterator,
    I::Item: AsRef<[f64]>,
{
    Frames {
        driver,
        requested: requested.into_iter(),
    }
}

/// The iterator of [`frames`].
pub struct Frames<'d, D: ?Sized, I> {
    driver: &'d mut D,
    requested: I,
}

impl<D, I> Iterator for Frames<'_, D, I>
where
    D: Animate + ?Sized,
    I: Iterator,
    I::Item: AsRef<[f64]>,
{
    type Item = Frame;

    fn next(&mut self) -> Option<Frame> {
        let requested = self.requested.next()?;
        let requested = requested.as_ref();
        let status = self.driver.frame(requested);
        Some(Frame {
            requested: requested.to_vec(),
            inputs: self.driver.inputs().to_vec(),
            status,
            poses: self.driver.poses().to_vec(),
            numeric: self.driver.numeric(),
        })
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        self.requested.size_hint()
    }
}

/// The frames of a sweep or drag when the file and the command line say
/// nothing.
pub const DEFAULT_STEPS: usize = 101;

/// The sweep a command runs (`simulate`, `analyze`): the file's `[sweep]`
/// with the command line's overrides, or one made of them alone. An error
/// is a message and what to do.
pub fn sweep_to_run(
    m: &dyn SweepSource,
    input: Option<&str>,
    from: Option<f64>,
    to: Option<f64>,
    steps: Option<usize>,
) -> Result<Sweep, (String, String)> {
    let names = || {
        m.inputs()
            .iter()
            .map(|i| i.name.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    };
    if m.inputs().is_empty() {
        return Err((
            "the file has no inputs to simulate".into(),
            format!(
                "drag a marker instead (`dofplan drag {} --marker BODY.MARKER --to X,Y`), or declare [inputs]",
                m.file_name()
            ),
        ));
    }
    let index = match (input, m.sweep()) {
        (Some(name), _) => m.inputs().iter().position(|i| i.name == name).ok_or_else(|| {
            (
                format!("no input `{name}` to sweep"),
                format!("inputs are: {}", names()),
            )
        })?,
        (None, Some(sweep)) if from.is_none() && to.is_none() => {
            // The file's sweep as it is (several inputs may move together).
            let mut sweep = sweep.clone();
            if let Some(n) = steps {
                sweep.steps = n;
            }
            return Ok(sweep);
        }
        (None, Some(sweep)) => sweep.primary().input,
        (None, None) if m.inputs().len() == 1 => 0,
        (None, None) => {
            return Err((
                format!("the file has no [sweep], and {} inputs", m.inputs().len()),
                format!(
                    "add a [sweep] (input, from, to, steps), or say which input to sweep: \
                     --input NAME --from A --to B [--steps N] (inputs are: {})",
                    names()
                ),
            ))
        }
    };
    // The file's range belongs to the file's swept input only.
    let file_range = m
        .sweep()
        .and_then(|s| s.inputs.iter().find(|w| w.input == index))
        .map(|s| (s.from, s.to));
    let (Some(from), Some(to)) = (from.or(file_range.map(|r| r.0)), to.or(file_range.map(|r| r.1))) else {
        let name = &m.inputs()[index].name;
        return Err(match m.sweep() {
            None => (
                "the file has no [sweep] to simulate".into(),
                format!(
                    "add a [sweep] (input, from, to, steps), or give the range here: \
                     --input {name} --from A --to B [--steps N]"
                ),
            ),
            Some(s) => (
                format!(
                    "input `{name}` is not the one the file's [sweep] drives (`{}`), so it has no range",
                    m.inputs()[s.primary().input].name
                ),
                format!("give its range: --input {name} --from A --to B"),
            ),
        });
    };
    Ok(Sweep::single(
        index,
        from,
        to,
        steps.or(m.sweep().map(|s| s.steps)).unwrap_or(DEFAULT_STEPS),
        m.sweep().map(|s| s.trace.clone()).unwrap_or_default(),
    ))
}

/// What [`sweep_to_run`] reads of a mechanism of either dimension.
pub trait SweepSource {
    /// The mechanism's inputs.
    fn inputs(&self) -> &[Input];
    /// The file's `[sweep]`, if it has one.
    fn sweep(&self) -> Option<&Sweep>;
    /// The file's name, as messages write it.
    fn file_name(&self) -> &str;
}

impl SweepSource for Mechanism {
    fn inputs(&self) -> &[Input] {
        &self.inputs
    }
    fn sweep(&self) -> Option<&Sweep> {
        self.sweep.as_ref()
    }
    fn file_name(&self) -> &str {
        &self.source.name
    }
}

impl SweepSource for crate::model::spatial::Mechanism {
    fn inputs(&self) -> &[Input] {
        &self.inputs
    }
    fn sweep(&self) -> Option<&Sweep> {
        self.sweep.as_ref()
    }
    fn file_name(&self) -> &str {
        &self.source.name
    }
}

/// Each input's rate along a sweep, in the input's units per unit of time
/// (degrees for angles), when the sweep's first input moves at `rate`
/// (radians or length units per unit of time) and the others keep their
/// proportions to it.
pub fn sweep_rates(m: &Mechanism, sweep: &Sweep, rate: f64) -> Vec<f64> {
    input_rates(&m.inputs, sweep, rate)
}

/// [`sweep_rates`] of a mechanism's `inputs`, planar or spatial.
pub fn input_rates(inputs: &[Input], sweep: &Sweep, rate: f64) -> Vec<f64> {
    let primary = sweep.primary();
    // Halves, so that a sweep over most of the f64 range (`--from -1e308
    // --to 1e308`) has a finite span; the ratio below is divided first for
    // the same reason.
    let half_span = |s: &crate::model::Swept| 0.5 * s.to - 0.5 * s.from;
    let span = half_span(primary);
    let per_unit = match inputs[primary.input].kind {
        InputKind::Angle => rate.to_degrees(),
        InputKind::Slide => rate,
    };
    let mut rates = vec![0.0; inputs.len()];
    for s in &sweep.inputs {
        rates[s.input] = if span == 0.0 {
            if s.input == primary.input {
                per_unit
            } else {
                0.0
            }
        } else {
            per_unit * (half_span(s) / span.abs())
        };
    }
    rates
}

#[cfg(test)]
mod tests {
    use super::*;
    use dofplan_runtime::numeric::NewtonReport;

    /// A one-body "mechanism" whose pose is its input, counting its frames.
    struct Counting {
        solved: usize,
        inputs: Vec<f64>,
        poses: Vec<Pose>,
    }

    impl Animate for Counting {
        fn frame(&mut self, inputs: &[f64]) -> FrameStatus {
            self.solved += 1;
            self.inputs = inputs.to_vec();
            self.poses[0].at = [inputs[0], 0.0];
            FrameStatus::Solved
        }
        fn poses(&self) -> &[Pose] {
            &self.poses
        }
        fn inputs(&self) -> &[f64] {
            &self.inputs
        }
        fn numeric(&self) -> Option<NewtonReport> {
            None
        }
        fn reset(&mut self) {}
    }

    fn counting() -> Counting {
        Counting {
            solved: 0,
            inputs: vec![0.0],
            poses: vec![Pose::IDENTITY],
        }
    }

    #[test]
    fn frames_are_solved_only_as_they_are_taken() {
        let sweep = Sweep::single(0, 0.0, 1.0, 1_000_000, vec![]);
        let mut driver = counting();
        let taken: Vec<Frame> = frames(&mut driver, sweep_requests(&sweep, 1)).take(3).collect();
        assert_eq!(driver.solved, 3);
        let third = 2.0 / 999_999.0;
        assert_eq!(taken[2].requested, [third]);
        assert_eq!(taken[2].poses[0].at, [third, 0.0]);
    }

    #[test]
    fn sweep_requests_are_the_sweeps_values() {
        let sweep = Sweep::single(1, -1.0, 0.3, 14, vec![]);
        let requested: Vec<Vec<f64>> = sweep_requests(&sweep, 3).collect();
        let values = sweep.values();
        assert_eq!(requested.len(), 14);
        assert_eq!(values[13], 0.3, "the last value is exactly `to`");
        for (r, v) in requested.iter().zip(&values) {
            assert_eq!(r, &[0.0, *v, 0.0]);
        }
    }
}
