//! Numerical solving of what closed-form contraction leaves over.
//!
//! After the plan has placed everything it can by construction (circles,
//! lines, turn tables), the remaining constraints form a small system of
//! equations `r(x) = 0` that is solved numerically at move time (Brunkhart,
//! MechEdit §3.4/§4): multidimensional Newton–Raphson whose linear step is
//! the **minimum-norm least-squares** solution of `J·δ = −r` obtained from a
//! singular value decomposition (the pseudo-inverse).
//!
//! That one choice of linear step covers every shape of system:
//!
//! - **well-constrained** (square, full rank): the ordinary Newton step, with
//!   quadratic convergence near a root;
//! - **under-constrained** (more unknowns than independent equations): of all
//!   the steps that satisfy the linearised equations the smallest one is
//!   taken, so the mechanism moves as little as possible — physically like
//!   friction holding the free degrees of freedom where they are;
//! - **over-constrained and consistent** (redundant constraints): the
//!   redundant rows add no rank and the iteration converges as if they were
//!   absent;
//! - **over-constrained and inconsistent**: the iteration settles at a
//!   least-squares minimum with a non-zero residual, which is reported as
//!   [`NewtonOutcome::NoSolution`] ("no solution within reach").
//!
//! The numerical rank is decided by a **relative** cut-off: singular values at
//! or below `rank_cutoff × σ_max` count as zero, so the rank follows from the
//! condition number of the Jacobian and does not depend on the units or the
//! scale of the mechanism.
//!
//! [`rank`] and [`min_norm_step`] are exposed on their own because analysis
//! uses the same rank decision to find redundant constraints and idle degrees
//! of freedom: plan time and move time then agree on what "dependent" means.

pub mod cluster;
mod linalg;
mod newton;
pub mod priority;

/// The fixed-size `nalgebra` types generated code names.
pub use nalgebra::{Const, SMatrix, SVector};

pub use linalg::{
    lu_solve, min_norm_step, null_space, pseudo_inverse, rank, Implicit, NewtonAllocator, RATE_CUTOFF,
};
pub use newton::{fixed_system, Equations, FixedSystem, Newton, NewtonOptions, NewtonOutcome, NewtonReport};

#[cfg(test)]
mod tests;
