//! `dofplan._dofplan`: the native half of the `dofplan` Python package.
//!
//! A thin layer over the `dofplan` crate: files are loaded, checked,
//! planned and simulated by the same functions the CLI calls, so a
//! mechanism gives the same answers (and the same error texts) from Python
//! as from `dofplan check` or `dofplan simulate`. The Python half
//! (`dofplan/__init__.py`) shapes arguments and wraps results; nothing
//! geometric is done there.
//!
//! - [`errors`]: the exceptions, carrying the CLI's diagnostics.
//! - [`mechanism`]: the `Mechanism` class (load, check, plan, emit).
//! - [`design`]: design parameters, candidates drawn at new values, and
//!   the tolerance study's steps (what `dofplan.study` and `dofplan.ray`
//!   spread over workers).
//! - [`synth`]: path, function and motion generation.
//! - [`run`]: inputs run through the plan into NumPy arrays (one file per
//!   dimension).

use pyo3::prelude::*;

mod design;
mod errors;
mod mechanism;
mod run;
mod synth;

/// The module `dofplan._dofplan`.
#[pymodule]
fn _dofplan(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("DofplanError", py.get_type::<errors::DofplanError>())?;
    m.add("MechanismError", py.get_type::<errors::MechanismError>())?;
    m.add("PlanError", py.get_type::<errors::PlanError>())?;
    m.add_class::<mechanism::Mechanism>()?;
    m.add_function(wrap_pyfunction!(mechanism::load, m)?)?;
    m.add_function(wrap_pyfunction!(mechanism::loads, m)?)?;
    m.add_function(wrap_pyfunction!(mechanism::pmks_to_toml, m)?)?;
    m.add_function(wrap_pyfunction!(mechanism::assemble_text, m)?)?;
    m.add_function(wrap_pyfunction!(design::parameters, m)?)?;
    m.add_function(wrap_pyfunction!(design::with_parameters, m)?)?;
    m.add_function(wrap_pyfunction!(design::tolerance_draws, m)?)?;
    m.add_function(wrap_pyfunction!(design::deviations, m)?)?;
    m.add_function(wrap_pyfunction!(design::spread, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
