//! Spatial mechanisms end to end: file to plan to interpreter against
//! closed forms and raw joint residuals, and their velocities and
//! accelerations. One test binary for both: each would link dofplan, the
//! runtime and dofplan-generated on its own.

mod forces;
mod spatial;
mod spatial_rates;
