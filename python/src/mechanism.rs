//! The `Mechanism` class: a loaded file of either dimension, with the
//! reports the CLI prints (`check`, `plan`, `emit`) and its plan, made
//! once on first use.

use std::sync::OnceLock;

use dofplan::model::{Format, Model, Sweep};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::errors::{mechanism_error, plan_error};

/// A plan of either dimension.
pub(crate) enum Plans {
    Planar(dofplan::plan::Plan),
    Spatial(dofplan::plan::spatial::Plan),
}

/// A mechanism loaded from a file or a text (`dofplan.load`,
/// `dofplan.loads`): its bodies, markers, joints and inputs by name, the
/// reports of `dofplan check`, `plan` and `emit`, and its frames
/// (`simulate`).
#[pyclass(module = "dofplan", frozen)]
pub struct Mechanism {
    pub(crate) model: Model,
    /// The plan, or why there is none: made on first use, kept.
    plan: OnceLock<Result<Plans, String>>,
    /// The live pose `frame` moves, frame after frame (made on first use;
    /// `reset` returns it to the drawing).
    live: std::sync::Mutex<Option<Live>>,
}

/// A driver kept between calls of `frame`, of either dimension.
enum Live {
    Planar(dofplan_runtime::Driver<dofplan::interp::Interpreter>),
    Spatial(dofplan_runtime::Driver<dofplan::interp::spatial::Interpreter>),
}

impl Mechanism {
    /// The file's sweep with `steps` frames if given, or a ValueError.
    pub(crate) fn sweep_of(&self, steps: Option<usize>) -> PyResult<Sweep> {
        let Some(sweep) = self.sweep() else {
            return Err(pyo3::exceptions::PyValueError::new_err(format!(
                "{} has no [sweep] to analyze: add one to the file",
                self.file()
            )));
        };
        let mut sweep = sweep.clone();
        if let Some(n) = steps {
            if n == 0 || n as i64 > dofplan::model::MAX_STEPS {
                return Err(pyo3::exceptions::PyValueError::new_err(format!(
                    "steps must be from 1 to {}, not {n}",
                    dofplan::model::MAX_STEPS
                )));
            }
            sweep.steps = n;
        }
        Ok(sweep)
    }

    /// A CLI report written into a string, the lock released; its error
    /// (the CLI's message) a `DofplanError`.
    fn report(
        &self,
        py: Python<'_>,
        write: impl FnOnce(&mut Vec<u8>) -> dofplan::report::Outcome + Send,
    ) -> PyResult<String> {
        let mut out = Vec::new();
        match py.detach(|| write(&mut out)) {
            Ok(Ok(())) => Ok(String::from_utf8_lossy(&out).into_owned()),
            Ok(Err(message)) => Err(crate::errors::DofplanError::new_err(message)),
            Err(e) => Err(pyo3::exceptions::PyIOError::new_err(e.to_string())),
        }
    }

    /// The text the mechanism was loaded from, and its format.
    pub(crate) fn source_text(&self) -> (String, &'static str) {
        let source = match &self.model {
            Model::Planar(m) => &m.source,
            Model::Spatial(m) => &m.source,
        };
        let json =
            source.name.to_ascii_lowercase().ends_with(".json") || source.text.trim_start().starts_with('{');
        (source.text.to_string(), if json { "json" } else { "toml" })
    }

    pub(crate) fn new(model: Model) -> Mechanism {
        Mechanism {
            model,
            plan: OnceLock::new(),
            live: std::sync::Mutex::new(None),
        }
    }

    /// The file name errors use.
    pub(crate) fn file(&self) -> &str {
        match &self.model {
            Model::Planar(m) => &m.source.name,
            Model::Spatial(m) => &m.source.name,
        }
    }

    /// The plan, or a `PlanError` saying why there is none.
    pub(crate) fn plans(&self, py: Python<'_>) -> PyResult<&Plans> {
        let made = self.plan.get_or_init(|| match &self.model {
            Model::Planar(m) => dofplan::analysis::analyse(m)
                .plan
                .map(Plans::Planar)
                .map_err(|e| e.to_string()),
            Model::Spatial(m) => dofplan::analysis::spatial::analyse(m)
                .map(Plans::Spatial)
                .map_err(|e| e.to_string()),
        });
        made.as_ref()
            .map_err(|reason| plan_error(py, self.file(), reason))
    }

    /// Every marker as "body.marker", in the mechanism's order (the order of
    /// the `markers` arrays).
    pub(crate) fn marker_names(&self) -> Vec<String> {
        match &self.model {
            Model::Planar(m) => m.all_markers().map(|id| m.marker_name(id)).collect(),
            Model::Spatial(m) => m.all_markers().map(|id| m.marker_name(id)).collect(),
        }
    }

    fn sweep(&self) -> Option<&Sweep> {
        match &self.model {
            Model::Planar(m) => m.sweep.as_ref(),
            Model::Spatial(m) => m.sweep.as_ref(),
        }
    }

    /// The inputs' names and kinds ("angle" or "slide").
    pub(crate) fn input_list(&self) -> Vec<(String, &'static str)> {
        let inputs = match &self.model {
            Model::Planar(m) => &m.inputs,
            Model::Spatial(m) => &m.inputs,
        };
        inputs.iter().map(|i| (i.name.clone(), i.kind.name())).collect()
    }
}

#[pymethods]
impl Mechanism {
    /// The mechanism's `name`.
    #[getter]
    fn name(&self) -> &str {
        match &self.model {
            Model::Planar(m) => &m.name,
            Model::Spatial(m) => &m.name,
        }
    }

    /// 2 (planar) or 3 (spatial).
    #[getter]
    fn dimension(&self) -> u8 {
        match &self.model {
            Model::Planar(_) => 2,
            Model::Spatial(_) => 3,
        }
    }

    /// The file name given to `load` or `loads` (used in errors).
    #[getter(file)]
    fn file_name(&self) -> &str {
        self.file()
    }

    /// The bodies' names, in file order (the order of `poses`).
    #[getter]
    fn bodies(&self) -> Vec<String> {
        match &self.model {
            Model::Planar(m) => m.bodies.iter().map(|b| b.name.clone()).collect(),
            Model::Spatial(m) => m.bodies.iter().map(|b| b.name.clone()).collect(),
        }
    }

    /// Every marker as "body.marker" (the order of `markers` arrays).
    #[getter]
    fn markers(&self) -> Vec<String> {
        self.marker_names()
    }

    /// The joints' names, in file order.
    #[getter]
    fn joints(&self) -> Vec<String> {
        match &self.model {
            Model::Planar(m) => m.joints.iter().map(|j| j.name.clone()).collect(),
            Model::Spatial(m) => m.joints.iter().map(|j| j.name.clone()).collect(),
        }
    }

    /// Every joint as (name, kind, first marker, second marker), the
    /// markers as "body.marker", in file order.
    #[getter]
    fn joint_markers(&self) -> Vec<(String, &'static str, String, String)> {
        match &self.model {
            Model::Planar(m) => (m.joints.iter())
                .map(|j| {
                    let [a, b] = j.markers;
                    (j.name.clone(), j.kind.name(), m.marker_name(a), m.marker_name(b))
                })
                .collect(),
            Model::Spatial(m) => (m.joints.iter())
                .map(|j| {
                    let [a, b] = j.markers;
                    (j.name.clone(), j.kind.name(), m.marker_name(a), m.marker_name(b))
                })
                .collect(),
        }
    }

    /// The inputs' names, in file order (the columns of `simulate`'s inputs).
    #[getter]
    fn inputs(&self) -> Vec<String> {
        self.input_list().into_iter().map(|(n, _)| n).collect()
    }

    /// Each input's kind, "angle" (degrees) or "slide" (length units).
    #[getter]
    fn input_kinds(&self) -> Vec<&'static str> {
        self.input_list().into_iter().map(|(_, k)| k).collect()
    }

    /// The file's `[sweep]` as a dict (`inputs`: a list of
    /// `{input, from, to}`, `steps`, `trace`: marker names), or None.
    #[getter]
    fn sweep_dict<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(s) = self.sweep() else {
            return Ok(None);
        };
        let names = self.inputs();
        let inputs = PyList::empty(py);
        for w in &s.inputs {
            let d = PyDict::new(py);
            d.set_item("input", &names[w.input])?;
            d.set_item("from", w.from)?;
            d.set_item("to", w.to)?;
            inputs.append(d)?;
        }
        let trace: Vec<String> = match &self.model {
            Model::Planar(m) => s.trace.iter().map(|&id| m.marker_name(id)).collect(),
            Model::Spatial(m) => s.trace.iter().map(|&id| m.marker_name(id)).collect(),
        };
        let d = PyDict::new(py);
        d.set_item("inputs", inputs)?;
        d.set_item("steps", s.steps)?;
        d.set_item("trace", trace)?;
        Ok(Some(d))
    }

    /// The requested inputs of every frame of the file's `[sweep]` (frames ×
    /// inputs; the inputs not swept stay at 0), `steps` frames if given:
    /// the frames `dofplan simulate` runs. A ValueError when the file has
    /// no sweep.
    #[pyo3(signature = (steps = None))]
    fn sweep_inputs<'py>(
        &self,
        py: Python<'py>,
        steps: Option<usize>,
    ) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
        use numpy::IntoPyArray;
        let Some(sweep) = self.sweep() else {
            return Err(pyo3::exceptions::PyValueError::new_err(format!(
                "{} has no [sweep]: give the inputs of every frame",
                self.file()
            )));
        };
        let mut sweep = sweep.clone();
        if let Some(n) = steps {
            if n == 0 || n as i64 > dofplan::model::MAX_STEPS {
                return Err(pyo3::exceptions::PyValueError::new_err(format!(
                    "steps must be from 1 to {}, not {n}",
                    dofplan::model::MAX_STEPS
                )));
            }
            sweep.steps = n;
        }
        let n = self.input_list().len();
        let flat: Vec<f64> = dofplan::simulate::sweep_requests(&sweep, n).flatten().collect();
        let rows = numpy::ndarray::Array2::from_shape_vec((sweep.steps, n), flat)
            .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
        Ok(rows.into_pyarray(py))
    }

    /// `dofplan check --json` as text, and whether the check passed.
    fn check_json(&self, py: Python<'_>) -> PyResult<(String, bool)> {
        let mut out = Vec::new();
        let ok = py
            .detach(|| match &self.model {
                Model::Planar(m) => {
                    let check = dofplan::report::planar::check::Check::of(m, &mut |_| {});
                    check.write(m, &m.source.name, true, &mut out)
                }
                Model::Spatial(m) => dofplan::report::spatial::check(m, true, &mut out),
            })
            .map_err(|e| pyo3::exceptions::PyIOError::new_err(e.to_string()))?;
        Ok((String::from_utf8_lossy(&out).into_owned(), ok))
    }

    /// `dofplan analyze --json` on the file's sweep (`steps` frames if
    /// given), its first input at `rate`: the text.
    #[pyo3(signature = (rate = 1.0, steps = None))]
    fn analyze_json(&self, py: Python<'_>, rate: f64, steps: Option<usize>) -> PyResult<String> {
        let sweep = self.sweep_of(steps)?;
        let plans = self.plans(py)?;
        self.report(py, |out| match (&self.model, plans) {
            (Model::Planar(m), Plans::Planar(p)) => dofplan::report::planar::analyze::analyze(
                m,
                p,
                &sweep,
                rate,
                dofplan::report::Form::Json,
                None,
                &mut (),
                out,
            ),
            (Model::Spatial(m), Plans::Spatial(p)) => dofplan::report::spatial::analyze::analyze(
                m,
                p,
                &sweep,
                rate,
                dofplan::report::Form::Json,
                None,
                &mut (),
                out,
            ),
            _ => unreachable!("a plan is made from its own mechanism"),
        })
    }

    /// `dofplan analyze --forces --json` on the file's sweep (`steps`
    /// frames if given): statics, or kinetostatics with its first input at
    /// `rate` (and `acceleration`, which needs a rate). The text.
    #[pyo3(signature = (rate = None, steps = None, acceleration = None))]
    fn forces_json(
        &self,
        py: Python<'_>,
        rate: Option<f64>,
        steps: Option<usize>,
        acceleration: Option<f64>,
    ) -> PyResult<String> {
        let running = match (rate, acceleration) {
            (None, Some(_)) => {
                return Err(pyo3::exceptions::PyValueError::new_err(
                    "an acceleration needs a rate: give rate= too (rate=0 starts from rest)",
                ))
            }
            (None, None) => None,
            (Some(rate), a) => Some(dofplan::report::forces::Running {
                rate,
                acceleration: a.unwrap_or(0.0),
            }),
        };
        let sweep = self.sweep_of(steps)?;
        let plans = self.plans(py)?;
        self.report(py, |out| match (&self.model, plans) {
            (Model::Planar(m), Plans::Planar(p)) => dofplan::report::planar::forces::run(
                m,
                p,
                &sweep,
                running,
                dofplan::report::Form::Json,
                None,
                out,
            ),
            (Model::Spatial(m), Plans::Spatial(p)) => dofplan::report::spatial::forces::run(
                m,
                p,
                &sweep,
                running,
                dofplan::report::Form::Json,
                None,
                out,
            ),
            _ => unreachable!("a plan is made from its own mechanism"),
        })
    }

    /// `dofplan analyze --sensitivity --json` on the file's sweep: the text.
    #[pyo3(signature = (tolerance = None, monte_carlo = None, seed = 0, steps = None))]
    fn sensitivity_json(
        &self,
        py: Python<'_>,
        tolerance: Option<f64>,
        monte_carlo: Option<usize>,
        seed: u64,
        steps: Option<usize>,
    ) -> PyResult<String> {
        let sweep = self.sweep_of(steps)?;
        let study = dofplan::report::sensitivity::Study {
            tolerance,
            monte_carlo,
            seed,
        };
        self.report(py, |out| match &self.model {
            Model::Planar(m) => {
                dofplan::report::planar::sensitivity::run(m, &sweep, study, dofplan::report::Form::Json, out)
            }
            Model::Spatial(m) => {
                dofplan::report::spatial::sensitivity::run(m, &sweep, study, dofplan::report::Form::Json, out)
            }
        })
    }

    /// The mechanism's text as loaded, and its format ("toml" or "json"):
    /// what pickling a mechanism keeps.
    fn source(&self) -> (String, &'static str) {
        self.source_text()
    }

    /// A synthesis on this mechanism (see `crate::synth`): the CLI's JSON
    /// document and the best solution's file.
    fn synth_raw(&self, py: Python<'_>, goal: crate::synth::Goal) -> PyResult<(String, String)> {
        crate::synth::run(py, self, goal)
    }

    /// The plan explained step by step, as `dofplan plan` prints it.
    fn plan_text(&self, py: Python<'_>) -> PyResult<String> {
        Ok(match self.plans(py)? {
            Plans::Planar(p) => p.explain_all(),
            Plans::Spatial(p) => p.explain_all(),
        })
    }

    /// The generated Rust module, as `dofplan emit` writes it.
    fn emit(&self, py: Python<'_>) -> PyResult<String> {
        let plans = self.plans(py)?;
        Ok(py.detach(|| match plans {
            Plans::Planar(p) => dofplan::emit::emit(p),
            Plans::Spatial(p) => dofplan::emit::emit_spatial(p),
        }))
    }

    /// The drawing as SVG (what `simulate --svg` draws, at the drawn pose
    /// only).
    fn svg(&self) -> String {
        match &self.model {
            Model::Planar(m) => dofplan::render::render(m, &[], &[], &dofplan::render::SvgOptions::default()),
            Model::Spatial(m) => dofplan::render::spatial::render_spatial(m, &[]),
        }
    }

    /// `marker` ("body.marker") pinned to each row of `targets` in turn, the
    /// inputs released: see `crate::run::drag`.
    #[pyo3(signature = (marker, targets, policy = "stretch"))]
    fn drag_raw<'py>(
        &self,
        py: Python<'py>,
        marker: &str,
        targets: numpy::PyReadonlyArray2<'py, f64>,
        policy: &str,
    ) -> PyResult<Bound<'py, PyDict>> {
        crate::run::drag(py, self, marker, targets, policy)
    }

    /// One frame from the live pose (the last `frame`'s, or the drawing):
    /// every marker's world position (markers × 2 or 3) and the frame's
    /// status name. Limit and keep-branch, as a slider in an editor moves a
    /// mechanism: a frame past a limit holds the pose.
    fn frame<'py>(
        &self,
        py: Python<'py>,
        inputs: Vec<f64>,
    ) -> PyResult<(Bound<'py, numpy::PyArray2<f64>>, &'static str)> {
        use numpy::IntoPyArray;
        let n = self.input_list().len();
        if inputs.len() != n || inputs.iter().any(|x| !x.is_finite()) {
            return Err(pyo3::exceptions::PyValueError::new_err(format!(
                "{} takes {n} finite input value(s), not {inputs:?}",
                self.file()
            )));
        }
        let plans = self.plans(py)?;
        let mut live = self.live.lock().map_err(|_| {
            pyo3::exceptions::PyRuntimeError::new_err("the live pose was poisoned by a failed frame")
        })?;
        let live = live.get_or_insert_with(|| match plans {
            Plans::Planar(p) => Live::Planar(dofplan_runtime::Driver::new(
                dofplan::interp::Interpreter::new(p.clone()),
                dofplan_runtime::Options::default(),
            )),
            Plans::Spatial(p) => Live::Spatial(dofplan_runtime::Driver::new(
                dofplan::interp::spatial::Interpreter::new(p.clone()),
                dofplan_runtime::Options::default(),
            )),
        });
        let (status, at, d) = match (live, &self.model) {
            (Live::Planar(driver), Model::Planar(m)) => {
                let status = driver.frame(&inputs);
                let poses = driver.poses();
                let at: Vec<f64> = m
                    .all_markers()
                    .flat_map(|id| dofplan::simulate::planar::marker_at(m, poses, id))
                    .collect();
                (status, at, 2)
            }
            (Live::Spatial(driver), Model::Spatial(m)) => {
                let status = driver.frame(&inputs);
                let at: Vec<f64> = dofplan::simulate::spatial::marker_positions(m, driver.poses())
                    .into_iter()
                    .flatten()
                    .collect();
                (status, at, 3)
            }
            _ => unreachable!("a driver is made from its own mechanism's plan"),
        };
        let rows = at.len() / d;
        let array = numpy::ndarray::Array2::from_shape_vec((rows, d), at)
            .map_err(|e| pyo3::exceptions::PyValueError::new_err(e.to_string()))?;
        Ok((
            array.into_pyarray(py),
            crate::run::STATUS_NAMES[crate::run::code(&status) as usize],
        ))
    }

    /// Returns the live pose of `frame` to the drawing.
    fn reset(&self) {
        if let Ok(mut live) = self.live.lock() {
            *live = None;
        }
    }

    /// A measurement hook for the speed table (`tools/bench/python_speed.py`):
    /// the seconds the Rust batch path (`solve_batch_parallel` on the
    /// interpreter, every core) takes over `inputs`, nothing read off and no
    /// array made, so that a run from Python can be set beside it. Planar
    /// closed-form plans only (the others run in order: a ValueError).
    fn _batch_seconds(&self, py: Python<'_>, inputs: numpy::PyReadonlyArray2<'_, f64>) -> PyResult<f64> {
        use dofplan_runtime::Batch;
        let (Model::Planar(m), Plans::Planar(plan)) = (&self.model, self.plans(py)?) else {
            return Err(pyo3::exceptions::PyValueError::new_err("a planar mechanism only"));
        };
        let interp = dofplan::interp::Interpreter::new(plan.clone());
        if !interp.independent() {
            return Err(pyo3::exceptions::PyValueError::new_err("a closed-form plan only"));
        }
        let flat: Vec<f64> = inputs.as_array().iter().copied().collect();
        let frames = inputs.as_array().nrows();
        Ok(py.detach(|| {
            let mut out = vec![dofplan_runtime::planar::Pose::IDENTITY; frames * m.bodies.len()];
            let mut status = vec![dofplan_runtime::FrameStatus::Solved; frames];
            let t = std::time::Instant::now();
            dofplan_runtime::batch::solve_batch_parallel(&interp, &flat, &mut out, &mut status);
            let dt = t.elapsed().as_secs_f64();
            std::hint::black_box((&out, &status));
            dt
        }))
    }

    /// The frames of `inputs` drawn as `simulate --svg` draws them: the
    /// sweep's traced markers (the last marker when none), faint poses, and
    /// how each frame met its inputs.
    #[pyo3(signature = (inputs, policy = "limit", branch = "keep"))]
    fn svg_frames(
        &self,
        py: Python<'_>,
        inputs: numpy::PyReadonlyArray2<'_, f64>,
        policy: &str,
        branch: &str,
    ) -> PyResult<String> {
        let options = crate::run::options(policy, branch)?;
        let rows: Vec<Vec<f64>> = inputs.as_array().outer_iter().map(|r| r.to_vec()).collect();
        if rows.iter().any(|r| r.len() != self.input_list().len()) {
            return Err(pyo3::exceptions::PyValueError::new_err("one column per input"));
        }
        let plans = self.plans(py)?;
        Ok(py.detach(|| match (&self.model, plans) {
            (Model::Planar(m), Plans::Planar(p)) => {
                let mut driver =
                    dofplan_runtime::Driver::new(dofplan::interp::Interpreter::new(p.clone()), options);
                let frames: Vec<_> = dofplan::simulate::frames(&mut driver, &rows).collect();
                let trace = match &m.sweep {
                    Some(s) if !s.trace.is_empty() => s.trace.clone(),
                    _ => m.all_markers().last().into_iter().collect(),
                };
                dofplan::render::render(m, &frames, &trace, &dofplan::render::SvgOptions::default())
            }
            (Model::Spatial(m), Plans::Spatial(p)) => {
                let mut driver = dofplan_runtime::Driver::new(
                    dofplan::interp::spatial::Interpreter::new(p.clone()),
                    options,
                );
                let frames: Vec<_> = (rows.iter())
                    .map(|r| {
                        let status = driver.frame(r);
                        dofplan::render::spatial::SpatialFrame {
                            requested: r.clone(),
                            status,
                            poses: driver.poses().to_vec(),
                        }
                    })
                    .collect();
                dofplan::render::spatial::render_spatial(m, &frames)
            }
            _ => unreachable!("a plan is made from its own mechanism"),
        }))
    }

    /// Runs `inputs` (frames × inputs, C order) through the plan: see
    /// `crate::run::simulate`.
    /// With `rates` (and `accelerations`), one per input, in radians (or
    /// length units) per unit of time, every solved frame's velocities and
    /// accelerations too.
    /// `parallel`: a long run of a closed-form planar plan under the
    /// default policies on every core (the same frames, to the bit).
    /// `check`: each frame's residual too.
    #[pyo3(signature = (inputs, policy = "limit", branch = "keep", rates = None, accelerations = None, parallel = true, check = false))]
    // Python's keyword arguments, each a plain value.
    #[allow(clippy::too_many_arguments)]
    fn simulate_raw<'py>(
        &self,
        py: Python<'py>,
        inputs: numpy::PyReadonlyArray2<'py, f64>,
        policy: &str,
        branch: &str,
        rates: Option<Vec<f64>>,
        accelerations: Option<Vec<f64>>,
        parallel: bool,
        check: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let drive = rates.map(|r| {
            let a = accelerations.unwrap_or_else(|| vec![0.0; r.len()]);
            (r, a)
        });
        crate::run::simulate(py, self, inputs, policy, branch, drive, (parallel, check))
    }

    fn __repr__(&self) -> String {
        let (bodies, joints, inputs) = match &self.model {
            Model::Planar(m) => (m.bodies.len(), m.joints.len(), m.inputs.len()),
            Model::Spatial(m) => (m.bodies.len(), m.joints.len(), m.inputs.len()),
        };
        format!(
            "<dofplan.Mechanism {:?} ({}D): {bodies} bodies, {joints} joints, {inputs} inputs>",
            self.name(),
            self.dimension()
        )
    }
}

/// Loads a mechanism file (TOML, or JSON by its `.json` extension) of
/// either dimension. Raises `MechanismError` with the CLI's diagnostics.
#[pyfunction]
pub fn load(py: Python<'_>, path: std::path::PathBuf) -> PyResult<Mechanism> {
    py.detach(|| dofplan::load_any(&path))
        .map(Mechanism::new)
        .map_err(|e| mechanism_error(py, &e))
}

/// Loads a mechanism from text, `format` "toml" or "json"; `name` is the
/// file name errors show.
#[pyfunction]
#[pyo3(signature = (text, format = "toml", name = "<string>"))]
pub fn loads(py: Python<'_>, text: &str, format: &str, name: &str) -> PyResult<Mechanism> {
    let format = format_of(format)?;
    py.detach(|| dofplan::load_any_str(name, text, format))
        .map(Mechanism::new)
        .map_err(|e| mechanism_error(py, &e))
}

/// A Pyslvs (PMKS) expression, `M[J[R, P[x, y], L[ground, L1]], …]`,
/// optionally followed by its input pairs, as `dofplan import` reads it;
/// `inputs` (pairs of point indices) replace the pairs written in the
/// text. Returns the mechanism file's text (with a header saying how the
/// names map) and the notes (no inputs, no plan). Errors point into the
/// expression.
#[pyfunction]
#[pyo3(signature = (text, inputs = None, name = "imported", file = "<pmks>"))]
pub fn pmks_to_toml(
    py: Python<'_>,
    text: &str,
    inputs: Option<Vec<(usize, usize)>>,
    name: &str,
    file: &str,
) -> PyResult<(String, Vec<String>)> {
    py.detach(|| dofplan::import::import_pmks(file, text, inputs.as_deref(), name))
        .map(|i| (i.toml, i.notes))
        .map_err(|e| mechanism_error(py, &e))
}

/// `dofplan assemble` on a text: the drawing moved the least that closes
/// every joint (the inputs held at their drawn values where they can be).
/// Returns the file's text with the assembled coordinates (comments and
/// key order kept; the text as given when nothing moved), the table of
/// moves `dofplan assemble` prints, and whether nothing moved.
#[pyfunction]
#[pyo3(signature = (text, format = "toml", name = "<string>"))]
pub fn assemble_text(
    py: Python<'_>,
    text: &str,
    format: &str,
    name: &str,
) -> PyResult<(String, String, bool)> {
    let format = format_of(format)?;
    let done = py.detach(|| match dofplan::model::load_any_str_drawn(name, text, format)? {
        dofplan::model::DrawnModel::Planar(_) => dofplan::assemble::planar::assemble_str(name, text, format)
            .map(|d| (d.report(), d.unchanged(), d.text)),
        dofplan::model::DrawnModel::Spatial(_) => {
            dofplan::assemble::spatial::assemble_str(name, text, format)
                .map(|d| (d.report(), d.unchanged(), d.text))
        }
    });
    let (report, unchanged, text) = done.map_err(|e| mechanism_error(py, &e))?;
    Ok((text, report, unchanged))
}

/// A format's name as Python gives it.
fn format_of(name: &str) -> PyResult<Format> {
    match name {
        "toml" => Ok(Format::Toml),
        "json" => Ok(Format::Json),
        other => Err(pyo3::exceptions::PyValueError::new_err(format!(
            "format must be \"toml\" or \"json\", not {other:?}"
        ))),
    }
}
