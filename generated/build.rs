//! Compiles every mechanism file in the workspace's mechanisms/ folder into
//! a plan module — exactly what a user's build.rs does — and the drag demo's
//! open chain dragged by its end, planned like an input.

fn main() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../mechanisms");
    let result = dofplan::build::Config::new()
        .drag(dir.join("drag/open_chain_15.toml"), "link_15.E")
        .compile_dir(&dir);
    if let Err(e) = result {
        // Cargo shows build-script output on failure; the error names the
        // file, line and column.
        eprintln!("{e}");
        std::process::exit(1);
    }
}
