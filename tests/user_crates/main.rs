//! Crates as a user writes them, built by cargo: a build script's
//! diagnostics on a broken file and a 1,000-loop chain that compiles in
//! debug. Both builds share one target directory (under
//! `target/user-crates/`), so cargo runs them one at a time whether they
//! are one test binary or two; as one, dofplan and the runtime are linked
//! once.

mod big_module;
mod build_script;
mod design_loop;
