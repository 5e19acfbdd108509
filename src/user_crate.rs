//! A crate as a dofplan user writes one — a `build.rs` calling
//! `dofplan::build`, a library including the generated `mechanisms.rs` —
//! built by cargo in a debug build, so tests see what a user sees: the
//! build script's output on a broken file, or whether a large generated
//! module compiles at all.
//!
//! Each crate lives in `target/user-crates/<name>/` and they share one
//! target directory, `target/user-crates/target/`, kept between runs so
//! their dependencies (the workspace's own, at the versions of its
//! `Cargo.lock`) are built once. It is separate from the workspace's target
//! directory, which the running `cargo test` holds locked.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A throwaway user crate.
pub struct UserCrate {
    dir: PathBuf,
}

impl UserCrate {
    /// A fresh crate named `name` (its folder is emptied first) depending on
    /// `dofplan-runtime` and, for its build script, on `dofplan` without
    /// the CLI, both by path to this workspace.
    pub fn new(name: &str) -> UserCrate {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let dir = root.join("target/user-crates").join(name);
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("src")).expect("create the user crate's folder");
        let manifest = format!(
            r#"[package]
name = "{name}"
version = "0.1.0"
edition = "2021"
publish = false

# Not a member of the dofplan workspace it sits in.
[workspace]

[dependencies]
dofplan-runtime = {{ path = {runtime:?} }}

[build-dependencies]
dofplan = {{ path = {compiler:?}, default-features = false }}
"#,
            runtime = root.join("runtime").display().to_string(),
            compiler = root.join("compiler").display().to_string(),
        );
        let krate = UserCrate { dir };
        krate.file("Cargo.toml", &manifest);
        // The workspace's lock file pins the same dependency versions, so
        // the build needs no registry look-up (cargo drops what is unused).
        std::fs::copy(root.join("Cargo.lock"), krate.dir.join("Cargo.lock")).expect("copy Cargo.lock");
        krate.file(
            "src/lib.rs",
            "include!(concat!(env!(\"OUT_DIR\"), \"/mechanisms.rs\"));\n",
        );
        krate
    }

    /// The crate's folder.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Writes `text` to `path` (relative to the crate), creating folders.
    pub fn file(&self, path: &str, text: &str) -> &UserCrate {
        let path = self.dir.join(path);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).expect("create a folder of the user crate");
        }
        std::fs::write(&path, text).expect("write a file of the user crate");
        self
    }

    /// `cargo build` (debug, offline, locked to the workspace's versions).
    pub fn build(&self) -> Output {
        let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
        let target = self
            .dir
            .parent()
            .expect("under target/user-crates")
            .join("target");
        Command::new(cargo)
            .arg("build")
            .arg("--offline")
            .current_dir(&self.dir)
            .env("CARGO_TARGET_DIR", target)
            // The colours and progress of the outer `cargo test` must not
            // leak into the output the tests read.
            .env("CARGO_TERM_COLOR", "never")
            .env_remove("RUSTFLAGS")
            .output()
            .expect("run cargo")
    }
}
