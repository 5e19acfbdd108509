//! `dofplan::build` as a user's build.rs runs it: a crate whose build script
//! is the README's (`fn main() -> Result<(), Box<dyn Error>>` with `?`),
//! built by cargo.

use dofplan_tests::user_crate::UserCrate;

/// The README's build.rs.
const BUILD_RS: &str = r#"fn main() -> Result<(), Box<dyn std::error::Error>> {
    dofplan::build::Config::new().compile_dir("mechanisms")?;
    Ok(())
}
"#;

#[test]
fn a_broken_file_fails_the_build_with_the_cli_diagnostic_not_a_debug_dump() {
    let krate = UserCrate::new("broken_mechanism");
    krate.file("build.rs", BUILD_RS);
    let good = std::fs::read_to_string(dofplan_tests::mechanisms_dir().join("fourbar.toml"))
        .expect("the bundled four-bar");
    // A joint naming a marker the crank does not have.
    let broken = good.replacen("\"crank.B\"", "\"crank.Q\"", 1);
    assert_ne!(broken, good, "the four-bar has a joint on crank.B");
    krate.file("mechanisms/fourbar.toml", &broken);
    let out = krate.build();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "the build must fail:\n{stderr}");
    // file:line:col of the bad marker name, its source line, and the
    // names involved, as the CLI shows them.
    let line = broken
        .lines()
        .position(|l| l.contains("\"crank.Q\""))
        .expect("the broken line")
        + 1;
    let col = broken.lines().nth(line - 1).unwrap().find("\"crank.Q\"").unwrap() + 1;
    let position = format!("mechanisms/fourbar.toml:{line}:{col}");
    assert!(stderr.contains(&position), "no {position} in:\n{stderr}");
    assert!(stderr.contains("crank.Q"), "the marker is named:\n{stderr}");
    let source_line = broken.lines().nth(line - 1).unwrap();
    assert!(
        stderr.contains(source_line),
        "the source line is shown:\n{stderr}"
    );
    assert!(stderr.contains("markers of `crank` are"), "the help:\n{stderr}");
    // Not the Debug dump of the error's fields, which holds the whole file
    // on one escaped line.
    assert!(!stderr.contains("Diagnostic {"), "a Debug dump:\n{stderr}");
    assert!(!stderr.contains("\\n"), "escaped newlines:\n{stderr}");
    // Cargo is told to rerun the script when the file changes (cargo
    // shows a failed script's stdout).
    assert!(
        stderr.contains("cargo:rerun-if-changed=mechanisms/fourbar.toml"),
        "rerun-if-changed for the file read:\n{stderr}"
    );
}
