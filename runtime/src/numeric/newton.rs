//! Newton–Raphson with the minimum-norm least-squares step: the solver,
//! its options and report, and the [`Equations`] it solves.

use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim, DimMin, DimMinimum, DimSub, Dyn, OMatrix, OVector, U1};

use super::linalg::{full_rank_step, NewtonAllocator, Spectrum};
use super::{Const, SMatrix, SVector};

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

/// The share of the residual left in the range of the Jacobian below which
/// the residual counts as orthogonal to it (a least-squares minimum).
const STATIONARY: f64 = 1e-6;

/// Iterations over which a residual that does not halve counts as stagnant.
const STAGNATION_WINDOW: usize = 6;

/// Iterations before the stagnation rule applies.
const STAGNATION_AFTER: u32 = 12;

/// A step is negligible when `‖δ‖ ≤ NEGLIGIBLE_STEP · (1 + ‖x‖)`: it could
/// not change `x` in floating point.
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

            let Some((step_rank, spectrum)) = self.min_norm_step(options.rank_cutoff) else {
                // A non-finite Jacobian (or an SVD that did not converge):
                // no direction to go.
                return report(NewtonOutcome::NoSolution, iterations, residual, 0);
            };
            rank = step_rank;
            let mut limit = options.max_step;
            if self.orthogonal_to_range(residual)
                || stagnant(&mut history, iterations, residual)
                || !clamp(&mut self.step, &mut limit)
                || self.negligible(x)
            {
                return report(NewtonOutcome::NoSolution, iterations, residual, rank);
            }
            match self.line_search(system, x, options.rank_cutoff, spectrum, limit, residual) {
                Some(accepted) => residual = accepted,
                // Every trial is a descent direction for ‖r‖² whenever
                // Jᵀ·r ≠ 0; if not even a tiny one helps, the residual is at
                // a least-squares minimum (to rounding).
                None => return report(NewtonOutcome::NoSolution, iterations, residual, rank),
            }
            if residual <= options.tolerance {
                return report(NewtonOutcome::Converged, iterations, residual, rank);
            }
        }
    }

    /// The minimum-norm step `δ = −J⁺·r` at the current point into `step`,
    /// with the Jacobian's numerical rank and, when the step needed it, the
    /// SVD's spectrum (kept to damp a rejected step). `None` when the
    /// Jacobian gives no direction: non-finite, or an SVD that did not
    /// converge.
    #[inline]
    fn min_norm_step(&mut self, rank_cutoff: f64) -> Option<(usize, Option<Spectrum<R, C>>)> {
        // The SVD is only needed when the Jacobian is not of full rank
        // and well conditioned (or to damp a rejected step): otherwise
        // the minimum-norm step is the same through a Cholesky solve of
        // the (much cheaper) normal equations.
        match full_rank_step(&self.jacobian, &self.r, &mut self.step) {
            Some(full) => Some((full, None)),
            None => {
                let s = Spectrum::new(&self.jacobian, &self.r, rank_cutoff)?;
                s.min_norm(&self.r, &mut self.step);
                Some((s.rank, Some(s)))
            }
        }
    }

    /// Whether the residual (of norm `residual`) is numerically orthogonal
    /// to the range of the Jacobian: a least-squares minimum above the
    /// tolerance.
    ///
    /// J·δ is minus the part of r in the range of J; this tests whether that
    /// part is a vanishing share of r. Far from the solution Gauss–Newton
    /// only creeps toward such a minimum, so waiting for a negligible step
    /// would use up the budget and report "not converged" where the truth is
    /// "no solution within reach".
    #[inline]
    fn orthogonal_to_range(&self, residual: f64) -> bool {
        let in_range = (&self.jacobian * &self.step).norm();
        in_range <= STATIONARY * residual
    }

    /// Whether the step could not change `x` in floating point. For the
    /// full step, J⁺·r ≈ 0 means Jᵀ·r ≈ 0: the gradient of ‖r‖² vanishes,
    /// so this is a least-squares minimum above the tolerance.
    #[inline]
    fn negligible(&self, x: &OVector<f64, C>) -> bool {
        self.step.norm() <= NEGLIGIBLE_STEP * (1.0 + x.norm())
    }

    /// Backtracking on the residual norm (`residual` at `x`): the full
    /// min-norm step, then ever more damped ones (see `Spectrum::damped`).
    /// On the first trial that decreases the residual enough, moves `x`
    /// there and returns its residual; `None` when none does.
    #[inline]
    fn line_search<E: Equations<R, C>>(
        &mut self,
        system: &mut E,
        x: &mut OVector<f64, C>,
        rank_cutoff: f64,
        mut spectrum: Option<Spectrum<R, C>>,
        mut limit: f64,
        residual: f64,
    ) -> Option<f64> {
        let target = residual * (1.0 - MIN_DECREASE);
        for trial in 0..MAX_TRIALS {
            if trial > 0 && !self.damp(x, rank_cutoff, &mut spectrum, trial, &mut limit) {
                break;
            }
            self.trial.copy_from(x);
            self.trial += &self.step;
            system.eval(&self.trial, &mut self.r_trial, None);
            let trial_residual = self.r_trial.norm();
            // `<` is false for NaN, so a non-finite trial is rejected.
            if trial_residual < target {
                x.copy_from(&self.trial);
                std::mem::swap(&mut self.r, &mut self.r_trial);
                return Some(trial_residual);
            }
        }
        None
    }

    /// The step of line-search trial `trial` (from 1): each singular
    /// component damped with `λ = σ_min²·(2ʲ − 1)`, then clamped to `limit`.
    /// The spectrum is computed here if the full step did without it. False
    /// when no further trial is worth making: no spectrum, a damping that
    /// has shrunk even the strongest component below `2^-MAX_HALVINGS`, or a
    /// step that is not finite or negligible.
    #[inline]
    fn damp(
        &mut self,
        x: &OVector<f64, C>,
        rank_cutoff: f64,
        spectrum: &mut Option<Spectrum<R, C>>,
        trial: i32,
        limit: &mut f64,
    ) -> bool {
        if spectrum.is_none() {
            *spectrum = Spectrum::new(&self.jacobian, &self.r, rank_cutoff);
        }
        let Some(sp) = spectrum.as_ref() else { return false };
        let low = sp.smallest();
        let lambda_limit = sp.largest().powi(2) * 2f64.powi(MAX_HALVINGS);
        let lambda = low * low * (2f64.powi(trial) - 1.0);
        if lambda > lambda_limit {
            return false;
        }
        sp.damped(lambda, &mut self.step);
        clamp(&mut self.step, limit) && !self.negligible(x)
    }
}

/// Records `residual` for iteration `iterations` in the window `history`
/// and tells whether the iteration has stagnated.
///
/// Once past the first iterations (where a far warm start may need
/// line-search steps), a residual that has not halved over the last few
/// iterations is creeping toward a least-squares minimum, not toward zero:
/// convergence to a solution, even a singular one (a change point), at
/// least halves it every iteration. Telling the two apart is what Brunkhart
/// (§5.1) found hard; this is the rule we use.
#[inline]
fn stagnant(history: &mut [f64; STAGNATION_WINDOW], iterations: u32, residual: f64) -> bool {
    let slot = iterations as usize % STAGNATION_WINDOW;
    let old = history[slot];
    history[slot] = residual;
    iterations >= STAGNATION_AFTER && residual > 0.5 * old
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
