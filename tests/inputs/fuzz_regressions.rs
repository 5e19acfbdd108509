//! Every input the fuzz targets (`fuzz/`) found a bug with, replayed
//! through the same path as its target (`src/fuzzing.rs`): load, analyse,
//! run. Each must end in a clear error or in frames whose joints hold, never
//! a panic or a hang.
//!
//! The inputs are files under `tests/fuzz_regressions/<target>/`, where
//! `<target>` names the fuzz target that found the bug.

use std::path::PathBuf;

use dofplan::analysis::PlanError;
use dofplan::model::Format;
use dofplan_tests::fuzzing::{guess_format, interpret, load, plan};

/// `(target, file name, bytes)` of every regression input.
fn regressions() -> Vec<(String, String, Vec<u8>)> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz_regressions");
    let mut found = Vec::new();
    for dir in std::fs::read_dir(&root).expect("tests/fuzz_regressions/ exists") {
        let dir = dir.expect("a readable entry").path();
        let target = dir.file_name().unwrap().to_string_lossy().into_owned();
        for file in std::fs::read_dir(&dir).expect("a target's folder") {
            let file = file.expect("a readable entry").path();
            let name = file.file_name().unwrap().to_string_lossy().into_owned();
            found.push((
                target.clone(),
                name,
                std::fs::read(&file).expect("a readable file"),
            ));
        }
    }
    found.sort();
    found
}

/// A rejected file says where and what: every diagnostic has a message and
/// names the file.
fn assert_clear_error(name: &str, data: &[u8], format: Format) {
    if let Some(Err(e)) = load(data, format) {
        for d in &e.diagnostics {
            assert!(!d.message.trim().is_empty(), "{name}: an empty message");
            assert!(d.to_string().starts_with("fuzz.mech"), "{name}: {d}");
        }
    }
}

#[test]
fn every_input_the_fuzzer_found_ends_in_an_error_or_valid_frames() {
    let found = regressions();
    assert!(!found.is_empty(), "tests/fuzz_regressions/ holds the inputs");
    for (target, name, data) in &found {
        eprintln!("{target}/{name}");
        match target.as_str() {
            "load_toml" => assert_clear_error(name, data, Format::Toml),
            "load_json" => assert_clear_error(name, data, Format::Json),
            "plan" => {
                assert_clear_error(name, data, guess_format(data));
                let _ = plan(data);
            }
            "interpret" => {
                assert_clear_error(name, data, guess_format(data));
                let _ = interpret(data);
            }
            other => panic!("tests/fuzz_regressions/{other}: not a fuzz target"),
        }
    }
}

#[test]
fn an_equation_no_step_checks_refuses_the_plan() {
    // The trammel's bar drawn with zero length: the rules take joint Y for
    // joint X and leave joint TY to nobody; the frames broke it unnoticed.
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fuzz_regressions/interpret/joints_at_one_point.toml");
    let m = dofplan::load_file(&path).expect("it loads: every joint holds as drawn");
    match dofplan::analysis::analyse(&m).plan {
        Err(PlanError::Unchecked { equations }) => assert_eq!(equations, ["joint TY"]),
        other => panic!("expected the plan refused for joint TY, got {other:?}"),
    }
}
