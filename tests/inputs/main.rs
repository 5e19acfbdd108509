//! Input that is not a good mechanism: bad files of every kind, planar
//! and spatial, the fuzz targets' regressions and huge files, each met with
//! a clear error and never a panic. One test binary for all of them: each
//! would link dofplan, the runtime and dofplan-generated on its own.

mod bad_input;
mod bad_input_spatial;
mod fuzz_regressions;
mod huge_input;
