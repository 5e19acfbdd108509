//! The README's own-loop example, verbatim: a user crate whose build.rs
//! asks for the four-bar's design module (`Config::design`) and whose
//! `fit` binary runs a pattern search over compiled candidates, built by
//! cargo and run. The search must find the drawn four-bar again from the
//! moved start (its targets are the drawing's own path).

use std::process::Command;

use dofplan_tests::user_crate::UserCrate;

/// The README block that starts with `marker` and ends at its fence.
fn readme_block(marker: &str) -> String {
    let readme =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/README.md")).expect("README.md");
    let start = readme
        .find(marker)
        .unwrap_or_else(|| panic!("the README shows {marker}"));
    let end = start + readme[start..].find("```").expect("the block ends");
    readme[start..end].to_string()
}

#[test]
fn the_readme_own_loop_over_a_compiled_design_module_builds_and_fits() {
    let krate = UserCrate::new("my_mechanisms_design");
    let fourbar =
        std::fs::read_to_string(dofplan_tests::mechanisms_dir().join("fourbar.toml")).expect("bundled");
    // The README's crate is `my_mechanisms`; this one has its own folder.
    let fit = readme_block("// src/bin/fit.rs").replace("my_mechanisms::", "my_mechanisms_design::");
    krate
        .file("build.rs", &readme_block("// build.rs, with the design module"))
        .file("mechanisms/fourbar.toml", &fourbar)
        .file("src/bin/fit.rs", &fit);
    let out = krate.build();
    assert!(
        out.status.success(),
        "the build failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let exe = krate
        .dir()
        .parent()
        .expect("under target/user-crates")
        .join("target/debug/fit");
    let out = Command::new(&exe)
        .output()
        .unwrap_or_else(|e| panic!("{}: {e}", exe.display()));
    let printed = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{printed}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // "error 1.2e-21 after 5432 candidates, D.x = 4.000000"
    let words: Vec<&str> = printed.split_whitespace().collect();
    let error: f64 = words[1].parse().unwrap_or_else(|e| panic!("{printed}: {e}"));
    assert!(
        error < 1e-12,
        "the fit does not reach the drawn four-bar: {printed}"
    );
    assert_eq!(words.last(), Some(&"4.000000"), "{printed}");
}
