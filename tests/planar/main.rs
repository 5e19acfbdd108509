//! Planar mechanisms end to end, one module per concern: closed forms,
//! breaking policies and circuits, sweeps and batches, rates, numeric
//! clusters, pure Newton, dragging, rank and over-constrained mechanisms,
//! gears and rack and pinion.
//! One test binary for all of them: each would link dofplan, the runtime
//! and dofplan-generated on its own.

mod arc_slots;
mod batch;
mod breaking;
mod circuits;
mod classics;
mod cluster_rates;
mod drag;
mod forces;
mod fragments;
mod gear_forces;
mod gears;
mod mixed;
mod newton;
mod overconstrained;
mod rank;
mod rates;
mod slots;
mod sweeps;
