//! Errors as Python exceptions. The message is the text the CLI prints
//! (`file:line:col`, the lines of the file, the help), and the same
//! diagnostics are there as data, one dict each, for a front end that
//! marks the positions itself.

use dofplan::model::{Diagnostic, Location, ModelError};
use pyo3::exceptions::PyException;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

pyo3::create_exception!(
    dofplan,
    DofplanError,
    PyException,
    "Every error dofplan raises (a subclass says which kind)."
);
pyo3::create_exception!(
    dofplan,
    MechanismError,
    DofplanError,
    "A mechanism file or text that does not load: syntax, unknown names, \
     joints that do not hold in the drawing... `diagnostics` lists each \
     error with its position."
);
pyo3::create_exception!(
    dofplan,
    PlanError,
    DofplanError,
    "A mechanism that loads but has no plan (the analysis says why)."
);

/// A load error: `MechanismError` with the rendered text as its message and
/// `diagnostics` as a list of dicts.
pub fn mechanism_error(py: Python<'_>, e: &ModelError) -> PyErr {
    let err = MechanismError::new_err(e.render(false));
    let list = PyList::empty(py);
    for d in &e.diagnostics {
        // A dict that cannot be built is a Python failure (memory): the
        // error stays the MechanismError with its message.
        if let Ok(dict) = diagnostic(py, d) {
            let _ = list.append(dict);
        }
    }
    let _ = err.value(py).setattr("diagnostics", list);
    err
}

/// A plan error: `PlanError` whose message is `place: error: reason`, as
/// the CLI says it, with one diagnostic without a position.
pub fn plan_error(py: Python<'_>, place: &str, reason: &str) -> PyErr {
    let err = PlanError::new_err(format!("{place}: error: {reason}"));
    let entry = PyDict::new(py);
    let _ = entry.set_item("file", place);
    let _ = entry.set_item("line", py.None());
    let _ = entry.set_item("column", py.None());
    let _ = entry.set_item("path", py.None());
    let _ = entry.set_item("message", reason);
    let _ = entry.set_item("help", py.None());
    let _ = entry.set_item("notes", PyList::empty(py));
    let _ = err
        .value(py)
        .setattr("diagnostics", PyList::new(py, [entry]).ok());
    err
}

/// One diagnostic as a dict: `file`, `line`, `column` (1-based, or None),
/// `path` (a JSON file's path in the document, or None), `message`,
/// `help`, `notes` (each with `line`, `column`, `path`, `message`) and
/// `text` (the rendered form).
fn diagnostic<'py>(py: Python<'py>, d: &Diagnostic) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    dict.set_item("file", &d.file.name)?;
    put_location(&dict, d, &d.location)?;
    dict.set_item("message", &d.message)?;
    dict.set_item("help", d.help.as_deref())?;
    let notes = PyList::empty(py);
    for n in &d.notes {
        let note = PyDict::new(py);
        put_location(&note, d, &n.location)?;
        note.set_item("message", &n.message)?;
        notes.append(note)?;
    }
    dict.set_item("notes", notes)?;
    dict.set_item("text", d.render(false))?;
    Ok(dict)
}

/// `line`, `column` and `path` of a location into `dict`.
fn put_location(dict: &Bound<'_, PyDict>, d: &Diagnostic, at: &Location) -> PyResult<()> {
    let (line, column, path) = match at {
        Location::Span(span) => {
            let (l, c) = d.file.line_col(span.start);
            (Some(l), Some(c), None)
        }
        Location::LineCol(l, c) => (Some(*l), Some(*c), None),
        Location::Path(p) => (None, None, Some(p.as_str())),
        Location::File => (None, None, None),
    };
    dict.set_item("line", line)?;
    dict.set_item("column", column)?;
    dict.set_item("path", path)?;
    Ok(())
}
