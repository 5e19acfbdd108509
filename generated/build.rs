//! Compiles every mechanism file in the workspace's mechanisms/ folder into
//! a plan module — exactly what a user's build.rs does.

fn main() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../mechanisms");
    if let Err(e) = dofplan::build::Config::new().compile_dir(&dir) {
        // Cargo shows build-script output on failure; the error names the
        // file, line and column.
        eprintln!("{e}");
        std::process::exit(1);
    }
}
