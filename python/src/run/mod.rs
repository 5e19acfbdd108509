//! Frames into NumPy arrays: the requested inputs run through the plan by
//! the driver `dofplan simulate` uses (the same frames, the same breaks),
//! with the interpreter lock released while they are solved; long runs of
//! closed-form planar plans on every core. A run gives each frame's poses,
//! inputs reached and status (`planar.rs`, `spatial.rs`, one per
//! dimension); what is read off the poses (the pose rows, every marker, the
//! residual) is computed for all frames at once, on every core. The arrays
//! are built in Rust vectors and handed to NumPy without a copy.

use dofplan::model::Model;
use dofplan_runtime::real::RateError;
use dofplan_runtime::{BranchPolicy, BreakPolicy, FrameStatus, Options, StartPolicy};
use numpy::ndarray::{Array1, Array2, Array3};
use numpy::{IntoPyArray, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;

use crate::mechanism::{Mechanism, Plans};

mod planar;
mod spatial;

/// The status codes of the `status` array, by index.
pub const STATUS_NAMES: [&str; 5] = ["solved", "limited", "searched", "unreached", "stretched"];

/// The frames' input rows in one buffer (`width` values a frame; a
/// mechanism without inputs has empty rows): a million frames are one
/// allocation, not a million.
pub(crate) struct Rows {
    flat: Vec<f64>,
    width: usize,
    frames: usize,
}

impl Rows {
    /// The rows of a (frames × width) array.
    fn of(a: numpy::ndarray::ArrayView2<'_, f64>) -> Rows {
        Rows {
            flat: a.iter().copied().collect(),
            width: a.ncols(),
            frames: a.nrows(),
        }
    }

    pub(crate) fn len(&self) -> usize {
        self.frames
    }

    /// Frame `k`'s row.
    pub(crate) fn row(&self, k: usize) -> &[f64] {
        &self.flat[k * self.width..(k + 1) * self.width]
    }

    pub(crate) fn iter(&self) -> impl Iterator<Item = &[f64]> + '_ {
        (0..self.frames).map(move |k| self.row(k))
    }

    /// Every row, one after the other.
    pub(crate) fn flat(&self) -> &[f64] {
        &self.flat
    }
}

/// What a run of either dimension gives, frame by frame: the poses (`P`,
/// the dimension's), the inputs of the pose reached, the status, and the
/// rates when asked for.
struct Run<P> {
    /// frames × bodies poses.
    poses: Vec<P>,
    /// frames × inputs.
    reached: Vec<f64>,
    status: Vec<FrameStatus>,
    rates: Option<Rates>,
}

/// `rows` through `driver`, frame after frame: each frame's poses, the
/// inputs of the pose reached and the status; `after` sees the driver
/// after each frame (the rates are read there) and `rates` starts the
/// run's rates if they are asked for.
fn driven<S: dofplan_runtime::Solver>(
    driver: &mut dofplan_runtime::Driver<S>,
    rows: &Rows,
    rates: Option<Rates>,
    mut after: impl FnMut(&dofplan_runtime::Driver<S>, FrameStatus, &mut Option<Rates>),
) -> Run<S::Pose> {
    let b = S::poses(&driver.solver().initial_state()).len();
    let mut run = Run {
        poses: Vec::with_capacity(rows.len() * b),
        reached: Vec::with_capacity(rows.flat().len()),
        status: Vec::with_capacity(rows.len()),
        rates,
    };
    for requested in rows.iter() {
        let status = driver.frame(requested);
        run.poses.extend_from_slice(driver.poses());
        run.reached.extend_from_slice(driver.inputs());
        run.status.push(status);
        after(driver, status, &mut run.rates);
    }
    run
}

/// Every frame's numbers, in flat row-major vectors.
struct Solved {
    frames: usize,
    /// frames × bodies × `pose_width`.
    poses: Vec<f64>,
    pose_width: usize,
    /// frames × markers × `dimension`.
    markers: Vec<f64>,
    dimension: usize,
    /// frames × inputs: the inputs of the pose reached.
    reached: Vec<f64>,
    status: Vec<i8>,
    /// The largest relative residual of every joint, constraint and input.
    residual: Vec<f64>,
    /// The rates, when asked for.
    rates: Option<Rates>,
}

/// Every frame's velocities and accelerations (NaN where a frame has none:
/// not solved, or at a dead point where a rate is infinite).
#[derive(Default)]
struct Rates {
    /// frames × markers × (2 or 3).
    velocity: Vec<f64>,
    acceleration: Vec<f64>,
    /// frames × bodies (× 3 in space): angular velocity, rad per unit of time.
    omega: Vec<f64>,
    alpha: Vec<f64>,
    /// Per frame: 0 rates computed, 1 frame not solved, 2 dead point
    /// (singular), 3 not computed (a numeric cluster without rates).
    code: Vec<i8>,
}

/// The names of the rate codes, by index.
pub const RATE_NAMES: [&str; 4] = ["ok", "not solved", "singular", "not computed"];

/// The inputs' rates and accelerations the interpreter takes (in the
/// inputs' units, degrees for angles), from what the caller gives (radians
/// for angles, as `dofplan analyze --rate`).
pub struct Drive {
    pub rates: Vec<f64>,
    pub accelerations: Vec<f64>,
}

/// `Mechanism.simulate_raw`: `inputs` (frames × the mechanism's inputs) run
/// under `policy` ("limit", "search" or "stretch") and `branch` ("keep" or
/// "nearest"), as `dofplan simulate --policy --branch` runs a sweep.
pub fn simulate<'py>(
    py: Python<'py>,
    mech: &Mechanism,
    inputs: PyReadonlyArray2<'py, f64>,
    policy: &str,
    branch: &str,
    drive: Option<(Vec<f64>, Vec<f64>)>,
    (parallel, check): (bool, bool),
) -> PyResult<Bound<'py, PyDict>> {
    let options = options(policy, branch)?;
    let shape = inputs.as_array().shape().to_vec();
    let n_inputs = mech.input_list().len();
    if shape[1] != n_inputs {
        return Err(PyValueError::new_err(format!(
            "{} has {n_inputs} input(s) ({}), but the inputs have {} column(s)",
            mech.file(),
            mech.input_list()
                .iter()
                .map(|(n, _)| n.as_str())
                .collect::<Vec<_>>()
                .join(", "),
            shape[1]
        )));
    }
    let rows = Rows::of(inputs.as_array());
    if let Some((f, r)) = rows
        .iter()
        .enumerate()
        .find(|(_, r)| r.iter().any(|x| !x.is_finite()))
    {
        return Err(PyValueError::new_err(format!(
            "frame {f}'s inputs are not all finite: {r:?}"
        )));
    }
    let drive = drive.map(|d| drive_of(mech, d)).transpose()?;
    let plans = mech.plans(py)?;
    let solved = py.detach(|| match (&mech.model, plans) {
        (Model::Planar(m), Plans::Planar(p)) => {
            planar::run(m, p, &rows, options, drive.as_ref(), (parallel, check))
        }
        (Model::Spatial(m), Plans::Spatial(p)) => spatial::run(m, p, &rows, options, drive.as_ref(), check),
        // A plan is made from its own mechanism.
        _ => unreachable!("a plan of the other dimension"),
    });
    into_dict(py, solved, n_inputs, mech.marker_names().len(), check)
}

/// `Mechanism.drag_raw`: `marker` pinned to `targets` (frames × 2, or × 3
/// in space) in turn, the inputs released, as `dofplan drag` moves it.
pub fn drag<'py>(
    py: Python<'py>,
    mech: &Mechanism,
    marker: &str,
    targets: PyReadonlyArray2<'py, f64>,
    policy: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let options = Options {
        start: StartPolicy::Drawn,
        ..options(policy, "keep")?
    };
    let rows = Rows::of(targets.as_array());
    let dimension = match &mech.model {
        Model::Planar(_) => 2,
        Model::Spatial(_) => 3,
    };
    if let Some(r) = rows
        .iter()
        .find(|r| r.len() != dimension || r.iter().any(|x| !x.is_finite()))
    {
        return Err(PyValueError::new_err(format!(
            "a target is {dimension} finite coordinates, not {r:?}"
        )));
    }
    let unknown = || {
        PyValueError::new_err(format!(
            "{} has no marker `{marker}` to drag; markers are: {}",
            mech.file(),
            mech.marker_names().join(", ")
        ))
    };
    let solved = match &mech.model {
        Model::Planar(m) => {
            let id = m.find_marker(marker).ok_or_else(unknown)?;
            py.detach(|| planar::drag(m, id, &rows, options))
        }
        Model::Spatial(m) => {
            let id = m.find_marker(marker).ok_or_else(unknown)?;
            py.detach(|| spatial::drag(m, id, &rows, options))
        }
    }
    .map_err(|e| crate::errors::plan_error(py, mech.file(), &e))?;
    into_dict(py, solved, dimension, mech.marker_names().len(), true)
}

/// The inputs' rates and accelerations in the interpreter's units: an angle
/// input's radians per unit of time become degrees (a slide's stay).
fn drive_of(mech: &Mechanism, (rates, accelerations): (Vec<f64>, Vec<f64>)) -> PyResult<Drive> {
    let kinds = mech.input_list();
    for (what, v) in [("rates", &rates), ("accelerations", &accelerations)] {
        if v.len() != kinds.len() {
            return Err(PyValueError::new_err(format!(
                "{} has {} input(s), but {} {what} are given",
                mech.file(),
                kinds.len(),
                v.len()
            )));
        }
        if v.iter().any(|x| !x.is_finite()) {
            return Err(PyValueError::new_err(format!(
                "the {what} are not all finite: {v:?}"
            )));
        }
    }
    let units = |v: &[f64]| -> Vec<f64> {
        (v.iter().zip(&kinds))
            .map(|(x, (_, kind))| if *kind == "angle" { x.to_degrees() } else { *x })
            .collect()
    };
    Ok(Drive {
        rates: units(&rates),
        accelerations: units(&accelerations),
    })
}

/// The driver's options from the policy names.
pub fn options(policy: &str, branch: &str) -> PyResult<Options> {
    let breaking = match policy {
        "limit" => BreakPolicy::Limit,
        "search" => BreakPolicy::Search,
        "stretch" => BreakPolicy::Stretch,
        other => {
            return Err(PyValueError::new_err(format!(
                "policy must be \"limit\", \"search\" or \"stretch\", not {other:?}"
            )))
        }
    };
    let branch = match branch {
        "keep" => BranchPolicy::Keep,
        "nearest" => BranchPolicy::Nearest,
        other => {
            return Err(PyValueError::new_err(format!(
                "branch must be \"keep\" or \"nearest\", not {other:?}"
            )))
        }
    };
    Ok(Options {
        breaking,
        branch,
        start: StartPolicy::Sweep,
        ..Options::default()
    })
}

/// The status code of a frame (an index into [`STATUS_NAMES`]).
pub fn code(status: &FrameStatus) -> i8 {
    match status {
        FrameStatus::Solved => 0,
        FrameStatus::Limited { .. } => 1,
        FrameStatus::Searched { .. } => 2,
        FrameStatus::Unreached { .. } => 3,
        FrameStatus::Stretched { .. } => 4,
    }
}

/// Reads a run's frames off its poses, every frame at once on every core:
/// `row` writes a frame's pose rows (`pose_width` numbers a body) and
/// marker positions (`dimension` numbers a marker) and returns its
/// residual, given its poses and inputs reached.
fn finish<P: Sync>(
    run: Run<P>,
    (bodies, pose_width): (usize, usize),
    (markers, dimension): (usize, usize),
    inputs: usize,
    row: impl Fn(&[P], &[f64], &mut [f64], &mut [f64]) -> f64 + Sync,
) -> Solved {
    let frames = run.status.len();
    let mut poses = vec![0.0; frames * bodies * pose_width];
    let mut at = vec![0.0; frames * markers * dimension];
    let mut residual = vec![0.0; frames];
    // Blocks of frames, so that a thread's work outweighs handing it out.
    const BLOCK: usize = 256;
    let (pw, mw) = (bodies * pose_width, markers * dimension);
    poses
        .par_chunks_mut(BLOCK * pw.max(1))
        .zip(at.par_chunks_mut(BLOCK * mw.max(1)))
        .zip(residual.par_chunks_mut(BLOCK))
        .enumerate()
        .for_each(|(k, ((p_out, m_out), r_out))| {
            for (j, r) in r_out.iter_mut().enumerate() {
                let f = k * BLOCK + j;
                let (p_row, m_row) = (&mut p_out[j * pw..(j + 1) * pw], &mut m_out[j * mw..(j + 1) * mw]);
                // An unreached frame has no pose of the run (the driver's
                // are the drawing's): NaN, as the CLI's JSON has null.
                if matches!(run.status[f], FrameStatus::Unreached { .. }) {
                    p_row.fill(f64::NAN);
                    m_row.fill(f64::NAN);
                    *r = f64::NAN;
                    continue;
                }
                *r = row(
                    &run.poses[f * bodies..(f + 1) * bodies],
                    &run.reached[f * inputs..(f + 1) * inputs],
                    p_row,
                    m_row,
                );
            }
        });
    Solved {
        frames,
        poses,
        pose_width,
        markers: at,
        dimension,
        reached: run.reached,
        status: run.status.iter().map(code).collect(),
        residual,
        rates: run.rates,
    }
}

/// The rate code of a frame whose rates failed.
fn rate_code(e: &RateError) -> i8 {
    match e {
        RateError::Break(_) => 1,
        RateError::Singular => 2,
        RateError::Cluster | RateError::Split => 3,
    }
}

impl Rates {
    /// A frame without rates: NaN for `markers` marker numbers and `bodies`
    /// body numbers, and its code.
    fn none(&mut self, markers: usize, bodies: usize, code: i8) {
        self.velocity.extend(std::iter::repeat_n(f64::NAN, markers));
        self.acceleration.extend(std::iter::repeat_n(f64::NAN, markers));
        self.omega.extend(std::iter::repeat_n(f64::NAN, bodies));
        self.alpha.extend(std::iter::repeat_n(f64::NAN, bodies));
        self.code.push(code);
    }
}

/// The arrays of a run, keyed as `dofplan.Result` takes them.
fn into_dict(
    py: Python<'_>,
    s: Solved,
    inputs: usize,
    markers: usize,
    check: bool,
) -> PyResult<Bound<'_, PyDict>> {
    let shape_error =
        |e: numpy::ndarray::ShapeError| PyValueError::new_err(format!("internal shape error: {e}"));
    let bodies = s.poses.len() / (s.frames * s.pose_width).max(1);
    let d = PyDict::new(py);
    let poses = Array3::from_shape_vec((s.frames, bodies, s.pose_width), s.poses).map_err(shape_error)?;
    d.set_item("poses", poses.into_pyarray(py))?;
    let at = Array3::from_shape_vec((s.frames, markers, s.dimension), s.markers).map_err(shape_error)?;
    d.set_item("markers", at.into_pyarray(py))?;
    let reached = Array2::from_shape_vec((s.frames, inputs), s.reached).map_err(shape_error)?;
    d.set_item("inputs", reached.into_pyarray(py))?;
    d.set_item("status", Array1::from_vec(s.status).into_pyarray(py))?;
    d.set_item("status_names", STATUS_NAMES.to_vec())?;
    if check {
        d.set_item("residual", Array1::from_vec(s.residual).into_pyarray(py))?;
    }
    if let Some(r) = s.rates {
        let v = Array3::from_shape_vec((s.frames, markers, s.dimension), r.velocity).map_err(shape_error)?;
        d.set_item("velocity", v.into_pyarray(py))?;
        let a =
            Array3::from_shape_vec((s.frames, markers, s.dimension), r.acceleration).map_err(shape_error)?;
        d.set_item("acceleration", a.into_pyarray(py))?;
        // Planar: frames × bodies; spatial: frames × bodies × 3.
        let w = if s.dimension == 2 { 1 } else { 3 };
        let omega = Array3::from_shape_vec((s.frames, bodies, w), r.omega).map_err(shape_error)?;
        let alpha = Array3::from_shape_vec((s.frames, bodies, w), r.alpha).map_err(shape_error)?;
        if w == 1 {
            d.set_item(
                "omega",
                omega.remove_axis(numpy::ndarray::Axis(2)).into_pyarray(py),
            )?;
            d.set_item(
                "alpha",
                alpha.remove_axis(numpy::ndarray::Axis(2)).into_pyarray(py),
            )?;
        } else {
            d.set_item("omega", omega.into_pyarray(py))?;
            d.set_item("alpha", alpha.into_pyarray(py))?;
        }
        d.set_item("rate_status", Array1::from_vec(r.code).into_pyarray(py))?;
        d.set_item("rate_status_names", RATE_NAMES.to_vec())?;
    }
    Ok(d)
}
