//! Shared helpers of the end-to-end tests in `tests/` (this root package
//! exists to own them; see the workspace `Cargo.toml`).
