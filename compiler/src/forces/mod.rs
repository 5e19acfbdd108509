//! Forces from the plan: what each input must supply for a mechanism to
//! hold, or to run at a given speed, under its masses, gravity and loads
//! (`[loads.NAME]`, `model::planar::loads`).
//!
//! By virtual work with the plan's exact rates: the input force `Q_i` is
//! minus the power every load (and, running, every body's d'Alembert
//! inertia) delivers per unit rate of input `i`, the others held; the
//! derivatives are the plan's own (`Interpreter::rates`), not differences.
//! One pass of the plan's rates per input and one for the motion itself.
//!
//! Planar for now (`planar.rs`); joint reactions are not computed yet.

pub mod planar;
