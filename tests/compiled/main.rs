//! Plans compiled into Rust: the snapshotted source dofplan-generated
//! compiles, the split and rolled forms of large plans and the compiled
//! spatial plans, each against the interpreter frame for frame. One test
//! binary for all of them: each would link dofplan, the runtime and
//! dofplan-generated on its own.

mod chunked;
mod design;
mod design_gradient;
mod forces;
mod higher_pairs;
mod rolled;
mod snapshots;
mod spatial_compiled;
