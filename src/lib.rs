//! Shared helpers of the end-to-end tests in `tests/` (this root package
//! exists to own them; see the workspace `Cargo.toml`).

use std::path::PathBuf;

use dofplan::analysis::analyse;
use dofplan::load_file;
use dofplan::model::Mechanism;
use dofplan::plan::Plan;

pub mod fuzzing;
pub mod user_crate;

/// The generators and plane arithmetic live in `dofplan-gen`, a crate with
/// no dependencies, so `cargo run -p dofplan-gen` builds in seconds.
pub use dofplan_gen::{huge, stress, vec2};

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

/// Whether dofplan-generated compiles a design module for the bundled
/// mechanism `name` (its build.rs: every closed-form one but the stress
/// chains).
pub fn designed(name: &str) -> bool {
    !name.starts_with("stress_") && plan(&load(name)).clusters() == 0
}

/// The source dofplan-generated compiles for the bundled mechanism `name`:
/// its module, and its design module when it has one.
pub fn generated_source(name: &str) -> String {
    let m = load(name);
    let p = plan(&m);
    let mut source = dofplan::emit::emit(&p);
    if designed(name) {
        let design = dofplan::synth::planar::Design::new(&m).unwrap_or_else(|e| panic!("{name}: {e}"));
        source.push_str(
            &dofplan::emit::emit_design(&p, &design.table()).unwrap_or_else(|e| panic!("{name}: {e}")),
        );
    }
    source
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

/// Names (file stems) of every bundled spatial mechanism
/// (`mechanisms/spatial/`), sorted.
pub fn bundled_spatial() -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(mechanisms_dir().join("spatial"))
        .expect("mechanisms/spatial/ exists")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "toml" || e == "json"))
        .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// Names (file stems) of the spatial test fixtures (`tests/fixtures/spatial/`:
/// mechanisms that exercise generated code no bundled one needs), sorted.
pub fn spatial_fixtures() -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(spatial_fixtures_dir())
        .expect("tests/fixtures/spatial/ exists")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "toml" || e == "json"))
        .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

fn spatial_fixtures_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/spatial")
}

/// Loads a bundled spatial mechanism, or else a spatial fixture, by name,
/// panicking with the diagnostics.
pub fn load_spatial(name: &str) -> dofplan::model::spatial::Mechanism {
    let bundled = mechanisms_dir().join(format!("spatial/{name}.toml"));
    let path = if bundled.exists() {
        bundled
    } else {
        spatial_fixtures_dir().join(format!("{name}.toml"))
    };
    match dofplan::load_any(&path) {
        Ok(dofplan::model::Model::Spatial(m)) => m,
        Ok(dofplan::model::Model::Planar(_)) => panic!("{} is planar", path.display()),
        Err(e) => panic!("{e}"),
    }
}

/// Plans a spatial mechanism, panicking with the reason if it has no plan.
pub fn plan_spatial(m: &dofplan::model::spatial::Mechanism) -> dofplan::plan::spatial::Plan {
    dofplan::analysis::spatial::analyse(m).unwrap_or_else(|e| panic!("{}: {e}", m.name))
}

/// Every combination of breaking and branch policy, for tests that must
/// hold under each.
pub fn all_options() -> Vec<dofplan_runtime::Options> {
    use dofplan_runtime::{BranchPolicy, BreakPolicy, Options};
    let mut out = Vec::new();
    for breaking in [BreakPolicy::Limit, BreakPolicy::Search, BreakPolicy::Stretch] {
        for branch in [BranchPolicy::Keep, BranchPolicy::Nearest] {
            out.push(Options {
                breaking,
                branch,
                ..Options::default()
            });
        }
    }
    out
}

/// The largest difference of two planar poses' coordinates and rotation
/// entries: how far apart two back ends' frames are.
pub fn pose_gap(a: &dofplan_runtime::planar::Pose, b: &dofplan_runtime::planar::Pose) -> f64 {
    (a.at[0] - b.at[0])
        .abs()
        .max((a.at[1] - b.at[1]).abs())
        .max((a.rot.c - b.rot.c).abs())
        .max((a.rot.s - b.rot.s).abs())
}
