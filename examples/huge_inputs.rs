//! Writes the 50 MB files of the huge-input tests into a directory, for
//! measuring the CLI on them:
//! `cargo run --release --example huge_inputs -- /tmp/huge`, then
//! `/usr/bin/time -v target/release/dofplan check /tmp/huge/array.toml`.

use std::path::PathBuf;
use std::process::ExitCode;

fn main() -> ExitCode {
    let Some(dir) = std::env::args().nth(1).map(PathBuf::from) else {
        eprintln!("usage: huge_inputs DIR   (the files are written into DIR)");
        return ExitCode::FAILURE;
    };
    if let Err(e) = std::fs::create_dir_all(&dir) {
        eprintln!("cannot create {}: {e}", dir.display());
        return ExitCode::FAILURE;
    }
    for (name, text) in dofplan_tests::huge::FILES {
        let path = dir.join(name);
        if let Err(e) = std::fs::write(&path, text()) {
            eprintln!("cannot write {}: {e}", path.display());
            return ExitCode::FAILURE;
        }
        println!("{}", path.display());
    }
    ExitCode::SUCCESS
}
