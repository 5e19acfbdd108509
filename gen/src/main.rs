//! `dofplan-gen`: writes generated mechanism files to standard output.
//!
//! `cargo run --release -p dofplan-gen -- stress-chain 2000 > chain.toml`
//! builds this crate alone (no dependencies) in seconds; `… -- huge DIR`
//! writes the huge-input tests' 50 MB files into DIR.

use std::io::Write;
use std::process::ExitCode;

const USAGE: &str = "usage: dofplan-gen stress-chain LOOPS   (LOOPS a whole number, at least 1)
  Writes a stress chain of LOOPS four-bar loops (Brunkhart's Stress-n pattern,
  every loop after the first a parallelogram) as a mechanism file.
       dofplan-gen huge DIR
  Writes the huge-input tests' 50 MB files into DIR (made if missing).";

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let words: Vec<&str> = args.iter().map(String::as_str).collect();
    match words.as_slice() {
        ["stress-chain", n] => match n.parse::<usize>() {
            Ok(loops) if loops >= 1 => {
                let text = dofplan_gen::stress::stress_chain(loops);
                // A closed pipe (`| head`) is not an error worth a panic.
                match std::io::stdout().lock().write_all(text.as_bytes()) {
                    Ok(()) => ExitCode::SUCCESS,
                    Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => ExitCode::SUCCESS,
                    Err(e) => {
                        eprintln!("dofplan-gen: cannot write the chain: {e}");
                        ExitCode::FAILURE
                    }
                }
            }
            _ => {
                eprintln!("dofplan-gen: LOOPS must be a whole number, at least 1, not {n:?}\n{USAGE}");
                ExitCode::FAILURE
            }
        },
        ["huge", dir] => write_huge(std::path::Path::new(dir)),
        ["--help"] | ["-h"] => {
            println!("{USAGE}");
            ExitCode::SUCCESS
        }
        _ => {
            eprintln!("{USAGE}");
            ExitCode::FAILURE
        }
    }
}

/// The huge-input files into `dir`, their paths on standard output.
fn write_huge(dir: &std::path::Path) -> ExitCode {
    if let Err(e) = std::fs::create_dir_all(dir) {
        eprintln!("dofplan-gen: cannot create {}: {e}", dir.display());
        return ExitCode::FAILURE;
    }
    for (name, text) in dofplan_gen::huge::FILES {
        let path = dir.join(name);
        if let Err(e) = std::fs::write(&path, text()) {
            eprintln!("dofplan-gen: cannot write {}: {e}", path.display());
            return ExitCode::FAILURE;
        }
        println!("{}", path.display());
    }
    ExitCode::SUCCESS
}
