//! Shared helpers of the end-to-end tests in `tests/` (this root package
//! exists to own them; see the workspace `Cargo.toml`).

use std::path::PathBuf;

use dofplan::analysis::analyse;
use dofplan::model::{load_file, Mechanism};
use dofplan::plan::Plan;

/// The bundled mechanisms folder.
pub fn mechanisms_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("mechanisms")
}

/// Names (file stems) of every bundled mechanism, sorted.
pub fn bundled() -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(mechanisms_dir())
        .expect("mechanisms/ exists")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "toml" || e == "json"))
        .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// Loads a bundled mechanism by name, panicking with the diagnostics.
pub fn load(name: &str) -> Mechanism {
    let path = mechanisms_dir().join(format!("{name}.toml"));
    load_file(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// Plans a mechanism, panicking with the reason if it has no plan.
pub fn plan(m: &Mechanism) -> Plan {
    analyse(m).plan.unwrap_or_else(|e| panic!("{}: {e}", m.name))
}
