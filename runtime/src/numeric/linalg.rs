//! The linear algebra of the numeric solver, all through one SVD with a
//! relative cut-off: rank, pseudo-inverse, null space, minimum-norm and
//! damped steps.

use nalgebra::allocator::Allocator;
use nalgebra::{
    DMatrix, DVector, DefaultAllocator, Dim, DimDiff, DimMin, DimMinimum, DimSub, OMatrix, OVector, SVD, U1,
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
pub(super) fn full_rank_step<R: DimMin<C>, C: Dim>(
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
pub(super) struct Spectrum<R: DimMin<C>, C: Dim>
where
    DimMinimum<R, C>: DimSub<U1>,
    DefaultAllocator: NewtonAllocator<R, C>,
{
    svd: SVD<f64, R, C>,
    /// Absolute singular-value threshold, `rank_cutoff × σ_max`.
    eps: f64,
    /// Number of singular values above `eps`.
    pub(super) rank: usize,
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
    pub(super) fn new(
        jacobian: &OMatrix<f64, R, C>,
        residual: &OVector<f64, R>,
        rank_cutoff: f64,
    ) -> Option<Self> {
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
    pub(super) fn min_norm(&self, residual: &OVector<f64, R>, step: &mut OVector<f64, C>) {
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
    pub(super) fn damped(&self, lambda: f64, step: &mut OVector<f64, C>) {
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
    pub(super) fn smallest(&self) -> f64 {
        let kept = self.svd.singular_values.iter().copied().filter(|&s| s > self.eps);
        kept.fold(f64::INFINITY, f64::min).min(self.largest())
    }

    /// Largest singular value.
    pub(super) fn largest(&self) -> f64 {
        self.svd.singular_values.iter().copied().fold(0.0, f64::max)
    }
}

/// Singular values at or below this share of the largest make a solved
/// cluster's Jacobian singular for its rates ([`Implicit`]). A rate grows
/// as the inverse of the smallest singular value, which near a dead point
/// vanishes as the square root of the distance to it: this is the closed
/// form's threshold for dead points (a squared half-chord of 1e-10 of the
/// squared radii), rates within about 1e5 of their scale.
pub const RATE_CUTOFF: f64 = 1e-5;

/// A solved cluster's Jacobian `J` factorised for its rates by the
/// implicit function theorem: [`solve`](Self::solve) gives `−J⁺·f`, the
/// minimum-norm least-squares motion of the unknowns that cancels a
/// residual rate `f` — the step the cluster's Newton takes, so an
/// under-constrained cluster moves by least motion and an over-constrained
/// consistent one by its independent rows. Of fixed size in generated code,
/// where it allocates nothing.
///
/// A well-conditioned `J` (the Cholesky factor of its Gram matrix with a
/// diagonal spanning at most 1e3, so `J` far from losing rank) is solved
/// through that factor, `J⁺ = Jᵀ(JJᵀ)⁻¹` or `(JᵀJ)⁻¹Jᵀ` (as Newton's full
/// rank steps); any other by the SVD. Where `J` has lost rank there (a
/// singular value at or below [`RATE_CUTOFF`] of the largest: the cluster
/// at a dead point, or an equation dependent on the others there only) the
/// rates are infinite, which the plan reports as singular rather than as
/// huge numbers.
pub struct Implicit<R: DimMin<C>, C: Dim>
where
    DimMinimum<R, C>: DimSub<U1>,
    DefaultAllocator: NewtonAllocator<R, C>,
{
    factor: Factor<R, C>,
    /// The number of unknowns.
    cols: C,
}

/// How [`Implicit`] solves.
enum Factor<R: DimMin<C>, C: Dim>
where
    DimMinimum<R, C>: DimSub<U1>,
    DefaultAllocator: NewtonAllocator<R, C>,
{
    /// A wide or square `J` and the Cholesky factor of `JJᵀ`.
    Wide(OMatrix<f64, R, C>, nalgebra::Cholesky<f64, R>),
    /// A tall `J` and the Cholesky factor of `JᵀJ`.
    Tall(OMatrix<f64, R, C>, nalgebra::Cholesky<f64, C>),
    /// The SVD and its absolute cut-off.
    Svd(SVD<f64, R, C>, f64),
    /// Rank lost.
    Singular,
}

impl<R: DimMin<C>, C: Dim> Implicit<R, C>
where
    DimMinimum<R, C>: DimSub<U1>,
    DefaultAllocator: NewtonAllocator<R, C>,
{
    /// The factorisation of `jacobian` (singular when it has lost rank).
    pub fn new(jacobian: &OMatrix<f64, R, C>) -> Self {
        let cols = C::from_usize(jacobian.ncols());
        let (m, n) = jacobian.shape();
        if m > 0 && n > 0 && jacobian.iter().all(|v| v.is_finite()) {
            if m <= n {
                if let Some(chol) = nalgebra::Cholesky::new(jacobian * jacobian.transpose()) {
                    if clear(chol.l_dirty()) {
                        let factor = Factor::Wide(jacobian.clone_owned(), chol);
                        return Implicit { factor, cols };
                    }
                }
            } else if let Some(chol) = nalgebra::Cholesky::new(jacobian.transpose() * jacobian) {
                if clear(chol.l_dirty()) {
                    let factor = Factor::Tall(jacobian.clone_owned(), chol);
                    return Implicit { factor, cols };
                }
            }
        }
        let factor = match decompose(jacobian, true) {
            Some(svd) => {
                let eps = threshold(&svd.singular_values, RATE_CUTOFF);
                let rank = svd.singular_values.iter().filter(|&&s| s > eps).count();
                if rank == m.min(n) {
                    Factor::Svd(svd, eps)
                } else {
                    Factor::Singular
                }
            }
            None => Factor::Singular,
        };
        Implicit { factor, cols }
    }

    /// Whether the Jacobian has lost rank.
    pub fn singular(&self) -> bool {
        matches!(self.factor, Factor::Singular)
    }

    /// `−J⁺·f`; infinite when the Jacobian is singular.
    pub fn solve(&self, f: &OVector<f64, R>) -> OVector<f64, C> {
        let infinite = || OVector::from_element_generic(self.cols, U1, f64::INFINITY);
        match &self.factor {
            Factor::Wide(j, chol) => -(j.tr_mul(&chol.solve(f))),
            Factor::Tall(j, chol) => -chol.solve(&j.tr_mul(f)),
            Factor::Svd(svd, eps) => svd.solve(f, *eps).map_or_else(|_| infinite(), |x| -x),
            Factor::Singular => infinite(),
        }
    }
}

/// Whether a Cholesky factor's diagonal spans at most 1e3: its matrix far
/// from losing rank, solved through the factor ([`Implicit`]).
fn clear<D: Dim>(l: &OMatrix<f64, D, D>) -> bool
where
    DefaultAllocator: Allocator<D, D>,
{
    let diag = (0..l.nrows()).map(|i| l[(i, i)].abs());
    let (lo, hi) = diag.fold((f64::INFINITY, 0.0_f64), |(lo, hi), d| (lo.min(d), hi.max(d)));
    lo > 1e-3 * hi
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

/// `a y = b` for the `k × k` row-major `a`, in place (`b` becomes `y`), by
/// LU with partial pivoting; `false` where `a` is singular to round-off
/// (a pivot below 1e-12 of its largest entry, or not a number).
///
/// The force plans' blocks are small (3 to 9 unknowns in the bundled
/// mechanisms) and solved every frame, so sizes up to 12 run a copy
/// compiled for their size: loops of known length, unrolled and without
/// bounds checks, which is most of a block solve's time saved. Every size
/// computes the same numbers the same way.
#[inline(always)]
pub fn lu_solve(a: &mut [f64], b: &mut [f64], k: usize) -> bool {
    // One unknown (most blocks of a force plan whose moments are taken
    // about pins): the same numbers as the elimination, without a call.
    if k == 1 {
        let p = a[0];
        if p.is_nan() || p == 0.0 {
            return false;
        }
        b[0] /= p;
        return b[0].is_finite();
    }
    lu_many(a, b, k)
}

/// [`lu_solve`] for two unknowns and more.
#[inline(never)]
fn lu_many(a: &mut [f64], b: &mut [f64], k: usize) -> bool {
    macro_rules! sized {
        ($($n:literal)*) => {
            match k {
                $($n => lu_sized::<$n>(&mut a[..$n * $n], &mut b[..$n]),)*
                _ => lu_any(a, b, k),
            }
        };
    }
    sized!(2 3 4 5 6 7 8 9 10 11 12)
}

/// [`lu_solve`] for a size known when compiled.
#[inline(always)]
fn lu_sized<const K: usize>(a: &mut [f64], b: &mut [f64]) -> bool {
    lu_any(a, b, K)
}

/// [`lu_solve`]'s elimination for any size `k`.
#[inline(always)]
fn lu_any(a: &mut [f64], b: &mut [f64], k: usize) -> bool {
    let (a, b) = (&mut a[..k * k], &mut b[..k]);
    let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for col in 0..k {
        let mut pivot = col;
        for r in col + 1..k {
            if a[r * k + col].abs() > a[pivot * k + col].abs() {
                pivot = r;
            }
        }
        let p = a[pivot * k + col];
        // A NaN pivot counts as singular too.
        if p.is_nan() || p.abs() <= 1e-12 * scale {
            return false;
        }
        if pivot != col {
            for c in 0..k {
                a.swap(pivot * k + c, col * k + c);
            }
            b.swap(pivot, col);
        }
        let inverse = 1.0 / p;
        for r in col + 1..k {
            let f = a[r * k + col] * inverse;
            // The blocks are sparse: most rows have nothing to eliminate.
            if f != 0.0 {
                for c in col..k {
                    a[r * k + c] -= f * a[col * k + c];
                }
                b[r] -= f * b[col];
            }
        }
    }
    for col in (0..k).rev() {
        let mut v = b[col];
        for c in col + 1..k {
            v -= a[col * k + c] * b[c];
        }
        b[col] = v / a[col * k + col];
    }
    b.iter().all(|v| v.is_finite())
}
