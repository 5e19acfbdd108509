//! A mechanism's design parameters from Python: their names and drawn
//! values, a candidate drawn at new values (a mechanism like any other),
//! and the Monte-Carlo tolerance study in the three steps a distributed
//! study spreads over workers (`dofplan.study`, `dofplan.ray`): the
//! candidates a seed gives, each candidate's largest deviation, and the
//! summary. Each step is the library's own (`dofplan::synth::tolerance`),
//! so a study split into chunks gives `analyze --tolerance --monte-carlo`'s
//! numbers to the bit.

use dofplan::model::{Format, MarkerId, Model};
use dofplan::synth::tolerance::{draws, worst, Paths, Spread};
use dofplan::synth::{planar, spatial, SynthError};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use rayon::prelude::*;

use crate::errors::DofplanError;
use crate::mechanism::Mechanism;

/// A design of either dimension.
enum Design {
    Planar(planar::Design),
    Spatial(spatial::Design),
}

impl Design {
    /// The design of `m`, or a `DofplanError` with the CLI's words (a
    /// mechanism without a plan has no design).
    fn of(py: Python<'_>, m: &Mechanism) -> PyResult<Design> {
        let made = py.detach(|| match &m.model {
            Model::Planar(p) => planar::Design::new(p).map(Design::Planar),
            Model::Spatial(s) => spatial::Design::new(s).map(Design::Spatial),
        });
        made.map_err(|e| failed(m, e))
    }

    fn names(&self) -> &[String] {
        match self {
            Design::Planar(d) => d.names(),
            Design::Spatial(d) => d.names(),
        }
    }

    fn drawn(&self) -> Vec<f64> {
        match self {
            Design::Planar(d) => d.drawn(),
            Design::Spatial(d) => d.drawn(),
        }
    }

    /// The markers the drawing at `values` moves: (body, marker, position).
    fn moved(&self, values: &[f64]) -> Result<Vec<(String, String, Vec<f64>)>, SynthError> {
        fn changes<const N: usize>(
            ids: impl Iterator<Item = MarkerId>,
            at: impl Fn(MarkerId) -> ([f64; N], [f64; N]),
            name: impl Fn(MarkerId) -> (String, String),
        ) -> Vec<(String, String, Vec<f64>)> {
            ids.filter(|&id| at(id).0 != at(id).1)
                .map(|id| {
                    let (body, marker) = name(id);
                    (body, marker, at(id).1.to_vec())
                })
                .collect()
        }
        Ok(match self {
            Design::Planar(d) => {
                let (m, moved) = (d.mechanism(), d.drawing(values)?);
                let at = |id: MarkerId| (m.marker(id).at, moved.marker(id).at);
                let name = |id: MarkerId| (m.bodies[id.body].name.clone(), m.marker(id).name.clone());
                changes(m.all_markers(), at, name)
            }
            Design::Spatial(d) => {
                let (m, moved) = (d.mechanism(), d.drawing(values)?);
                let at = |id: MarkerId| (m.marker(id).at, moved.marker(id).at);
                let name = |id: MarkerId| (m.bodies[id.body].name.clone(), m.marker(id).name.clone());
                changes(m.all_markers(), at, name)
            }
        })
    }
}

/// The error of a design step, as the CLI words it.
fn failed(m: &Mechanism, e: SynthError) -> PyErr {
    DofplanError::new_err(format!("{}: error: {e}", m.file()))
}

/// A parameter row of the right length, or a ValueError naming them.
fn checked<'a>(design: &Design, values: &'a [f64]) -> PyResult<&'a [f64]> {
    let names = design.names();
    if values.len() != names.len() {
        return Err(PyValueError::new_err(format!(
            "the mechanism has {} design parameters ({}), not {}",
            names.len(),
            names.join(", "),
            values.len()
        )));
    }
    if let Some(k) = values.iter().position(|v| !v.is_finite()) {
        return Err(PyValueError::new_err(format!(
            "parameter {} is {}: give a finite number",
            names[k], values[k]
        )));
    }
    Ok(values)
}

/// The design parameters' names (`NAME.x`, `NAME.y`[, `NAME.z`] per point
/// that moves as one) and their drawn values.
#[pyfunction]
pub fn parameters(py: Python<'_>, m: &Mechanism) -> PyResult<(Vec<String>, Vec<f64>)> {
    let d = Design::of(py, m)?;
    Ok((d.names().to_vec(), d.drawn()))
}

/// The candidate drawn at `values` (every parameter, in `parameters`'
/// order): the mechanism's own text with the moved markers rewritten
/// (exactly: the shortest numbers that read back to the same values;
/// comments and key order kept), loaded as any file is.
#[pyfunction]
pub fn with_parameters(py: Python<'_>, m: &Mechanism, values: Vec<f64>) -> PyResult<Mechanism> {
    let d = Design::of(py, m)?;
    let values = checked(&d, &values)?;
    let moved = d.moved(values).map_err(|e| failed(m, e))?;
    let (text, format) = m.source_text();
    let format = if format == "json" {
        Format::Json
    } else {
        Format::Toml
    };
    // A size of 0 writes every number to its last bit: the candidate is
    // the values given, not a rounding of them.
    let written = dofplan::assemble::rewrite_positions(&text, format, 0.0, &moved)
        .map_err(|e| DofplanError::new_err(format!("{}: error: {e}", m.file())))?;
    let name = m.file().to_string();
    py.detach(|| dofplan::load_any_str(&name, &written, format))
        .map(Mechanism::new)
        .map_err(|e| crate::errors::mechanism_error(py, &e))
}

/// The `n` candidates `analyze --tolerance T --monte-carlo N --seed S` runs:
/// every parameter uniform within `±t` of the drawing, one row each.
#[pyfunction]
pub fn tolerance_draws<'py>(
    py: Python<'py>,
    m: &Mechanism,
    n: usize,
    t: f64,
    seed: u64,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    if !(t.is_finite() && t > 0.0) {
        return Err(PyValueError::new_err(format!(
            "tolerance must be a positive length, not {t}"
        )));
    }
    let d = Design::of(py, m)?;
    let rows = draws(&d.drawn(), (n, t, seed));
    let p = d.names().len();
    let flat: Vec<f64> = rows.into_iter().flatten().collect();
    Ok(table(flat, n, p).into_pyarray(py))
}

/// Each candidate's (row's) largest deviation from the drawing's path per
/// traced marker over the file's sweep (`steps` frames if given), NaN for
/// a candidate that cannot be planned or breaks where the drawing does
/// not; with the traced markers' names. Candidates run on every core, or
/// one after another when `parallel` is false (a worker of a distributed
/// study, given one core of its own).
#[pyfunction]
#[pyo3(signature = (m, rows, steps = None, parallel = true))]
pub fn deviations<'py>(
    py: Python<'py>,
    m: &Mechanism,
    rows: PyReadonlyArray2<'py, f64>,
    steps: Option<usize>,
    parallel: bool,
) -> PyResult<(Vec<String>, Bound<'py, PyArray2<f64>>)> {
    let sweep = m.sweep_of(steps)?;
    if sweep.trace.is_empty() {
        return Err(DofplanError::new_err(dofplan::report::sensitivity::untraced(
            m.file(),
        )));
    }
    let d = Design::of(py, m)?;
    let rows = rows.as_array();
    let p = d.names().len();
    if rows.ncols() != p {
        return Err(PyValueError::new_err(format!(
            "candidates are rows of the {p} design parameters ({}), not of {}",
            d.names().join(", "),
            rows.ncols()
        )));
    }
    let candidates: Vec<Vec<f64>> = rows.rows().into_iter().map(|r| r.to_vec()).collect();
    let markers = sweep.trace.len();
    let (names, found) = py
        .detach(|| match &d {
            Design::Planar(d) => {
                let mech = d.mechanism();
                let requested: Vec<Vec<f64>> =
                    dofplan::simulate::sweep_requests(&sweep, mech.inputs.len()).collect();
                let names = sweep.trace.iter().map(|id| mech.marker_name(*id)).collect();
                let nominal = planar::nominal(d, &requested, &sweep.trace)?;
                let each = |c: &Vec<f64>| measured(planar::paths(d, &requested, &sweep.trace, c), &nominal);
                Ok((names, each_candidate(&candidates, parallel, each)))
            }
            Design::Spatial(d) => {
                let mech = d.mechanism();
                let requested: Vec<Vec<f64>> =
                    dofplan::simulate::sweep_requests(&sweep, mech.inputs.len()).collect();
                let names = sweep.trace.iter().map(|id| mech.marker_name(*id)).collect();
                let nominal = spatial::nominal(d, &requested, &sweep.trace)?;
                let each = |c: &Vec<f64>| measured(spatial::paths(d, &requested, &sweep.trace, c), &nominal);
                Ok((names, each_candidate(&candidates, parallel, each)))
            }
        })
        .map_err(|e| failed(m, e))?;
    let flat: Vec<f64> = (found.into_iter())
        .flat_map(|w| w.unwrap_or_else(|| vec![f64::NAN; markers]))
        .collect();
    Ok((names, table(flat, rows.nrows(), markers).into_pyarray(py)))
}

/// Rows of `columns` numbers, as one array.
fn table(flat: Vec<f64>, rows: usize, columns: usize) -> Array2<f64> {
    Array2::from_shape_vec((rows, columns), flat).expect("every row has every column")
}

/// `each` of the candidates in order, on every core if `parallel`.
fn each_candidate<T: Send>(
    candidates: &[Vec<f64>],
    parallel: bool,
    each: impl Fn(&Vec<f64>) -> T + Sync + Send,
) -> Vec<T> {
    if parallel {
        candidates.par_iter().map(each).collect()
    } else {
        candidates.iter().map(each).collect()
    }
}

/// A candidate's largest deviation per marker, `None` if it failed.
fn measured<const N: usize>(paths: Option<Paths<N>>, nominal: &Paths<N>) -> Option<Vec<f64>> {
    paths.and_then(|p| worst(&p, nominal))
}

/// The summary of `deviations`' rows in order (NaN rows: failed
/// candidates): candidates, failed, and per marker the largest and the
/// mean deviation, as `analyze --tolerance --monte-carlo` reports them.
#[pyfunction]
#[allow(clippy::type_complexity)]
pub fn spread<'py>(
    py: Python<'py>,
    rows: PyReadonlyArray2<'py, f64>,
) -> (usize, usize, Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>) {
    let rows = rows.as_array();
    let candidates = (rows.rows().into_iter()).map(|r| (!r.iter().any(|v| v.is_nan())).then(|| r.to_vec()));
    let s = Spread::of(rows.ncols(), candidates);
    (
        s.candidates,
        s.failed,
        s.largest.into_pyarray(py),
        s.mean.into_pyarray(py),
    )
}
