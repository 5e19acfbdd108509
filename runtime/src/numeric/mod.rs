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
pub mod priority;

/// The fixed-size `nalgebra` types generated code names.
pub use nalgebra::{Const, SMatrix, SVector};

use nalgebra::allocator::Allocator;
use nalgebra::{
    DMatrix, DVector, DefaultAllocator, Dim, DimDiff, DimMin, DimMinimum, DimSub, Dyn, OMatrix, OVector, SVD,
    U1,
};

/// Every matrix shape Newton's linear algebra uses on an `R × C` Jacobian
/// (`R` equations, `C` unknowns), as one bound: the residual and step
/// vectors, `J` and `Jᵀ`, both Gram matrices of the normal equations and
/// the SVD's factors. Implemented for `nalgebra`'s allocator whenever all
/// of them exist — for `Dyn` (heap) and for fixed sizes up to 127 (stack,
/// where a solve allocates nothing).
pub trait NewtonAllocator<R: DimMin<C>, C: Dim>:
    Allocator<R, C>
    + Allocator<C, R>
    + Allocator<R, R>
    + Allocator<C, C>
    + Allocator<R>
    + Allocator<C>
    + Allocator<DimDiff<DimMinimum<R, C>, U1>>
    + Allocator<DimMinimum<R, C>, C>
    + Allocator<R, DimMinimum<R, C>>
    + Allocator<DimMinimum<R, C>>
where
    DimMinimum<R, C>: DimSub<U1>,
{
}

impl<R: DimMin<C>, C: Dim, A> NewtonAllocator<R, C> for A
where
    DimMinimum<R, C>: DimSub<U1>,
    A: Allocator<R, C>
        + Allocator<C, R>
        + Allocator<R, R>
        + Allocator<C, C>
        + Allocator<R>
        + Allocator<C>
        + Allocator<DimDiff<DimMinimum<R, C>, U1>>
        + Allocator<DimMinimum<R, C>, C>
        + Allocator<R, DimMinimum<R, C>>
        + Allocator<DimMinimum<R, C>>,
{
}

/// Options of a Newton solve.
///
/// The defaults suit a well-scaled system whose unknowns are of order one;
/// callers with other scales set [`tolerance`](Self::tolerance) (and possibly
/// [`max_step`](Self::max_step)) accordingly.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonOptions {
    /// Iteration budget: the largest number of Jacobian evaluations (Newton
    /// steps) one solve may spend. Default 50.
    ///
    /// A per-frame budget keeps a move-time frame bounded even when the
    /// system converges slowly or not at all.
    pub max_iterations: u32,
    /// Converged when the residual's Euclidean norm is at most this. The
    /// value is absolute: callers scale it to the size of their mechanism.
    /// Default `1e-12`.
    pub tolerance: f64,
    /// Singular values at or below `rank_cutoff × σ_max` count as zero.
    /// Default `1e-10`.
    ///
    /// Relative rather than absolute, so the numerical rank is a statement
    /// about the condition number of the Jacobian, independent of units.
    /// Negative or NaN values are treated as zero (exact rank).
    pub rank_cutoff: f64,
    /// Largest step per iteration: the step is scaled down (direction kept)
    /// so its max-norm — the largest `|δ_i|` — is at most this. Default
    /// `f64::INFINITY` (no limit).
    ///
    /// Limiting the step keeps a far-off warm start from jumping to a
    /// different assembly branch; it should be positive. A zero, negative
    /// or NaN value is treated as no limit.
    pub max_step: f64,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        NewtonOptions {
            max_iterations: 50,
            tolerance: 1e-12,
            rank_cutoff: 1e-10,
            max_step: f64::INFINITY,
        }
    }
}

/// How a solve ended.
///
/// Brunkhart (§5.1) notes that a slowly converging system cannot be told from
/// one with no real solution by watching the iteration count alone. Here the
/// two are told apart by a least-squares minimum test: when the Newton step
/// has become negligible, or no shortened (backtracked) version of it
/// decreases the residual any more, the residual is at a (local) least-squares minimum and further
/// iterations cannot help — that is [`NoSolution`](Self::NoSolution). Running
/// out of budget while still making progress is
/// [`NotConverged`](Self::NotConverged): more iterations (or a better warm
/// start, e.g. a smaller motion per frame) may still succeed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NewtonOutcome {
    /// The residual norm reached the tolerance.
    Converged,
    /// The iteration budget ran out while the residual was still decreasing.
    NotConverged,
    /// The residual stopped decreasing above the tolerance (a least-squares
    /// minimum with non-zero residual: no solution within reach of the warm
    /// start), or the system evaluated to a non-finite value.
    NoSolution,
}

/// What a solve reports (per frame, to the user).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonReport {
    /// How the solve ended.
    pub outcome: NewtonOutcome,
    /// Newton iterations taken (Jacobian evaluations). Zero when the warm
    /// start already satisfied the tolerance.
    pub iterations: u32,
    /// Final residual norm (Euclidean), at the point left in `x`. A
    /// non-finite residual at the warm start is reported as `f64::INFINITY`.
    pub residual: f64,
    /// Numerical rank of the last Jacobian (0 if none was evaluated).
    ///
    /// Less than `min(unknowns, equations)` means dependent constraints or
    /// idle unknowns at the final point.
    pub rank: usize,
}

/// A system of equations `r(x) = 0` with its Jacobian.
///
/// Implemented by whatever the plan leaves to be solved numerically. The
/// system is `&mut` so it can keep its own scratch space.
pub trait Equations<R: Dim = Dyn, C: Dim = Dyn>
where
    DefaultAllocator: Allocator<R> + Allocator<C> + Allocator<R, C>,
{
    /// Number of unknowns (length of `x`).
    fn unknowns(&self) -> usize;
    /// Number of equations (length of `r`).
    fn equations(&self) -> usize;
    /// Writes `r(x)` into `r` (length = `equations()`); when `jacobian` is
    /// `Some`, also `∂r/∂x` into it (`equations() × unknowns()`).
    ///
    /// The residual is asked for alone (without the Jacobian) during the line
    /// search, so a system may skip the derivative work then.
    fn eval(
        &mut self,
        x: &OVector<f64, C>,
        r: &mut OVector<f64, R>,
        jacobian: Option<&mut OMatrix<f64, R, C>>,
    );
}

/// A fixed-size system given by a closure `(x, r, J)` — what generated code
/// writes for a numeric cluster: its residuals and analytic Jacobian as
/// straight-line code over `M` equations and `N` unknowns.
pub struct FixedSystem<const M: usize, const N: usize, F> {
    f: F,
}

/// A fixed-size system from its evaluation closure (see [`FixedSystem`]).
pub fn fixed_system<const M: usize, const N: usize, F>(f: F) -> FixedSystem<M, N, F>
where
    F: FnMut(&SVector<f64, N>, &mut SVector<f64, M>, Option<&mut SMatrix<f64, M, N>>),
{
    FixedSystem { f }
}

impl<const M: usize, const N: usize, F> Equations<Const<M>, Const<N>> for FixedSystem<M, N, F>
where
    F: FnMut(&SVector<f64, N>, &mut SVector<f64, M>, Option<&mut SMatrix<f64, M, N>>),
{
    fn unknowns(&self) -> usize {
        N
    }
    fn equations(&self) -> usize {
        M
    }
    fn eval(
        &mut self,
        x: &SVector<f64, N>,
        r: &mut SVector<f64, M>,
        jacobian: Option<&mut SMatrix<f64, M, N>>,
    ) {
        (self.f)(x, r, jacobian)
    }
}

/// Newton–Raphson with an SVD pseudo-inverse step; owns its work buffers so
/// repeated solves of the same size do not reallocate them.
///
/// (The SVD itself still allocates its factors per iteration; the buffers
/// kept here are the residuals, the Jacobian, the step and the trial point.)
///
/// Each iteration takes the minimum-norm least-squares step `δ = −J⁺·r`,
/// limits it to [`NewtonOptions::max_step`], and tries `x + δ`. Near a
/// regular root that full step is always accepted and convergence is
/// quadratic. Far from a solution the full step can overshoot, so the solver
/// backtracks until the residual norm decreases — this line search is what
/// makes the iteration robust from a poor warm start:
///
/// - When the kept singular values of `J` are all alike the backtracking is
///   plain halving, `x + δ/2`, `x + δ/4`, ….
/// - When `J` is ill-conditioned (a configuration near a singular one, like
///   two circles that barely miss each other), halving alone crawls: the
///   Newton step is dominated by its weak, wildly extrapolated component, and
///   cutting the whole step down to what that component tolerates leaves the
///   useful components negligible. The trials therefore damp each singular
///   component by `σᵢ²/(σᵢ² + λ)` with `λ = σ_min²·(2ʲ − 1)` for trial `j`
///   (Levenberg–Marquardt damping in the SVD basis), which cuts the weak
///   directions back first and reduces to exact halving in the
///   well-conditioned case.
///
/// Only decreasing steps are accepted, so the current point is always the
/// best one seen.
///
/// The sizes are `nalgebra` dimensions: `Newton` (= `Newton<Dyn, Dyn>`)
/// for systems sized at run time, `Newton<Const<M>, Const<N>>` (see
/// [`Newton::fixed`]) for the clusters generated code knows at build time,
/// whose buffers and factorisations then all live on the stack.
#[derive(Clone, Debug)]
pub struct Newton<R: Dim = Dyn, C: Dim = Dyn>
where
    DefaultAllocator: Allocator<R> + Allocator<C> + Allocator<R, C>,
{
    /// Residual at the current point.
    r: OVector<f64, R>,
    /// Jacobian at the current point.
    jacobian: OMatrix<f64, R, C>,
    /// Newton step.
    step: OVector<f64, C>,
    /// Trial point of the line search.
    trial: OVector<f64, C>,
    /// Residual at the trial point.
    r_trial: OVector<f64, R>,
}

/// The line search stops once the damping has shrunk even the strongest
/// component of the step below `2^-MAX_HALVINGS` of its full length.
const MAX_HALVINGS: i32 = 30;

/// Hard cap on the trials of one line search (the damping grows as `2^j`, so
/// `MAX_HALVINGS` plus twice the binary logarithm of the condition number,
/// at most about 100 with the default cut-off, are reached before this).
const MAX_TRIALS: i32 = 200;

/// A step is negligible when `‖δ‖ ≤ NEGLIGIBLE_STEP · (1 + ‖x‖)`: it could
/// not change `x` in floating point.
/// The share of the residual left in the range of the Jacobian below which
/// the residual counts as orthogonal to it (a least-squares minimum).
const STATIONARY: f64 = 1e-6;

/// Iterations over which a residual that does not halve counts as stagnant.
const STAGNATION_WINDOW: usize = 6;

/// Iterations before the stagnation rule applies.
const STAGNATION_AFTER: u32 = 12;

const NEGLIGIBLE_STEP: f64 = 1e-15;

/// A trial point is accepted when its residual norm is below
/// `(1 − MIN_DECREASE) ×` the current one. The tiny relative margin stops the
/// iteration from creeping by rounding noise at a least-squares minimum.
const MIN_DECREASE: f64 = 1e-14;

impl Newton {
    /// A solver with work buffers for `unknowns` unknowns and `equations`
    /// equations. Solving a system of another size still works; the buffers
    /// are then resized.
    pub fn new(unknowns: usize, equations: usize) -> Newton {
        Newton::with_shape(Dyn(equations), Dyn(unknowns))
    }
}

impl<const M: usize, const N: usize> Newton<Const<M>, Const<N>>
where
    Const<M>: DimMin<Const<N>>,
    DimMinimum<Const<M>, Const<N>>: DimSub<U1>,
    DefaultAllocator: NewtonAllocator<Const<M>, Const<N>>,
{
    /// A solver for `M` equations in `N` unknowns whose buffers live on the
    /// stack: a solve allocates nothing.
    pub fn fixed() -> Self {
        Self::with_shape(Const, Const)
    }
}

impl<R: DimMin<C>, C: Dim> Newton<R, C>
where
    DimMinimum<R, C>: DimSub<U1>,
    DefaultAllocator: NewtonAllocator<R, C>,
{
    /// A solver with work buffers of this shape.
    pub fn with_shape(equations: R, unknowns: C) -> Self {
        Newton {
            r: OVector::zeros_generic(equations, U1),
            jacobian: OMatrix::zeros_generic(equations, unknowns),
            step: OVector::zeros_generic(unknowns, U1),
            trial: OVector::zeros_generic(unknowns, U1),
            r_trial: OVector::zeros_generic(equations, U1),
        }
    }

    /// Makes the buffers fit a system of this size (only ever resizes
    /// dynamic buffers: a fixed-size system has the size of its type).
    fn fit(&mut self, unknowns: usize, equations: usize) {
        if self.r.len() != equations || self.step.len() != unknowns {
            *self = Self::with_shape(R::from_usize(equations), C::from_usize(unknowns));
        }
    }

    /// Solves in place from the warm start `x`. On
    /// [`NoSolution`](NewtonOutcome::NoSolution) /
    /// [`NotConverged`](NewtonOutcome::NotConverged), `x` holds the best point
    /// found (smallest residual) — for an inconsistent system that is the
    /// least-squares point nearest the warm start, which is what a frame
    /// should show.
    ///
    /// Never panics on non-finite values: a NaN or infinite residual at a
    /// trial point just rejects that trial, and one at the warm start (or a
    /// non-finite Jacobian) ends the solve with
    /// [`NoSolution`](NewtonOutcome::NoSolution), leaving `x` at the last
    /// finite point.
    ///
    /// # Panics
    ///
    /// If `x.len() != system.unknowns()` (a caller bug, not a numerical
    /// condition).
    pub fn solve<E: Equations<R, C>>(
        &mut self,
        system: &mut E,
        x: &mut OVector<f64, C>,
        options: &NewtonOptions,
    ) -> NewtonReport {
        let unknowns = system.unknowns();
        let equations = system.equations();
        assert_eq!(
            x.len(),
            unknowns,
            "Newton::solve: x has {} entries but the system has {} unknowns",
            x.len(),
            unknowns
        );
        self.fit(unknowns, equations);

        let report = |outcome, iterations, residual, rank| NewtonReport {
            outcome,
            iterations,
            residual,
            rank,
        };

        if equations == 0 {
            // Nothing to satisfy: any x is a solution.
            return report(NewtonOutcome::Converged, 0, 0.0, 0);
        }

        // The warm start first, without the Jacobian: a frame whose pose
        // already fits costs no Newton iteration.
        system.eval(x, &mut self.r, None);
        let mut residual = self.r.norm();
        if !residual.is_finite() {
            return report(NewtonOutcome::NoSolution, 0, f64::INFINITY, 0);
        }
        if residual <= options.tolerance {
            return report(NewtonOutcome::Converged, 0, residual, 0);
        }
        if unknowns == 0 {
            // Nothing to move: the residual is what it is.
            return report(NewtonOutcome::NoSolution, 0, residual, 0);
        }

        let mut iterations = 0;
        let mut rank = 0;
        let mut history = [f64::INFINITY; STAGNATION_WINDOW];
        loop {
            if iterations >= options.max_iterations {
                return report(NewtonOutcome::NotConverged, iterations, residual, rank);
            }
            system.eval(x, &mut self.r, Some(&mut self.jacobian));
            iterations += 1;
            residual = self.r.norm();
            if !residual.is_finite() {
                // Only reachable if the system is not deterministic (this x
                // evaluated finite before).
                return report(NewtonOutcome::NoSolution, iterations, f64::INFINITY, rank);
            }
            if residual <= options.tolerance {
                return report(NewtonOutcome::Converged, iterations, residual, rank);
            }

            // The SVD is only needed when the Jacobian is not of full rank
            // and well conditioned (or to damp a rejected step): otherwise
            // the minimum-norm step is the same through a Cholesky solve of
            // the (much cheaper) normal equations.
            let mut spectrum: Option<Spectrum<R, C>> = None;
            match full_rank_step(&self.jacobian, &self.r, &mut self.step) {
                Some(full) => rank = full,
                None => {
                    let Some(s) = Spectrum::new(&self.jacobian, &self.r, options.rank_cutoff) else {
                        // A non-finite Jacobian (or an SVD that did not
                        // converge): no direction to go.
                        return report(NewtonOutcome::NoSolution, iterations, residual, 0);
                    };
                    rank = s.rank;
                    s.min_norm(&self.r, &mut self.step);
                    spectrum = Some(s);
                }
            }
            // J·δ is minus the part of r in the range of J. When that part
            // is a vanishing share of r, r is (numerically) orthogonal to
            // the range: a least-squares minimum above the tolerance. Far
            // from the solution Gauss–Newton only creeps toward such a
            // minimum, so waiting for a negligible step would use up the
            // budget and report "not converged" where the truth is "no
            // solution within reach".
            let in_range = (&self.jacobian * &self.step).norm();
            if in_range <= STATIONARY * residual {
                return report(NewtonOutcome::NoSolution, iterations, residual, rank);
            }
            // Stagnation: once past the first iterations (where a far warm
            // start may need line-search steps), a residual that has not
            // halved over the last few iterations is creeping toward a
            // least-squares minimum, not toward zero: convergence to a
            // solution, even a singular one (a change point), at least
            // halves it every iteration. Telling the two apart is what
            // Brunkhart (§5.1) found hard; this is the rule we use.
            let slot = iterations as usize % STAGNATION_WINDOW;
            let old = history[slot];
            history[slot] = residual;
            if iterations >= STAGNATION_AFTER && residual > 0.5 * old {
                return report(NewtonOutcome::NoSolution, iterations, residual, rank);
            }
            let mut limit = options.max_step;
            if !clamp(&mut self.step, &mut limit) {
                return report(NewtonOutcome::NoSolution, iterations, residual, rank);
            }
            if self.step.norm() <= NEGLIGIBLE_STEP * (1.0 + x.norm()) {
                // J⁺·r ≈ 0 means Jᵀ·r ≈ 0: the gradient of ‖r‖² vanishes,
                // so this is a least-squares minimum above the tolerance.
                return report(NewtonOutcome::NoSolution, iterations, residual, rank);
            }

            // Backtracking on the residual norm: the full min-norm step,
            // then ever more damped ones (see `Spectrum::damped`).
            let target = residual * (1.0 - MIN_DECREASE);
            let mut accepted = false;
            for trial in 0..MAX_TRIALS {
                if trial > 0 {
                    if spectrum.is_none() {
                        spectrum = Spectrum::new(&self.jacobian, &self.r, options.rank_cutoff);
                    }
                    let Some(sp) = spectrum.as_ref() else { break };
                    let low = sp.smallest();
                    let lambda_limit = sp.largest().powi(2) * 2f64.powi(MAX_HALVINGS);
                    let lambda = low * low * (2f64.powi(trial) - 1.0);
                    if lambda > lambda_limit {
                        break;
                    }
                    sp.damped(lambda, &mut self.step);
                    if !clamp(&mut self.step, &mut limit)
                        || self.step.norm() <= NEGLIGIBLE_STEP * (1.0 + x.norm())
                    {
                        break;
                    }
                }
                self.trial.copy_from(x);
                self.trial += &self.step;
                system.eval(&self.trial, &mut self.r_trial, None);
                let trial_residual = self.r_trial.norm();
                // `<` is false for NaN, so a non-finite trial is rejected.
                if trial_residual < target {
                    x.copy_from(&self.trial);
                    std::mem::swap(&mut self.r, &mut self.r_trial);
                    residual = trial_residual;
                    accepted = true;
                    break;
                }
            }
            if !accepted {
                // Every trial is a descent direction for ‖r‖² whenever
                // Jᵀ·r ≠ 0; if not even a tiny one helps, the residual is at
                // a least-squares minimum (to rounding).
                return report(NewtonOutcome::NoSolution, iterations, residual, rank);
            }
            if residual <= options.tolerance {
                return report(NewtonOutcome::Converged, iterations, residual, rank);
            }
        }
    }
}

/// Rank of a matrix by the relative cut-off (used by analysis to find
/// redundant constraints and idle DOFs).
///
/// Counts the singular values greater than `rank_cutoff × σ_max`. Because the
/// cut-off is relative, scaling the matrix does not change its rank: the rank
/// is decided by the condition number, so a constraint that is redundant up
/// to rounding counts as redundant whatever the units of the mechanism.
///
/// An empty matrix, a zero matrix and a matrix with a non-finite entry have
/// rank 0. A negative or NaN `rank_cutoff` counts as 0 (exact rank).
pub fn rank(matrix: &DMatrix<f64>, rank_cutoff: f64) -> usize {
    match decompose(matrix, false) {
        Some(svd) => {
            let eps = threshold(&svd.singular_values, rank_cutoff);
            svd.singular_values.iter().filter(|&&s| s > eps).count()
        }
        None => 0,
    }
}

/// The minimum-norm step `δ = −J⁺·r` by the normal equations when `J` has
/// full rank and is well conditioned: `δ = −Jᵀ(JJᵀ)⁻¹r` for a wide or
/// square `J`, `δ = −(JᵀJ)⁻¹Jᵀr` for a tall one (its unique least-squares
/// solution). Returns the rank, or `None` — leave it to the SVD — when the
/// Cholesky factor is missing or its diagonal spans more than 1e5 (a
/// condition number of `J` beyond about 1e5, where squaring it in the normal
/// equations would cost accuracy the SVD keeps).
fn full_rank_step<R: DimMin<C>, C: Dim>(
    j: &OMatrix<f64, R, C>,
    r: &OVector<f64, R>,
    step: &mut OVector<f64, C>,
) -> Option<usize>
where
    DimMinimum<R, C>: DimSub<U1>,
    DefaultAllocator: NewtonAllocator<R, C>,
{
    let (m, n) = j.shape();
    if m == 0 || n == 0 {
        return None;
    }
    // Both Gram matrices are written out (only one is factorised) because
    // their types differ: R × R for a wide J, C × C for a tall one.
    if m <= n {
        let chol = nalgebra::Cholesky::new(j * j.transpose())?;
        if !well_conditioned(chol.l_dirty()) {
            return None;
        }
        j.tr_mul_to(&chol.solve(r), step);
    } else {
        let chol = nalgebra::Cholesky::new(j.transpose() * j)?;
        if !well_conditioned(chol.l_dirty()) {
            return None;
        }
        j.tr_mul_to(r, step);
        chol.solve_mut(step);
    }
    if step.iter().any(|v| !v.is_finite()) {
        return None;
    }
    step.neg_mut();
    Some(m.min(n))
}

/// Whether a Cholesky factor's diagonal spans at most 1e5 (see
/// [`full_rank_step`]).
fn well_conditioned<D: Dim>(l: &OMatrix<f64, D, D>) -> bool
where
    DefaultAllocator: Allocator<D, D>,
{
    let diag = (0..l.nrows()).map(|i| l[(i, i)].abs());
    let (lo, hi) = diag.fold((f64::INFINITY, 0.0_f64), |(lo, hi), d| (lo.min(d), hi.max(d)));
    !(lo.is_nan() || lo <= 1e-5 * hi)
}

/// The Moore–Penrose pseudo-inverse `J⁺` with the same relative cut-off as
/// [`min_norm_step`] (singular values at or below `rank_cutoff × σ_max`
/// dropped). Used where a step must be split between a task and the null
/// space of the constraints (dragging: `I − J⁺J` projects onto the motions
/// the joints allow). An empty, zero or non-finite matrix gives zeros.
pub fn pseudo_inverse(matrix: &DMatrix<f64>, rank_cutoff: f64) -> DMatrix<f64> {
    let (rows, cols) = matrix.shape();
    let Some(svd) = decompose(matrix, true) else {
        return DMatrix::zeros(cols, rows);
    };
    let eps = threshold(&svd.singular_values, rank_cutoff);
    svd.pseudo_inverse(eps)
        .unwrap_or_else(|_| DMatrix::zeros(cols, rows))
}

/// An orthonormal basis of the null space of `matrix` (one column per
/// direction), by the same relative cut-off as [`rank`]: the motions a set
/// of equations allows to first order. A matrix with a non-finite entry
/// allows none (zero columns); an empty one (no rows) allows every motion.
pub fn null_space(matrix: &DMatrix<f64>, rank_cutoff: f64) -> DMatrix<f64> {
    let (rows, cols) = matrix.shape();
    if cols == 0 {
        return DMatrix::zeros(0, 0);
    }
    // nalgebra's SVD is thin (min(rows, cols) right singular vectors): pad
    // with zero rows to at least square, so every direction is a vector.
    let mut square = DMatrix::zeros(rows.max(cols), cols);
    square.rows_mut(0, rows).copy_from(matrix);
    let Some(svd) = decompose(&square, true) else {
        return DMatrix::zeros(cols, 0);
    };
    let eps = threshold(&svd.singular_values, rank_cutoff);
    let v_t = svd.v_t.as_ref().expect("computed with vectors");
    let free: Vec<_> = (0..svd.singular_values.len())
        .filter(|&i| svd.singular_values[i] <= eps)
        .map(|i| v_t.row(i).transpose())
        .collect();
    if free.is_empty() {
        DMatrix::zeros(cols, 0)
    } else {
        DMatrix::from_columns(&free)
    }
}

/// Null-space-free min-norm least-squares solve of `J·δ = −r` via SVD with
/// relative cut-off (the Newton step); returns `(δ, rank)`.
///
/// `δ = −J⁺·r` where `J⁺` is the pseudo-inverse with singular values at or
/// below `rank_cutoff × σ_max` dropped. Among all least-squares solutions it
/// is the one of smallest norm, i.e. it has no component in the null space of
/// `J`: unknowns the equations do not constrain are not moved (least motion),
/// and directions made nearly free by a near-singular `J` are not amplified
/// into huge steps.
///
/// Any shape works (tall, square, wide). For an empty `J`, a zero `J` or one
/// with a non-finite entry (or a non-finite `r`) the step is zero and the
/// rank 0.
///
/// # Panics
///
/// If `residual.len() != jacobian.nrows()`.
pub fn min_norm_step(
    jacobian: &DMatrix<f64>,
    residual: &DVector<f64>,
    rank_cutoff: f64,
) -> (DVector<f64>, usize) {
    let mut step = DVector::zeros(jacobian.ncols());
    let rank = min_norm_step_into(jacobian, residual, rank_cutoff, &mut step);
    (step, rank)
}

/// [`min_norm_step`] writing into `step` (resized if needed); returns the rank.
fn min_norm_step_into(
    jacobian: &DMatrix<f64>,
    residual: &DVector<f64>,
    rank_cutoff: f64,
    step: &mut DVector<f64>,
) -> usize {
    assert_eq!(
        residual.len(),
        jacobian.nrows(),
        "min_norm_step: the residual has {} entries but the Jacobian {} rows",
        residual.len(),
        jacobian.nrows()
    );
    if step.len() != jacobian.ncols() {
        *step = DVector::zeros(jacobian.ncols());
    }
    match Spectrum::new(jacobian, residual, rank_cutoff) {
        Some(spectrum) => {
            spectrum.min_norm(residual, step);
            spectrum.rank
        }
        None => {
            step.fill(0.0);
            0
        }
    }
}

/// The SVD of a Jacobian with the residual expressed in its left singular
/// vectors: everything needed for the min-norm step and its damped variants.
struct Spectrum<R: DimMin<C>, C: Dim>
where
    DimMinimum<R, C>: DimSub<U1>,
    DefaultAllocator: NewtonAllocator<R, C>,
{
    svd: SVD<f64, R, C>,
    /// Absolute singular-value threshold, `rank_cutoff × σ_max`.
    eps: f64,
    /// Number of singular values above `eps`.
    rank: usize,
    /// `uᵢ·r` for every singular triple.
    coefficients: OVector<f64, DimMinimum<R, C>>,
}

impl<R: DimMin<C>, C: Dim> Spectrum<R, C>
where
    DimMinimum<R, C>: DimSub<U1>,
    DefaultAllocator: NewtonAllocator<R, C>,
{
    /// `None` when `jacobian` is empty or has a non-finite entry, `residual`
    /// has a non-finite entry, or the SVD does not converge.
    fn new(jacobian: &OMatrix<f64, R, C>, residual: &OVector<f64, R>, rank_cutoff: f64) -> Option<Self> {
        if !residual.iter().all(|v| v.is_finite()) {
            return None;
        }
        let svd = decompose(jacobian, true)?;
        let eps = threshold(&svd.singular_values, rank_cutoff);
        let rank = svd.singular_values.iter().filter(|&&s| s > eps).count();
        let coefficients = svd.u.as_ref()?.ad_mul(residual);
        Some(Spectrum {
            svd,
            eps,
            rank,
            coefficients,
        })
    }

    /// The min-norm step `−J⁺·r` into `step`.
    fn min_norm(&self, residual: &OVector<f64, R>, step: &mut OVector<f64, C>) {
        // `solve` zeroes the components whose singular value is `<= eps`:
        // its eps is an absolute threshold, hence cut-off × σ_max.
        match self.svd.solve(residual, self.eps) {
            Ok(solution) if self.rank > 0 => {
                step.copy_from(&solution);
                step.neg_mut();
            }
            _ => step.fill(0.0),
        }
    }

    /// The damped step `−Σ σᵢ·(uᵢ·r)/(σᵢ² + λ)·vᵢ` over the kept singular
    /// values into `step` (λ = 0 is the min-norm step).
    ///
    /// Each component of the min-norm step is scaled by `σᵢ²/(σᵢ² + λ)`:
    /// weak directions (small σᵢ, where the linearisation extrapolates
    /// wildly) are cut back long before strong ones. This is
    /// Levenberg–Marquardt damping; the step stays in the row space of `J`,
    /// so it still does not move what the equations leave free.
    fn damped(&self, lambda: f64, step: &mut OVector<f64, C>) {
        step.fill(0.0);
        let v_t = self.svd.v_t.as_ref().expect("computed with vectors");
        for (i, &sigma) in self.svd.singular_values.iter().enumerate() {
            if sigma > self.eps {
                let factor = -sigma * self.coefficients[i] / (sigma * sigma + lambda);
                step.axpy(factor, &v_t.row(i).transpose(), 1.0);
            }
        }
    }

    /// Smallest kept singular value (0 if none is kept).
    fn smallest(&self) -> f64 {
        let kept = self.svd.singular_values.iter().copied().filter(|&s| s > self.eps);
        kept.fold(f64::INFINITY, f64::min).min(self.largest())
    }

    /// Largest singular value.
    fn largest(&self) -> f64 {
        self.svd.singular_values.iter().copied().fold(0.0, f64::max)
    }
}

/// Scales `step` down so its max-norm is at most `limit`; when it had to,
/// halves `limit` for the next trial, so a clamped step that fails is
/// followed by a shorter one (plain halving). A non-positive or NaN `limit`
/// means no limit. Returns false if the step is not finite.
fn clamp<C: Dim>(step: &mut OVector<f64, C>, limit: &mut f64) -> bool
where
    DefaultAllocator: Allocator<C>,
{
    if !step.iter().all(|v| v.is_finite()) {
        return false;
    }
    let largest = step.amax();
    if *limit > 0.0 && largest > *limit {
        *step *= *limit / largest;
        *limit *= 0.5;
    }
    true
}

/// SVD of `matrix`, or `None` when it is empty, has a non-finite entry or
/// the iteration fails to converge.
///
/// nalgebra's SVD panics on an empty matrix, and its default constructor
/// iterates without bound, which a NaN would turn into a hang; hence the
/// checks and the bounded [`SVD::try_new`].
fn decompose<R: DimMin<C>, C: Dim>(matrix: &OMatrix<f64, R, C>, vectors: bool) -> Option<SVD<f64, R, C>>
where
    DimMinimum<R, C>: DimSub<U1>,
    DefaultAllocator: NewtonAllocator<R, C>,
{
    if matrix.is_empty() || !matrix.iter().all(|v| v.is_finite()) {
        return None;
    }
    let dim = matrix.nrows().min(matrix.ncols());
    // Implicit-shift QR sweeps; LAPACK allows 6·n² — be more generous.
    let max_sweeps = (30 * dim * dim).max(1000);
    SVD::try_new(matrix.clone(), vectors, vectors, f64::EPSILON * 5.0, max_sweeps)
}

/// The absolute singular-value threshold `rank_cutoff × σ_max`.
fn threshold<D: Dim>(singular_values: &OVector<f64, D>, rank_cutoff: f64) -> f64
where
    DefaultAllocator: Allocator<D>,
{
    let sigma_max = singular_values.iter().copied().fold(0.0, f64::max);
    let cutoff = if rank_cutoff > 0.0 { rank_cutoff } else { 0.0 };
    let eps = cutoff * sigma_max;
    // inf × 0 is NaN; with σ_max = 0 nothing counts anyway.
    if eps.is_nan() {
        0.0
    } else {
        eps
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A system given by closures.
    struct Closure<F> {
        unknowns: usize,
        equations: usize,
        f: F,
        jacobians: u32,
    }

    impl<F: FnMut(&DVector<f64>, &mut DVector<f64>, Option<&mut DMatrix<f64>>)> Equations for Closure<F> {
        fn unknowns(&self) -> usize {
            self.unknowns
        }
        fn equations(&self) -> usize {
            self.equations
        }
        fn eval(&mut self, x: &DVector<f64>, r: &mut DVector<f64>, jacobian: Option<&mut DMatrix<f64>>) {
            if jacobian.is_some() {
                self.jacobians += 1;
            }
            (self.f)(x, r, jacobian)
        }
    }

    fn system<F: FnMut(&DVector<f64>, &mut DVector<f64>, Option<&mut DMatrix<f64>>)>(
        unknowns: usize,
        equations: usize,
        f: F,
    ) -> Closure<F> {
        Closure {
            unknowns,
            equations,
            f,
            jacobians: 0,
        }
    }

    fn solve<F: FnMut(&DVector<f64>, &mut DVector<f64>, Option<&mut DMatrix<f64>>)>(
        sys: &mut Closure<F>,
        x: &mut DVector<f64>,
        options: &NewtonOptions,
    ) -> NewtonReport {
        let mut newton = Newton::new(sys.unknowns, sys.equations);
        sys.jacobians = 0;
        let report = newton.solve(sys, x, options);
        assert_eq!(
            report.iterations, sys.jacobians,
            "iterations count Jacobian evaluations"
        );
        report
    }

    #[test]
    fn the_null_space_is_complete_and_orthonormal() {
        // Two independent rows in four unknowns, and a third their sum: a
        // two-dimensional null space, which nalgebra's thin SVD of the 3×4
        // matrix alone would not give in full.
        let j = DMatrix::from_row_slice(
            3,
            4,
            &[1.0, 2.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0, 3.0, 1.0, 1.0],
        );
        let z = null_space(&j, 1e-10);
        assert_eq!(z.ncols(), 2);
        assert!((&j * &z).amax() < 1e-12);
        assert!((z.transpose() * &z - DMatrix::identity(2, 2)).amax() < 1e-12);
        // No rows: every direction; a non-finite entry: none.
        assert_eq!(null_space(&DMatrix::zeros(0, 3), 1e-10).ncols(), 3);
        let mut bad = DMatrix::identity(2, 3);
        bad[(0, 2)] = f64::NAN;
        assert_eq!(null_space(&bad, 1e-10).ncols(), 0);
    }

    /// Squared-distance circle equations `|p − c_i|² − r_i² = 0`.
    fn circles(
        circles: Vec<([f64; 2], f64)>,
    ) -> impl FnMut(&DVector<f64>, &mut DVector<f64>, Option<&mut DMatrix<f64>>) {
        move |x, r, jacobian| {
            for (i, (c, radius)) in circles.iter().enumerate() {
                let dx = x[0] - c[0];
                let dy = x[1] - c[1];
                r[i] = dx * dx + dy * dy - radius * radius;
            }
            if let Some(j) = jacobian {
                for (i, (c, _)) in circles.iter().enumerate() {
                    j[(i, 0)] = 2.0 * (x[0] - c[0]);
                    j[(i, 1)] = 2.0 * (x[1] - c[1]);
                }
            }
        }
    }

    /// Linear equations `A·x − b = 0`.
    fn linear(
        a: DMatrix<f64>,
        b: DVector<f64>,
    ) -> impl FnMut(&DVector<f64>, &mut DVector<f64>, Option<&mut DMatrix<f64>>) {
        move |x, r, jacobian| {
            r.copy_from(&(&a * x - &b));
            if let Some(j) = jacobian {
                j.copy_from(&a);
            }
        }
    }

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol
    }

    #[test]
    fn defaults() {
        let o = NewtonOptions::default();
        assert_eq!(o.max_iterations, 50);
        assert_eq!(o.tolerance, 1e-12);
        assert_eq!(o.rank_cutoff, 1e-10);
        assert_eq!(o.max_step, f64::INFINITY);
    }

    #[test]
    fn numeric_two_circles_converge_to_closed_form_root() {
        let (c1, r1): ([f64; 2], f64) = ([1.0, 2.0], 3.0);
        let (c2, r2): ([f64; 2], f64) = ([4.0, 6.0], 4.0);
        // Closed form: a along the centre line, h across it.
        let d = ((c2[0] - c1[0]) * (c2[0] - c1[0]) + (c2[1] - c1[1]) * (c2[1] - c1[1])).sqrt();
        let a = (d * d + r1 * r1 - r2 * r2) / (2.0 * d);
        let h = (r1 * r1 - a * a).sqrt();
        let u = [(c2[0] - c1[0]) / d, (c2[1] - c1[1]) / d];
        let roots = [
            [c1[0] + a * u[0] - h * u[1], c1[1] + a * u[1] + h * u[0]],
            [c1[0] + a * u[0] + h * u[1], c1[1] + a * u[1] - h * u[0]],
        ];
        // (4, 2) and (0.16, 4.88) by hand.
        assert!(close(roots[1][0], 4.0, 1e-12) && close(roots[1][1], 2.0, 1e-12));
        assert!(close(roots[0][0], 0.16, 1e-12) && close(roots[0][1], 4.88, 1e-12));

        for (root, start) in [(roots[1], [4.2, 1.7]), (roots[0], [0.0, 5.2])] {
            let mut sys = system(2, 2, circles(vec![(c1, r1), (c2, r2)]));
            let mut x = DVector::from_row_slice(&start);
            let rep = solve(&mut sys, &mut x, &NewtonOptions::default());
            assert_eq!(rep.outcome, NewtonOutcome::Converged, "{rep:?}");
            assert!(rep.residual <= 1e-12);
            assert!((2..=6).contains(&rep.iterations), "{rep:?}");
            assert_eq!(rep.rank, 2);
            assert!(
                close(x[0], root[0], 1e-12) && close(x[1], root[1], 1e-12),
                "{x:?} vs {root:?}"
            );
        }
    }

    #[test]
    fn numeric_converged_warm_start_costs_no_iteration() {
        let mut sys = system(2, 2, circles(vec![([1.0, 2.0], 3.0), ([4.0, 6.0], 4.0)]));
        let mut x = DVector::from_row_slice(&[4.0, 2.0]);
        let rep = solve(&mut sys, &mut x, &NewtonOptions::default());
        assert_eq!(
            rep,
            NewtonReport {
                outcome: NewtonOutcome::Converged,
                iterations: 0,
                residual: 0.0,
                rank: 0
            }
        );
    }

    #[test]
    fn numeric_underdetermined_linear_takes_min_norm_step() {
        // x0 + 2·x1 = 5: the solution nearest the origin is (1, 2)·5/5.
        let mut sys = system(
            2,
            1,
            linear(
                DMatrix::from_row_slice(1, 2, &[1.0, 2.0]),
                DVector::from_row_slice(&[5.0]),
            ),
        );
        let mut x = DVector::zeros(2);
        let rep = solve(&mut sys, &mut x, &NewtonOptions::default());
        assert_eq!(rep.outcome, NewtonOutcome::Converged);
        assert_eq!(rep.iterations, 1);
        assert_eq!(rep.rank, 1);
        assert!(close(x[0], 1.0, 1e-14) && close(x[1], 2.0, 1e-14), "{x:?}");

        // From elsewhere the motion is orthogonal to the line: from (3, −1),
        // the projection onto x0 + 2·x1 = 5 is (3, −1) + (1, 2)·(5 − 1)/5.
        let mut sys = system(
            2,
            1,
            linear(
                DMatrix::from_row_slice(1, 2, &[1.0, 2.0]),
                DVector::from_row_slice(&[5.0]),
            ),
        );
        let mut x = DVector::from_row_slice(&[3.0, -1.0]);
        let rep = solve(&mut sys, &mut x, &NewtonOptions::default());
        assert_eq!(rep.outcome, NewtonOutcome::Converged);
        assert!(close(x[0], 3.8, 1e-14) && close(x[1], 0.6, 1e-14), "{x:?}");
    }

    #[test]
    fn numeric_underdetermined_circle_moves_radially() {
        // A point on x² + y² = 4 nearest the warm start.
        for (start, expected) in [
            ([3.0, 0.0], [2.0, 0.0]),
            ([3.0, 4.0], [1.2, 1.6]),
            (
                [-0.5, 0.2],
                [-2.0 * 0.5 / 0.29f64.sqrt(), 2.0 * 0.2 / 0.29f64.sqrt()],
            ),
        ] {
            let mut sys = system(2, 1, circles(vec![([0.0, 0.0], 2.0)]));
            let mut x = DVector::from_row_slice(&start);
            let rep = solve(&mut sys, &mut x, &NewtonOptions::default());
            assert_eq!(rep.outcome, NewtonOutcome::Converged, "{rep:?}");
            assert_eq!(rep.rank, 1);
            assert!(
                close(x[0], expected[0], 1e-12) && close(x[1], expected[1], 1e-12),
                "{x:?} vs {expected:?}"
            );
        }
    }

    #[test]
    fn numeric_overdetermined_consistent_converges() {
        // Three lines through (1, 2).
        let a = DMatrix::from_row_slice(3, 2, &[1.0, 1.0, 1.0, -1.0, 2.0, 1.0]);
        let b = DVector::from_row_slice(&[3.0, -1.0, 4.0]);
        let mut sys = system(2, 3, linear(a, b));
        let mut x = DVector::zeros(2);
        let rep = solve(&mut sys, &mut x, &NewtonOptions::default());
        assert_eq!(rep.outcome, NewtonOutcome::Converged, "{rep:?}");
        assert_eq!(rep.rank, 2);
        assert_eq!(rep.iterations, 1);
        assert!(close(x[0], 1.0, 1e-14) && close(x[1], 2.0, 1e-14), "{x:?}");

        // Three circles through (1, 1).
        let mut sys = system(
            2,
            3,
            circles(vec![
                ([0.0, 0.0], 2f64.sqrt()),
                ([4.0, 0.0], 10f64.sqrt()),
                ([0.0, 3.0], 5f64.sqrt()),
            ]),
        );
        let mut x = DVector::from_row_slice(&[1.3, 0.8]);
        let rep = solve(&mut sys, &mut x, &NewtonOptions::default());
        assert_eq!(rep.outcome, NewtonOutcome::Converged, "{rep:?}");
        assert_eq!(rep.rank, 2);
        assert!(close(x[0], 1.0, 1e-12) && close(x[1], 1.0, 1e-12), "{x:?}");
    }

    #[test]
    fn numeric_inconsistent_linear_reaches_least_squares_point() {
        // x = 1 and x = 2: least squares at 1.5, residual |(0.5, −0.5)|.
        let mut sys = system(
            1,
            2,
            linear(
                DMatrix::from_row_slice(2, 1, &[1.0, 1.0]),
                DVector::from_row_slice(&[1.0, 2.0]),
            ),
        );
        let mut x = DVector::zeros(1);
        let rep = solve(&mut sys, &mut x, &NewtonOptions::default());
        assert_eq!(rep.outcome, NewtonOutcome::NoSolution, "{rep:?}");
        assert!(close(rep.residual, 0.5f64.sqrt(), 1e-14), "{rep:?}");
        assert!(close(x[0], 1.5, 1e-14), "{x:?}");
        assert_eq!(rep.rank, 1);
        assert!(rep.iterations <= 2, "{rep:?}");
    }

    /// Distance-form circle equations `|p − c_i| − r_i = 0`.
    fn distance_circles(
        circles: Vec<([f64; 2], f64)>,
    ) -> impl FnMut(&DVector<f64>, &mut DVector<f64>, Option<&mut DMatrix<f64>>) {
        move |x, r, mut jacobian| {
            for (i, (c, radius)) in circles.iter().enumerate() {
                let dx = x[0] - c[0];
                let dy = x[1] - c[1];
                let rho = (dx * dx + dy * dy).sqrt();
                r[i] = rho - radius;
                if let Some(j) = jacobian.as_deref_mut() {
                    j[(i, 0)] = dx / rho;
                    j[(i, 1)] = dy / rho;
                }
            }
        }
    }

    #[test]
    fn numeric_circles_that_do_not_meet_end_on_the_centre_segment() {
        // Centres 5 apart, radii 1 and 2: the gap of 2 is shared equally by
        // the two distance residuals, so the least-squares point lies on the
        // centre segment at distance 2 from c1, with residual |(1, 1)| = √2.
        let c1 = [1.0, 1.0];
        let c2 = [4.0, 5.0];
        let expected = [c1[0] + 2.0 * 0.6, c1[1] + 2.0 * 0.8];
        for start in [
            [3.0, 3.0],
            [2.2, 2.0],
            [0.0, 4.0],
            [expected[0], expected[1] + 1e-3],
        ] {
            let mut sys = system(2, 2, distance_circles(vec![(c1, 1.0), (c2, 2.0)]));
            let mut x = DVector::from_row_slice(&start);
            let rep = solve(&mut sys, &mut x, &NewtonOptions::default());
            assert_eq!(rep.outcome, NewtonOutcome::NoSolution, "from {start:?}: {rep:?}");
            // The stagnation rule stops on the flat floor of the minimum
            // after a bounded number of iterations: the residual is then
            // right to ~1e-11 and the point (which moves the residual only
            // quadratically) to a few 1e-6.
            assert!(close(rep.residual, 2f64.sqrt(), 1e-9), "from {start:?}: {rep:?}");
            // Distance from the centre line (through c1 along (0.6, 0.8)).
            let off_line = ((x[0] - c1[0]) * 0.8 - (x[1] - c1[1]) * 0.6).abs();
            assert!(
                off_line < 1e-4,
                "from {start:?}: {x:?} is {off_line} off the line"
            );
            assert!(
                close(x[0], expected[0], 1e-4) && close(x[1], expected[1], 1e-4),
                "from {start:?}: {x:?}"
            );
        }

        // Squared form, equal radii: the midpoint by symmetry, residual
        // |(1.25, 1.25)|.
        let mut sys = system(2, 2, circles(vec![([0.0, 0.0], 1.0), ([3.0, 0.0], 1.0)]));
        let mut x = DVector::from_row_slice(&[1.0, 0.0]);
        let rep = solve(&mut sys, &mut x, &NewtonOptions::default());
        assert_eq!(rep.outcome, NewtonOutcome::NoSolution, "{rep:?}");
        assert!(close(rep.residual, 1.25 * 2f64.sqrt(), 1e-12), "{rep:?}");
        // The residual is flat at a least-squares minimum (it changes by
        // O(e²) for an error e), so the point is located to about √ε only.
        assert!(close(x[0], 1.5, 1e-6) && x[1] == 0.0, "{x:?}");
        assert_eq!(rep.rank, 1);
    }

    #[test]
    fn numeric_rank_deficient_jacobian_converges() {
        // The same line twice: min-norm solution of x + y = 3 from the
        // origin is (1.5, 1.5).
        let a = DMatrix::from_row_slice(2, 2, &[1.0, 1.0, 1.0, 1.0]);
        let b = DVector::from_row_slice(&[3.0, 3.0]);
        let mut sys = system(2, 2, linear(a, b));
        let mut x = DVector::zeros(2);
        let rep = solve(&mut sys, &mut x, &NewtonOptions::default());
        assert_eq!(rep.outcome, NewtonOutcome::Converged, "{rep:?}");
        assert_eq!(rep.rank, 1);
        assert!(close(x[0], 1.5, 1e-14) && close(x[1], 1.5, 1e-14), "{x:?}");

        // The same circle twice: radial motion onto it.
        let mut sys = system(2, 2, circles(vec![([0.0, 0.0], 10.0), ([0.0, 0.0], 10.0)]));
        let mut x = DVector::from_row_slice(&[3.0, 4.0]);
        let rep = solve(&mut sys, &mut x, &NewtonOptions::default());
        assert_eq!(rep.outcome, NewtonOutcome::Converged, "{rep:?}");
        assert_eq!(rep.rank, 1);
        assert!(close(x[0], 6.0, 1e-12) && close(x[1], 8.0, 1e-12), "{x:?}");
    }

    #[test]
    fn numeric_iteration_budget_gives_not_converged() {
        let mut sys = system(2, 2, circles(vec![([1.0, 2.0], 3.0), ([4.0, 6.0], 4.0)]));
        let mut x = DVector::from_row_slice(&[6.0, 0.0]);
        let options = NewtonOptions {
            max_iterations: 1,
            ..NewtonOptions::default()
        };
        let rep = solve(&mut sys, &mut x, &options);
        assert_eq!(rep.outcome, NewtonOutcome::NotConverged, "{rep:?}");
        assert_eq!(rep.iterations, 1);
        assert!(rep.residual > 1e-12);
        // It did move, to a better point.
        let mut r = DVector::zeros(2);
        circles(vec![([1.0, 2.0], 3.0), ([4.0, 6.0], 4.0)])(
            &DVector::from_row_slice(&[6.0, 0.0]),
            &mut r,
            None,
        );
        assert!(rep.residual < r.norm());

        // Zero budget: no Jacobian at all.
        let mut x = DVector::from_row_slice(&[6.0, 0.0]);
        let options = NewtonOptions {
            max_iterations: 0,
            ..NewtonOptions::default()
        };
        let rep = solve(&mut sys, &mut x, &options);
        assert_eq!(rep.outcome, NewtonOutcome::NotConverged);
        assert_eq!(rep.iterations, 0);
        assert_eq!(x, DVector::from_row_slice(&[6.0, 0.0]));
    }

    #[test]
    fn numeric_slow_progress_is_not_converged_not_no_solution() {
        // x² = 0 has a double root: Newton halves x each step, so reaching
        // |r| = x² ≤ 1e-12 from x = 1 takes 20 steps (2⁻⁴⁰ ≈ 9.1e-13 but
        // 2⁻³⁸ ≈ 3.6e-12). Slow, but never stuck.
        let square = |x: &DVector<f64>, r: &mut DVector<f64>, j: Option<&mut DMatrix<f64>>| {
            r[0] = x[0] * x[0];
            if let Some(j) = j {
                j[(0, 0)] = 2.0 * x[0];
            }
        };
        let mut sys = system(1, 1, square);
        let mut x = DVector::from_row_slice(&[1.0]);
        let options = NewtonOptions {
            max_iterations: 5,
            ..NewtonOptions::default()
        };
        let rep = solve(&mut sys, &mut x, &options);
        assert_eq!(rep.outcome, NewtonOutcome::NotConverged, "{rep:?}");
        assert_eq!(rep.iterations, 5);
        assert_eq!(x[0], 1.0 / 32.0);

        let mut x = DVector::from_row_slice(&[1.0]);
        let rep = solve(&mut sys, &mut x, &NewtonOptions::default());
        assert_eq!(rep.outcome, NewtonOutcome::Converged, "{rep:?}");
        assert_eq!(rep.iterations, 20);
        assert_eq!(x[0], 2f64.powi(-20));
    }

    #[test]
    fn numeric_line_search_rescues_divergent_newton() {
        // Plain Newton on atan(x) = 0 diverges from |x| ≳ 1.39; the
        // backtracking brings it home to the root 0.
        let atan = |x: &DVector<f64>, r: &mut DVector<f64>, j: Option<&mut DMatrix<f64>>| {
            r[0] = x[0].atan();
            if let Some(j) = j {
                j[(0, 0)] = 1.0 / (1.0 + x[0] * x[0]);
            }
        };
        for (start, max_step) in [
            (1.5, f64::INFINITY),
            (10.0, f64::INFINITY),
            (-30.0, f64::INFINITY),
            (10.0, 1.0),
        ] {
            let mut sys = system(1, 1, atan);
            let mut x = DVector::from_row_slice(&[start]);
            let options = NewtonOptions {
                max_step,
                ..NewtonOptions::default()
            };
            let rep = solve(&mut sys, &mut x, &options);
            assert_eq!(rep.outcome, NewtonOutcome::Converged, "from {start}: {rep:?}");
            assert!(x[0].abs() <= 1e-12, "from {start}: {x:?}");
        }
    }

    #[test]
    fn numeric_max_step_limits_the_step() {
        // Full step from the origin is (1, 2); max-norm 0.5 scales it by 1/4.
        let mut sys = system(
            2,
            1,
            linear(
                DMatrix::from_row_slice(1, 2, &[1.0, 2.0]),
                DVector::from_row_slice(&[5.0]),
            ),
        );
        let mut x = DVector::zeros(2);
        let options = NewtonOptions {
            max_iterations: 1,
            max_step: 0.5,
            ..NewtonOptions::default()
        };
        let rep = solve(&mut sys, &mut x, &options);
        assert_eq!(rep.outcome, NewtonOutcome::NotConverged);
        assert!(close(x[0], 0.25, 1e-15) && close(x[1], 0.5, 1e-15), "{x:?}");
        assert!(close(rep.residual, 5.0 - 1.25, 1e-14), "{rep:?}");

        // With enough budget it still gets there, in 4 steps.
        let mut x = DVector::zeros(2);
        let options = NewtonOptions {
            max_step: 0.5,
            ..NewtonOptions::default()
        };
        let rep = solve(&mut sys, &mut x, &options);
        assert_eq!(rep.outcome, NewtonOutcome::Converged);
        assert_eq!(rep.iterations, 4);
        assert!(close(x[0], 1.0, 1e-14) && close(x[1], 2.0, 1e-14), "{x:?}");
    }

    #[test]
    fn numeric_nan_residual_is_no_solution() {
        // NaN everywhere.
        let mut sys = system(
            2,
            1,
            |_: &DVector<f64>, r: &mut DVector<f64>, _: Option<&mut DMatrix<f64>>| r[0] = f64::NAN,
        );
        let mut x = DVector::from_row_slice(&[1.0, 2.0]);
        let rep = solve(&mut sys, &mut x, &NewtonOptions::default());
        assert_eq!(rep.outcome, NewtonOutcome::NoSolution);
        assert_eq!(rep.residual, f64::INFINITY);
        assert_eq!(x, DVector::from_row_slice(&[1.0, 2.0]));

        // NaN only in the Jacobian.
        let mut sys = system(
            1,
            1,
            |x: &DVector<f64>, r: &mut DVector<f64>, j: Option<&mut DMatrix<f64>>| {
                r[0] = x[0] - 1.0;
                if let Some(j) = j {
                    j[(0, 0)] = f64::NAN;
                }
            },
        );
        let mut x = DVector::from_row_slice(&[3.0]);
        let rep = solve(&mut sys, &mut x, &NewtonOptions::default());
        assert_eq!(rep.outcome, NewtonOutcome::NoSolution);
        assert_eq!(rep.iterations, 1);
        assert_eq!(x[0], 3.0);

        // NaN at the first trials: ln(x) = 0 from x = 10 overshoots to
        // negative x (NaN) and the line search backs off.
        let mut sys = system(
            1,
            1,
            |x: &DVector<f64>, r: &mut DVector<f64>, j: Option<&mut DMatrix<f64>>| {
                r[0] = x[0].ln();
                if let Some(j) = j {
                    j[(0, 0)] = 1.0 / x[0];
                }
            },
        );
        let mut x = DVector::from_row_slice(&[10.0]);
        let rep = solve(&mut sys, &mut x, &NewtonOptions::default());
        assert_eq!(rep.outcome, NewtonOutcome::Converged, "{rep:?}");
        assert!(close(x[0], 1.0, 1e-12), "{x:?}");

        // Infinite residual everywhere but the warm start: the best finite
        // point is kept.
        let mut sys = system(
            1,
            1,
            |x: &DVector<f64>, r: &mut DVector<f64>, j: Option<&mut DMatrix<f64>>| {
                r[0] = if x[0] == 3.0 { 1.0 } else { f64::INFINITY };
                if let Some(j) = j {
                    j[(0, 0)] = 1.0;
                }
            },
        );
        let mut x = DVector::from_row_slice(&[3.0]);
        let rep = solve(&mut sys, &mut x, &NewtonOptions::default());
        assert_eq!(rep.outcome, NewtonOutcome::NoSolution);
        assert_eq!(rep.residual, 1.0);
        assert_eq!(x[0], 3.0);
    }

    #[test]
    fn numeric_zero_unknowns_or_equations() {
        let noop = |_: &DVector<f64>, _: &mut DVector<f64>, _: Option<&mut DMatrix<f64>>| {};
        // No equations: converged where it stands.
        let mut sys = system(2, 0, noop);
        let mut x = DVector::from_row_slice(&[1.0, 2.0]);
        let rep = solve(&mut sys, &mut x, &NewtonOptions::default());
        assert_eq!(
            rep,
            NewtonReport {
                outcome: NewtonOutcome::Converged,
                iterations: 0,
                residual: 0.0,
                rank: 0
            }
        );
        assert_eq!(x, DVector::from_row_slice(&[1.0, 2.0]));

        // Nothing at all.
        let mut sys = system(0, 0, noop);
        let mut x = DVector::zeros(0);
        let rep = solve(&mut sys, &mut x, &NewtonOptions::default());
        assert_eq!(rep.outcome, NewtonOutcome::Converged);

        // No unknowns, satisfied equation.
        let mut sys = system(
            0,
            1,
            |_: &DVector<f64>, r: &mut DVector<f64>, _: Option<&mut DMatrix<f64>>| r[0] = 0.0,
        );
        let mut x = DVector::zeros(0);
        let rep = solve(&mut sys, &mut x, &NewtonOptions::default());
        assert_eq!(rep.outcome, NewtonOutcome::Converged);

        // No unknowns, violated equations.
        let mut sys = system(
            0,
            2,
            |_: &DVector<f64>, r: &mut DVector<f64>, _: Option<&mut DMatrix<f64>>| {
                r[0] = 3.0;
                r[1] = 4.0;
            },
        );
        let mut x = DVector::zeros(0);
        let rep = solve(&mut sys, &mut x, &NewtonOptions::default());
        assert_eq!(
            rep,
            NewtonReport {
                outcome: NewtonOutcome::NoSolution,
                iterations: 0,
                residual: 5.0,
                rank: 0
            }
        );

        // The free functions on empty matrices.
        assert_eq!(rank(&DMatrix::zeros(0, 3), 1e-10), 0);
        assert_eq!(rank(&DMatrix::zeros(3, 0), 1e-10), 0);
        let (step, r) = min_norm_step(&DMatrix::zeros(0, 3), &DVector::zeros(0), 1e-10);
        assert_eq!((step, r), (DVector::zeros(3), 0));
        let (step, r) = min_norm_step(
            &DMatrix::zeros(2, 0),
            &DVector::from_row_slice(&[1.0, 2.0]),
            1e-10,
        );
        assert_eq!((step.len(), r), (0, 0));
    }

    #[test]
    fn numeric_solver_is_reusable_across_sizes() {
        let mut newton = Newton::new(1, 1);
        let mut sys = system(
            2,
            1,
            linear(
                DMatrix::from_row_slice(1, 2, &[1.0, 2.0]),
                DVector::from_row_slice(&[5.0]),
            ),
        );
        let mut x = DVector::zeros(2);
        assert_eq!(
            newton.solve(&mut sys, &mut x, &NewtonOptions::default()).outcome,
            NewtonOutcome::Converged
        );
        let mut sys = system(
            1,
            2,
            linear(
                DMatrix::from_row_slice(2, 1, &[1.0, 1.0]),
                DVector::from_row_slice(&[2.0, 2.0]),
            ),
        );
        let mut x = DVector::zeros(1);
        assert_eq!(
            newton.solve(&mut sys, &mut x, &NewtonOptions::default()).outcome,
            NewtonOutcome::Converged
        );
        assert!(close(x[0], 2.0, 1e-14));
    }

    #[test]
    fn numeric_rank_of_small_matrices() {
        let m = |r, c, v: &[f64]| DMatrix::from_row_slice(r, c, v);
        assert_eq!(rank(&m(2, 2, &[1.0, 0.0, 0.0, 1.0]), 1e-10), 2);
        assert_eq!(rank(&m(2, 2, &[1.0, 2.0, 2.0, 4.0]), 1e-10), 1);
        assert_eq!(rank(&m(2, 2, &[0.0, 0.0, 0.0, 0.0]), 1e-10), 0);
        // Relative cut-off: 1e-12 is zero next to 1, but not with a finer
        // cut-off, and scaling the whole matrix changes nothing.
        assert_eq!(rank(&m(2, 2, &[1.0, 0.0, 0.0, 1e-12]), 1e-10), 1);
        assert_eq!(rank(&m(2, 2, &[1.0, 0.0, 0.0, 1e-12]), 1e-14), 2);
        assert_eq!(rank(&m(2, 2, &[1e-20, 0.0, 0.0, 2e-20]), 1e-10), 2);
        assert_eq!(rank(&m(2, 2, &[1e20, 0.0, 0.0, 2e20]), 1e-10), 2);
        // Third row = first + second.
        assert_eq!(
            rank(&m(3, 3, &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 5.0, 7.0, 9.0]), 1e-10),
            2
        );
        // Wide and tall.
        assert_eq!(rank(&m(2, 3, &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]), 1e-10), 2);
        assert_eq!(rank(&m(2, 3, &[1.0, 2.0, 3.0, 2.0, 4.0, 6.0]), 1e-10), 1);
        assert_eq!(rank(&m(3, 2, &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]), 1e-10), 2);
        assert_eq!(rank(&m(1, 4, &[0.0, 0.0, 3.0, 0.0]), 1e-10), 1);
        // Non-finite: rank 0, no hang.
        assert_eq!(rank(&m(2, 2, &[1.0, f64::NAN, 0.0, 1.0]), 1e-10), 0);
        assert_eq!(rank(&m(2, 2, &[1.0, f64::INFINITY, 0.0, 1.0]), 1e-10), 0);
        // Odd cut-offs.
        assert_eq!(rank(&m(2, 2, &[1.0, 0.0, 0.0, 1e-100]), -1.0), 2);
        assert_eq!(rank(&m(2, 2, &[1.0, 0.0, 0.0, 1.0]), f64::NAN), 2);
        assert_eq!(rank(&m(2, 2, &[1.0, 0.0, 0.0, 1.0]), f64::INFINITY), 0);
    }

    #[test]
    fn numeric_min_norm_step_of_small_matrices() {
        let m = |r, c, v: &[f64]| DMatrix::from_row_slice(r, c, v);
        let v = |s: &[f64]| DVector::from_row_slice(s);
        let near = |a: &DVector<f64>, b: &[f64]| {
            a.len() == b.len() && a.iter().zip(b).all(|(x, y)| close(*x, *y, 1e-14))
        };

        // Square regular: the Newton step. J = [[2, 0], [0, 4]], r = (2, −4).
        let (d, r) = min_norm_step(&m(2, 2, &[2.0, 0.0, 0.0, 4.0]), &v(&[2.0, -4.0]), 1e-10);
        assert!(near(&d, &[-1.0, 1.0]) && r == 2, "{d:?}");
        // Wide: x0 + 2·x1 = 5 → (1, 2).
        let (d, r) = min_norm_step(&m(1, 2, &[1.0, 2.0]), &v(&[-5.0]), 1e-10);
        assert!(near(&d, &[1.0, 2.0]) && r == 1, "{d:?}");
        // Wide with an untouched unknown: it is not moved.
        let (d, r) = min_norm_step(
            &m(2, 3, &[1.0, 0.0, 0.0, 0.0, 1.0, 0.0]),
            &v(&[-1.0, -2.0]),
            1e-10,
        );
        assert!(near(&d, &[1.0, 2.0, 0.0]) && r == 2, "{d:?}");
        // Tall inconsistent: least squares.
        let (d, r) = min_norm_step(&m(2, 1, &[1.0, 1.0]), &v(&[-1.0, -2.0]), 1e-10);
        assert!(near(&d, &[1.5]) && r == 1, "{d:?}");
        // Rank deficient: the duplicate row adds nothing; min norm (1, 1).
        let (d, r) = min_norm_step(&m(2, 2, &[1.0, 1.0, 1.0, 1.0]), &v(&[-2.0, -2.0]), 1e-10);
        assert!(near(&d, &[1.0, 1.0]) && r == 1, "{d:?}");
        // Nearly singular below the cut-off: the weak direction is dropped
        // instead of amplified (1e-12 would give a step of 1e12).
        let (d, r) = min_norm_step(&m(2, 2, &[1.0, 0.0, 0.0, 1e-12]), &v(&[-1.0, -1.0]), 1e-10);
        assert!(near(&d, &[1.0, 0.0]) && r == 1, "{d:?}");
        // Zero matrix and non-finite input: zero step.
        let (d, r) = min_norm_step(&m(2, 2, &[0.0; 4]), &v(&[1.0, 1.0]), 1e-10);
        assert!(near(&d, &[0.0, 0.0]) && r == 0, "{d:?}");
        let (d, r) = min_norm_step(&m(2, 2, &[f64::NAN, 0.0, 0.0, 1.0]), &v(&[1.0, 1.0]), 1e-10);
        assert!(near(&d, &[0.0, 0.0]) && r == 0, "{d:?}");
        let (d, r) = min_norm_step(&m(2, 2, &[1.0, 0.0, 0.0, 1.0]), &v(&[f64::NAN, 1.0]), 1e-10);
        assert!(near(&d, &[0.0, 0.0]) && r == 0, "{d:?}");
    }

    #[test]
    fn numeric_min_norm_step_of_general_wide_and_tall_matrices() {
        // Wide, full row rank: δ = −Jᵀ(J·Jᵀ)⁻¹·r, computed here with an
        // explicit 3×3 inverse (LU), independently of the SVD.
        let j = DMatrix::from_row_slice(
            3,
            7,
            &[
                1.0, -2.0, 0.5, 3.0, 0.0, 1.5, -1.0, //
                0.0, 1.0, 4.0, -1.0, 2.0, 0.0, 0.5, //
                2.0, 0.0, -1.0, 1.0, 1.0, -3.0, 2.0,
            ],
        );
        let r = DVector::from_row_slice(&[0.3, -1.2, 2.5]);
        let expected = -(j.transpose() * (&j * j.transpose()).try_inverse().unwrap() * &r);
        let (d, rank_j) = min_norm_step(&j, &r, 1e-10);
        assert_eq!(rank_j, 3);
        assert!((&d - &expected).amax() < 1e-13, "{d:?} vs {expected:?}");
        assert!((&j * &d + &r).amax() < 1e-13);

        // Tall, full column rank: normal equations δ = −(JᵀJ)⁻¹Jᵀ·r.
        let jt = j.transpose();
        let r7 = DVector::from_row_slice(&[1.0, -0.5, 0.25, 2.0, -1.0, 0.0, 3.0]);
        let expected = -((jt.transpose() * &jt).try_inverse().unwrap() * jt.transpose() * &r7);
        let (d, rank_jt) = min_norm_step(&jt, &r7, 1e-10);
        assert_eq!(rank_jt, 3);
        assert!((&d - &expected).amax() < 1e-12, "{d:?} vs {expected:?}");

        // Wide, rank deficient (third row = first + second): the result has
        // no null-space component, i.e. it lies in the row space and is the
        // min-norm solution of the two independent rows.
        let mut jd = j.clone();
        let sum = jd.row(0) + jd.row(1);
        jd.row_mut(2).copy_from(&sum);
        let r = DVector::from_row_slice(&[0.3, -1.2, 0.3 - 1.2]);
        let (d, rank_jd) = min_norm_step(&jd, &r, 1e-10);
        assert_eq!(rank_jd, 2);
        let j2 = jd.rows(0, 2).into_owned();
        let r2 = r.rows(0, 2).into_owned();
        let expected = -(j2.transpose() * (&j2 * j2.transpose()).try_inverse().unwrap() * &r2);
        assert!((&d - &expected).amax() < 1e-12, "{d:?} vs {expected:?}");
        assert_eq!(rank(&jd, 1e-10), 2);
    }
}
