//! Stress chains of hundreds of loops: the generator's files, the
//! linear growth of the planner's work and readable pictures. One test
//! binary for all of them: each would link dofplan, the runtime and
//! dofplan-generated on its own.

mod render;
mod scaling;
mod stress_chain;
