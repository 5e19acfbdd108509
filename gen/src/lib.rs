//! Generators of mechanism files, kept in a crate of their own with no
//! dependencies so that writing a file never waits for the workspace's
//! heavier crates to build (`cargo run -p dofplan-gen`). The tests, examples
//! and benchmarks use the same functions through `dofplan_tests`.

pub mod huge;
pub mod stress;
pub mod vec2;
