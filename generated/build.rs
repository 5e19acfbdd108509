//! Compiles every mechanism file in the workspace's mechanisms/ folder into
//! a plan module — exactly what a user's build.rs does — plus the drag
//! demo's open chain dragged by its end, planned like an input, and the
//! test fixtures of tests/fixtures/ (mechanisms that exercise generated
//! code no bundled mechanism needs).

use std::path::{Path, PathBuf};

fn files(dir: &Path) -> Vec<PathBuf> {
    println!("cargo:rerun-if-changed={}", dir.display());
    let mut out: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| matches!(p.extension().and_then(|e| e.to_str()), Some("toml" | "json")))
        .collect();
    out.sort();
    out
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mechanisms = root.join("mechanisms");
    let mut all = files(&mechanisms);
    all.extend(files(&root.join("tests/fixtures")));
    let result = dofplan::build::Config::new()
        .drag(mechanisms.join("drag/open_chain_15.toml"), "link_15.E")
        .compile(&all);
    if let Err(e) = result {
        // Cargo shows build-script output on failure; the error names the
        // file, line and column.
        eprintln!("{e}");
        std::process::exit(1);
    }
}
