//! Writes a stress chain of N four-bar loops as a mechanism file, for the
//! CLI and for scaling measurements:
//! `cargo run --example stress_chain -- 1000 > stress_loops_1000.toml`.

use std::process::ExitCode;

fn main() -> ExitCode {
    let arg = std::env::args().nth(1);
    match arg.as_deref().map(str::parse::<usize>) {
        Some(Ok(loops)) if loops >= 1 => {
            print!("{}", dofplan_tests::stress::stress_chain(loops));
            ExitCode::SUCCESS
        }
        _ => {
            eprintln!("usage: stress_chain LOOPS   (a whole number, at least 1)");
            ExitCode::FAILURE
        }
    }
}
