//! The `dofplan` binary as a user runs it: every command on the bundled
//! files, `assemble` on rough drawings, spatial `check`, `analyze` and
//! `emit`, and the outputs and pictures the README shows. One test binary
//! for all of them: each would link dofplan on its own.

mod assemble;
mod assemble_spatial;
mod cli;
mod docs_links;
mod docs_pictures;
mod forces;
mod import;
mod readme;
mod sensitivity;
mod spatial_analyze;
mod spatial_build;
mod synth;
mod synth_spatial;
mod user_docs;
