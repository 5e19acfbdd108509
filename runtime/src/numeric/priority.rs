//! Task priority: a system whose equations are split into a **first task**
//! held exactly (a mechanism's joints) and a **second task** met as well as
//! the first allows (a drag: a marker pulled toward a target).
//!
//! When the second task can be met, the solve ends *converged*. When it
//! cannot (a target out of reach), the answer wanted is the **closest
//! approach**: the first task exact and the second's residual at its
//! least-squares minimum over the poses the first allows. That is an
//! outcome in its own right ([`NewtonOutcome::NoSolution`], a converged
//! least-squares minimum), distinct from running out of iterations.
//!
//! Two phases, because the closest approach of a mechanism is typically a
//! *singular* pose: a chain pulled toward a target beyond its reach ends
//! straight, where the Jacobian of the second task in the first's null space
//! loses rank exactly in the direction the residual points to.
//!
//! 1. **Gauss–Newton task priority** (the classic scheme, cheap, with
//!    minimum-norm motion for an under-constrained mechanism):
//!
//!    ```text
//!    δ₁ = −J₁⁺ r₁          meet the first task (minimum-norm)
//!    N  = I − J₁⁺ J₁       the motions the first task allows
//!    δ  = δ₁ + N (J₂ N)⁺ (−r₂ − J₂ δ₁)
//!    ```
//!
//!    It converges fast to a zero residual. Toward a least-squares minimum
//!    with a residual left it does not: Gauss–Newton ignores the curvature
//!    `r₂·∇²r₂` that makes that minimum a minimum, so near a straight chain
//!    its step along the weak direction is the residual divided by a
//!    vanishing singular value. Once the residual stops halving with the
//!    first task met, phase 2 takes over.
//! 2. **Second-order closest approach**, on poses where the first task holds
//!    (each trial step is pulled back onto them by minimum-norm Newton on
//!    the first task alone, so every iterate is a pose that could be
//!    shown): Newton on the reduced problem
//!    `min ½‖r₂‖²  subject to  r₁ = 0`, with
//!
//!    ```text
//!    Z   an orthonormal basis of the null space of J₁
//!    g   = Zᵀ J₂ᵀ r₂                      the reduced gradient
//!    μ   = −(J₁ᵀ)⁺ J₂ᵀ r₂                 the first task's multipliers
//!    B   = Zᵀ ∇²(½‖r₂‖² + μᵀ r₁) Z        the reduced Hessian of the Lagrangian
//!    s   = −(B + λI)⁻¹ g,  δ = Z s
//!    ```
//!
//!    `B` comes from central differences of the Lagrangian's gradient
//!    `Jᵀ[μ; r₂]` along the columns of `Z` (the systems here give analytic
//!    first derivatives only). With the exact curvature the step converges
//!    quadratically to the closest approach, singular or not, where
//!    damping alone (Levenberg–Marquardt on `J₂ Z`) would only creep: the
//!    reduced Hessian of a straight chain under a pull spreads over a wide
//!    range (the bending modes of a string under tension), and one damping
//!    factor cannot suit them all. `λ` is a Levenberg–Marquardt shift, zero
//!    while `B` is positive definite and the steps do what the model
//!    predicts, raised to keep the step a descent when `B` is indefinite
//!    (far from the minimum) or the model is poor.
//!
//!    The closest approach is certified, not guessed: the reduced gradient
//!    vanishes (the residual is orthogonal to every motion the first task
//!    allows) and `B` has no negative curvature. At a stationary point with
//!    negative curvature (a chain pulled straight *away* from its target, a
//!    maximum) the solve steps along the curvature's direction instead.

use nalgebra::{DMatrix, DVector, SymmetricEigen};

use super::{null_space, pseudo_inverse, Equations, Newton, NewtonOptions, NewtonOutcome, NewtonReport};

/// What a prioritised solve reports.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PriorityReport {
    /// How it ended, the Jacobian evaluations of the iterations (not those
    /// of the differences for the curvature), the **second task's**
    /// residual norm at the point left in `x`, and the rank of the first
    /// task's Jacobian there.
    ///
    /// - [`Converged`](NewtonOutcome::Converged): both tasks met;
    /// - [`NoSolution`](NewtonOutcome::NoSolution): the first task met and
    ///   the second at a least-squares minimum over the poses the first
    ///   allows — the closest approach;
    /// - [`NotConverged`](NewtonOutcome::NotConverged): the budget ran out,
    ///   or the first task could not be met (see `first`).
    pub newton: NewtonReport,
    /// The first task's residual norm at the point left in `x`: at most
    /// the tolerance unless the first task could not be met at all.
    pub first: f64,
}

/// The reduced gradient counts as zero (a stationary point) below this
/// share of `‖J₂‖·‖r₂‖`: at most the cosine of the angle between the
/// residual and the motions allowed. Phase 2 converges quadratically, so this is met to
/// spare well before rounding.
const STATIONARY: f64 = 1e-11;

/// Between a rounding-level stall and a closest approach: a reduced
/// gradient this small (same measure as [`STATIONARY`]) at a point no step
/// can improve is a least-squares minimum to rounding.
const STALLED: f64 = 1e-7;

/// Curvature below `−CURVATURE × ‖B‖` is negative (a saddle or a maximum,
/// not a closest approach).
const CURVATURE: f64 = 1e-9;

/// Directions of the shifted reduced Hessian whose eigenvalue is at or below
/// this share of its largest are left out of the step (as the rank cut-off
/// does for a pseudo-inverse): an under-constrained mechanism near a zero
/// residual has directions neither task cares about, and they stay put.
const EIGEN_CUTOFF: f64 = 1e-12;

/// The Levenberg–Marquardt shift (relative to `‖B‖`) above which no step
/// is tried any more: the point is a minimum to rounding.
const MAX_DAMPING: f64 = 1e12;

/// Iterations of phase 2 that improve the residual by less than the
/// tolerance and the reduced gradient by less than half before the point
/// counts as the least-squares minimum (to the tolerance).
const STALL_ITERATIONS: u32 = 3;

/// A change of ½‖r₂‖² within this share of it is rounding.
const ROUNDING: f64 = 1e-10;

/// Iterations of the Newton solve that pulls a trial point back onto the
/// first task.
const RESTORE_ITERATIONS: u32 = 20;

/// Solves `system` by task priority from the warm start `x`: its first
/// `first` equations are the first task, the others the second. `options`
/// gives the tolerance (both tasks), the rank cut-off, the largest step
/// (max-norm) and the iteration budget of each phase.
///
/// `x` is left at the best point found where the first task holds; when it
/// holds nowhere tried, at the warm start. `system` may be left evaluated
/// elsewhere: evaluate (or apply) `x` afterwards.
///
/// # Panics
///
/// If `x.len() != system.unknowns()` or `first > system.equations()`.
pub fn solve<E: Equations>(
    system: &mut E,
    first: usize,
    x: &mut DVector<f64>,
    options: &NewtonOptions,
) -> PriorityReport {
    let (n, m) = (system.unknowns(), system.equations());
    assert_eq!(
        x.len(),
        n,
        "priority::solve: x has {} entries, the system {n} unknowns",
        x.len()
    );
    assert!(first <= m, "priority::solve: {first} first-task rows of {m}");
    let mut w = Work {
        first,
        r: DVector::zeros(m),
        j: DMatrix::zeros(m, n),
        restore: Newton::new(n, first),
    };
    let start = x.clone();
    let mut iterations = 0;
    let mut best: Option<(DVector<f64>, f64)> = None;
    let outcome = gauss_newton(system, &mut w, x, options, &mut iterations, &mut best);
    let outcome = if outcome == NewtonOutcome::Converged {
        outcome
    } else {
        // Phase 2 from the last iterate pulled back onto the first task,
        // or the best pose phase 1 met it at if that is closer, or the warm
        // start.
        let mut feasible = w.restore(system, x, options);
        if let Some((b, d)) = best {
            if !feasible || w.eval(system, x, false).1 > d {
                *x = b;
                feasible = true;
            }
        }
        if !feasible {
            x.copy_from(&start);
            feasible = w.restore(system, x, options);
        }
        if feasible {
            closest(system, &mut w, x, options, &mut iterations)
        } else {
            x.copy_from(&start);
            NewtonOutcome::NotConverged
        }
    };
    let (first_residual, second) = w.eval(system, x, true);
    let jc = w.j.rows(0, first).into_owned();
    let (null, _) = Basis::of(&jc, options.rank_cutoff);
    PriorityReport {
        newton: NewtonReport {
            outcome,
            iterations,
            residual: second,
            rank: n - null.ncols(),
        },
        first: first_residual,
    }
}

/// Buffers and the pull-back solver.
struct Work {
    first: usize,
    r: DVector<f64>,
    j: DMatrix<f64>,
    restore: Newton,
}

impl Work {
    /// Evaluates at `x`: the two tasks' residual norms.
    fn eval<E: Equations>(&mut self, system: &mut E, x: &DVector<f64>, jacobian: bool) -> (f64, f64) {
        system.eval(x, &mut self.r, jacobian.then_some(&mut self.j));
        let k = self.first;
        let first = self.r.rows(0, k).norm();
        let second = self.r.rows(k, self.r.len() - k).norm();
        (first, second)
    }

    /// Pulls `x` onto the first task by minimum-norm Newton (the least
    /// motion that closes it); whether it holds there.
    fn restore<E: Equations>(
        &mut self,
        system: &mut E,
        x: &mut DVector<f64>,
        options: &NewtonOptions,
    ) -> bool {
        let mut task = FirstTask {
            system,
            first: self.first,
            r: DVector::zeros(self.r.len()),
            j: DMatrix::zeros(self.r.len(), x.len()),
        };
        let options = NewtonOptions {
            max_iterations: RESTORE_ITERATIONS,
            ..*options
        };
        self.restore.solve(&mut task, x, &options).outcome == NewtonOutcome::Converged
    }
}

/// The first task alone, as a system for Newton.
struct FirstTask<'a, E> {
    system: &'a mut E,
    first: usize,
    r: DVector<f64>,
    j: DMatrix<f64>,
}

impl<E: Equations> Equations for FirstTask<'_, E> {
    fn unknowns(&self) -> usize {
        self.system.unknowns()
    }
    fn equations(&self) -> usize {
        self.first
    }
    fn eval(&mut self, x: &DVector<f64>, r: &mut DVector<f64>, jacobian: Option<&mut DMatrix<f64>>) {
        let k = self.first;
        match jacobian {
            Some(j) => {
                self.system.eval(x, &mut self.r, Some(&mut self.j));
                j.copy_from(&self.j.rows(0, k));
            }
            None => self.system.eval(x, &mut self.r, None),
        }
        r.copy_from(&self.r.rows(0, k));
    }
}

/// Phase 1 (see the module's doc). Ends converged, or hands over: the
/// residual stopped halving with the first task met, the budget ran out,
/// or a value was not finite. Offers every point where the first task
/// holds to `best`.
fn gauss_newton<E: Equations>(
    system: &mut E,
    w: &mut Work,
    x: &mut DVector<f64>,
    options: &NewtonOptions,
    iterations: &mut u32,
    best: &mut Option<(DVector<f64>, f64)>,
) -> NewtonOutcome {
    let (n, k) = (x.len(), w.first);
    let s = w.r.len() - k;
    let tolerance = options.tolerance;
    let mut previous = f64::INFINITY;
    let mut rc = DVector::zeros(k);
    for iteration in 0..=options.max_iterations {
        let (joints, drag) = w.eval(system, x, true);
        *iterations = iteration;
        if !joints.is_finite() || !drag.is_finite() {
            return NewtonOutcome::NotConverged;
        }
        if joints <= tolerance {
            if best.as_ref().is_none_or(|(_, d)| drag < *d) {
                *best = Some((x.clone(), drag));
            }
            if drag <= tolerance {
                return NewtonOutcome::Converged;
            }
        }
        // Not even halving after a full step: Gauss–Newton is creeping
        // toward a least-squares minimum (see the module's doc), or fighting
        // a singular pose. Phase 2 finds the minimum.
        if drag > previous {
            return NewtonOutcome::NoSolution;
        }
        if iteration == options.max_iterations {
            break;
        }
        let jc = w.j.rows(0, k).into_owned();
        let jd = w.j.rows(k, s).into_owned();
        rc.copy_from(&w.r.rows(0, k));
        let rd = w.r.rows(k, s).into_owned();
        let jc_pinv = pseudo_inverse(&jc, options.rank_cutoff);
        let step_joints = -(&jc_pinv * &rc);
        let null = DMatrix::identity(n, n) - &jc_pinv * &jc;
        let along = &jd * &null;
        let wanted = -rd - &jd * &step_joints;
        let mut step = step_joints + &null * (pseudo_inverse(&along, options.rank_cutoff) * wanted);
        let largest = step.amax();
        let clamped = largest > options.max_step;
        if clamped {
            step *= options.max_step / largest;
        }
        // A step cut to the step limit makes a fixed progress: only an
        // uncut one is expected to halve the residual.
        previous = if clamped { 0.9 * drag } else { 0.5 * drag };
        // Keep the first task: near a singular pose the linearised null
        // space lets a full step open it. Halve the step until it stays
        // within what it was (or a share of the step); failing that, only
        // restore it.
        let allowed = (2.0 * joints).max(0.05 * step.norm()).max(tolerance);
        let mut accepted = false;
        for _ in 0..30 {
            let trial = &*x + &step;
            w.eval(system, &trial, false);
            if w.r.rows(0, k).norm() <= allowed {
                *x = trial;
                accepted = true;
                break;
            }
            step *= 0.5;
        }
        if !accepted {
            *x -= &jc_pinv * &rc;
        }
    }
    NewtonOutcome::NotConverged
}

/// Phase 2 (see the module's doc), from a point where the first task holds.
fn closest<E: Equations>(
    system: &mut E,
    w: &mut Work,
    x: &mut DVector<f64>,
    options: &NewtonOptions,
    iterations: &mut u32,
) -> NewtonOutcome {
    let mut phase = Closest {
        damping: 0.0,
        trial: x.clone(),
        previous: (f64::INFINITY, f64::INFINITY),
        stalled: 0,
    };
    for _ in 0..options.max_iterations {
        let local = Local::at(system, w, x, options);
        *iterations += 1;
        if local.drag <= options.tolerance {
            return NewtonOutcome::Converged;
        }
        if local.z.ncols() == 0 {
            // Nothing the first task lets move: the pose is the answer.
            return NewtonOutcome::NoSolution;
        }
        if phase.flat(local.drag, local.cosine, options.tolerance) {
            return NewtonOutcome::NoSolution;
        }
        let curvature = Curvature::at(system, w, x, &local);

        // The residual is known to about the tolerance, so its direction
        // (hence the cosine) only to tolerance/‖r₂‖: the floor of both tests.
        let floor = options.tolerance / local.drag;
        if local.cosine <= STATIONARY + floor {
            if curvature.lowest >= -CURVATURE * curvature.scale {
                return NewtonOutcome::NoSolution;
            }
            if !phase.leave_saddle(system, w, x, options, &local, &curvature) {
                return NewtonOutcome::NoSolution;
            }
            continue;
        }
        if !phase.damped_newton(system, w, x, options, &local, &curvature) {
            return if local.cosine <= STALLED + floor {
                NewtonOutcome::NoSolution
            } else {
                NewtonOutcome::NotConverged
            };
        }
    }
    NewtonOutcome::NotConverged
}

/// What phase 2 carries from one iteration to the next.
struct Closest {
    /// The Levenberg–Marquardt shift, relative to `‖B‖`.
    damping: f64,
    /// The trial point (a buffer).
    trial: DVector<f64>,
    /// The previous iteration's residual norm and cosine.
    previous: (f64, f64),
    /// Iterations in a row that left the minimum flat (see [`Closest::flat`]).
    stalled: u32,
}

impl Closest {
    /// Whether the minimum is too flat to resolve, given this iteration's
    /// residual norm `drag` and `cosine` (see [`Local`]).
    ///
    /// A target out of reach by less than about the step the curvature
    /// can be resolved at (a chain all but straight at the edge of its
    /// reach) leaves a minimum so flat that the differenced curvature is
    /// noise: the residual then improves by less than the tolerance
    /// while the reduced gradient wanders. Within the tolerance that is
    /// the least-squares minimum.
    fn flat(&mut self, drag: f64, cosine: f64, tolerance: f64) -> bool {
        if self.previous.0 - drag <= tolerance && cosine > 0.5 * self.previous.1 {
            self.stalled += 1;
            if self.stalled >= STALL_ITERATIONS {
                return true;
            }
        } else {
            self.stalled = 0;
        }
        self.previous = (drag, cosine);
        false
    }

    /// At a stationary point with negative curvature (a saddle or a
    /// maximum): leaves it along the negative curvature, either way (both
    /// descend to second order). Whether either way lowered the residual
    /// (`x` moved there).
    fn leave_saddle<E: Equations>(
        &mut self,
        system: &mut E,
        w: &mut Work,
        x: &mut DVector<f64>,
        options: &NewtonOptions,
        local: &Local,
        curvature: &Curvature,
    ) -> bool {
        let length = if options.max_step.is_finite() && options.max_step > 0.0 {
            0.1 * options.max_step
        } else {
            1e-3 * (1.0 + x.amax())
        };
        let mut direction = &local.z * curvature.eigen.eigenvectors.column(curvature.low_at);
        direction *= length / direction.amax();
        for sign in [1.0, -1.0] {
            self.trial.copy_from(x);
            self.trial.axpy(sign, &direction, 1.0);
            if w.restore(system, &mut self.trial, options)
                && w.eval(system, &self.trial, false).1 < local.drag
            {
                x.copy_from(&self.trial);
                return true;
            }
        }
        false
    }

    /// Damped Newton trials: the shift keeps B + λI positive definite,
    /// the damping grows while the model promises more than the pose
    /// delivers. Whether a trial was accepted (`x` moved there).
    fn damped_newton<E: Equations>(
        &mut self,
        system: &mut E,
        w: &mut Work,
        x: &mut DVector<f64>,
        options: &NewtonOptions,
        local: &Local,
        curvature: &Curvature,
    ) -> bool {
        let (lowest, scale) = (curvature.lowest, curvature.scale);
        let f0 = 0.5 * local.drag * local.drag;
        if lowest < 0.0 {
            self.damping = self.damping.max(1e-3);
        }
        while self.damping <= MAX_DAMPING {
            let lambda = (-lowest).max(0.0) + self.damping * scale;
            let mut reduced = curvature.shifted_step(&local.g, lambda, local.z.ncols());
            let mut step = &local.z * &reduced;
            let longest = step.amax();
            if longest > options.max_step {
                let cut = options.max_step / longest;
                step *= cut;
                reduced *= cut;
            }
            if longest <= f64::EPSILON * (1.0 + x.amax()) {
                // No step can move the pose: a minimum to rounding.
                return false;
            }
            let predicted = -(local.g.dot(&reduced) + 0.5 * reduced.dot(&(&curvature.b * &reduced)));
            self.trial.copy_from(x);
            self.trial += &step;
            if w.restore(system, &mut self.trial, options) {
                let f = 0.5 * w.eval(system, &self.trial, false).1.powi(2);
                let gain = f0 - f;
                // Close to the minimum the change of ½‖r₂‖² is of the
                // order of the step squared, below its rounding: judge the
                // step by the reduced gradient (first order) instead.
                let better = if gain.abs() <= ROUNDING * f0 {
                    Local::at(system, w, &self.trial, options).cosine < 0.5 * local.cosine
                } else {
                    gain > 0.0 && (predicted <= 0.0 || gain >= 1e-4 * predicted)
                };
                if better {
                    x.copy_from(&self.trial);
                    if predicted > 0.0 && gain >= 0.75 * predicted {
                        self.damping = if self.damping < 1e-10 {
                            0.0
                        } else {
                            self.damping / 4.0
                        };
                    }
                    return true;
                }
            }
            self.damping = (4.0 * self.damping).max(1e-8);
        }
        false
    }
}

/// The second-order picture at a point where the first task holds: the
/// reduced Hessian of the Lagrangian and its eigen-decomposition.
struct Curvature {
    /// The reduced Hessian B.
    b: DMatrix<f64>,
    /// Its eigenvalues and eigenvectors.
    eigen: SymmetricEigen<f64, nalgebra::Dyn>,
    /// Its lowest eigenvalue, and that eigenvalue's index.
    lowest: f64,
    low_at: usize,
    /// ‖B‖ (or ‖J₂ Z‖² when larger): what the shift and the cut-offs are
    /// relative to.
    scale: f64,
}

impl Curvature {
    /// The curvature at `x`, whose first-order picture is `local`.
    fn at<E: Equations>(system: &mut E, w: &mut Work, x: &DVector<f64>, local: &Local) -> Curvature {
        let grad = local.jd.tr_mul(&local.rd);
        let mu = -local.multipliers.solve(&grad);
        let b = reduced_hessian(system, w, x, &local.z, &mu);
        let eigen = SymmetricEigen::new(b.clone());
        let (lowest, low_at) =
            eigen
                .eigenvalues
                .iter()
                .enumerate()
                .fold(
                    (f64::INFINITY, 0),
                    |acc, (i, &v)| if v < acc.0 { (v, i) } else { acc },
                );
        let largest = eigen.eigenvalues.amax();
        let scale = largest.max(local.a.norm_squared()).max(f64::MIN_POSITIVE);
        Curvature {
            b,
            eigen,
            lowest,
            low_at,
            scale,
        }
    }

    /// The reduced step `s = −(B + λI)⁻¹ g` (of length `n`), over the
    /// eigen-directions whose shifted eigenvalue is above the cut-off.
    fn shifted_step(&self, g: &DVector<f64>, lambda: f64, n: usize) -> DVector<f64> {
        let coefficients = self.eigen.eigenvectors.tr_mul(g);
        let mut reduced = DVector::zeros(n);
        for (i, &value) in self.eigen.eigenvalues.iter().enumerate() {
            let shifted = value + lambda;
            if shifted > EIGEN_CUTOFF * self.scale {
                reduced.axpy(
                    -coefficients[i] / shifted,
                    &self.eigen.eigenvectors.column(i),
                    1.0,
                );
            }
        }
        reduced
    }
}

/// The first-order picture at a point where the first task holds.
struct Local {
    /// ‖r₂‖.
    drag: f64,
    /// J₂, r₂.
    jd: DMatrix<f64>,
    rd: DVector<f64>,
    /// The null space of J₁ (orthonormal columns).
    z: DMatrix<f64>,
    /// Solves `J₁ᵀ μ = v` in the least-squares sense.
    multipliers: Basis,
    /// J₂ Z.
    a: DMatrix<f64>,
    /// The reduced gradient Zᵀ J₂ᵀ r₂.
    g: DVector<f64>,
    /// ‖g‖ / (‖J₂‖ ‖r₂‖): how far from stationary, scale-free.
    cosine: f64,
}

impl Local {
    fn at<E: Equations>(system: &mut E, w: &mut Work, x: &DVector<f64>, options: &NewtonOptions) -> Local {
        let (_, drag) = w.eval(system, x, true);
        let (k, s) = (w.first, w.r.len() - w.first);
        let jc = w.j.rows(0, k).into_owned();
        let jd = w.j.rows(k, s).into_owned();
        let rd = w.r.rows(k, s).into_owned();
        let (z, multipliers) = Basis::of(&jc, options.rank_cutoff);
        let a = &jd * &z;
        let g = a.tr_mul(&rd);
        // Measured against the marker's own Jacobian, not `J₂ Z`: a marker
        // the first task holds still (a pivot) has `J₂ Z ≈ 0`, and is
        // stationary, not undecided.
        let cosine = g.norm() / (jd.norm() * drag).max(f64::MIN_POSITIVE);
        Local {
            drag,
            jd,
            rd,
            z,
            multipliers,
            a,
            g,
            cosine,
        }
    }
}

/// What the null space of the first task's Jacobian was found from, kept
/// to solve for its multipliers.
enum Basis {
    /// A Householder QR of `J₁ᵀ` whose diagonal spans at most 1e5: `J₁` has
    /// full row rank, and the columns of the full `Q` beyond its rank span
    /// the null space. Several times cheaper than an SVD, which is what
    /// phase 2 would otherwise spend most of its time in.
    Qr(nalgebra::linalg::QR<f64, nalgebra::Dyn, nalgebra::Dyn>),
    /// Otherwise (redundant joints, a near-singular first task): the SVD's
    /// pseudo-inverse with the rank cut-off.
    Pseudo(DMatrix<f64>),
}

impl Basis {
    /// An orthonormal basis of the null space of `jc`, and how to solve for
    /// multipliers.
    fn of(jc: &DMatrix<f64>, rank_cutoff: f64) -> (DMatrix<f64>, Basis) {
        let (m, n) = jc.shape();
        if m > 0 && m < n && jc.iter().all(|v| v.is_finite()) {
            let qr = jc.transpose().qr();
            let r = qr.r();
            let diag = (0..m).map(|i| r[(i, i)].abs());
            let (lo, hi) = diag.fold((f64::INFINITY, 0.0_f64), |(lo, hi), d| (lo.min(d), hi.max(d)));
            if lo > 1e-5 * hi {
                let mut q_t = DMatrix::identity(n, n);
                qr.q_tr_mul(&mut q_t);
                let z = q_t.rows(m, n - m).transpose();
                return (z, Basis::Qr(qr));
            }
        }
        (
            null_space(jc, rank_cutoff),
            Basis::Pseudo(pseudo_inverse(jc, rank_cutoff)),
        )
    }

    /// The least-squares `μ` of `J₁ᵀ μ = v`.
    fn solve(&self, v: &DVector<f64>) -> DVector<f64> {
        match self {
            Basis::Qr(qr) => {
                let m = qr.r().nrows().min(qr.r().ncols());
                let mut qtv = v.clone();
                qr.q_tr_mul(&mut qtv);
                let r = qr.r();
                let upper = r.view((0, 0), (m, m));
                upper
                    .solve_upper_triangular(&qtv.rows(0, m))
                    .unwrap_or_else(|| DVector::zeros(m))
            }
            Basis::Pseudo(pinv) => pinv.tr_mul(v),
        }
    }
}

/// `Zᵀ ∇²L Z` for `L = ½‖r₂‖² + μᵀ r₁`, by central differences of
/// `∇L = Jᵀ [μ; r₂]` along each column of `Z`, symmetrised. The difference
/// step is the cube root of the machine epsilon relative to `x`, the
/// balance of truncation and rounding for central differences.
fn reduced_hessian<E: Equations>(
    system: &mut E,
    w: &mut Work,
    x: &DVector<f64>,
    z: &DMatrix<f64>,
    mu: &DVector<f64>,
) -> DMatrix<f64> {
    let k = w.first;
    let h = f64::EPSILON.cbrt() * (1.0 + x.amax());
    let dim = z.ncols();
    let mut gradient = |w: &mut Work, at: &DVector<f64>| -> DVector<f64> {
        w.eval(system, at, true);
        w.r.rows_mut(0, k).copy_from(mu);
        w.j.tr_mul(&w.r)
    };
    let mut b = DMatrix::zeros(dim, dim);
    let mut at = x.clone();
    for c in 0..dim {
        at.copy_from(x);
        at.axpy(h, &z.column(c), 1.0);
        let plus = gradient(w, &at);
        at.copy_from(x);
        at.axpy(-h, &z.column(c), 1.0);
        let minus = gradient(w, &at);
        b.set_column(c, &(z.tr_mul(&(plus - minus)) / (2.0 * h)));
    }
    (&b + b.transpose()) * 0.5
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two unit links pinned at the origin (absolute angles as unknowns,
    /// so the first task is empty) with their end pulled toward a point
    /// beyond reach: the closest approach is the straight pose toward it.
    struct TwoLinks {
        target: [f64; 2],
    }

    impl Equations for TwoLinks {
        fn unknowns(&self) -> usize {
            2
        }
        fn equations(&self) -> usize {
            2
        }
        fn eval(&mut self, x: &DVector<f64>, r: &mut DVector<f64>, jacobian: Option<&mut DMatrix<f64>>) {
            let (a, b) = (x[0], x[1]);
            r[0] = a.cos() + b.cos() - self.target[0];
            r[1] = a.sin() + b.sin() - self.target[1];
            if let Some(j) = jacobian {
                j[(0, 0)] = -a.sin();
                j[(0, 1)] = -b.sin();
                j[(1, 0)] = a.cos();
                j[(1, 1)] = b.cos();
            }
        }
    }

    fn options() -> NewtonOptions {
        NewtonOptions {
            max_iterations: 50,
            tolerance: 1e-12,
            rank_cutoff: 1e-10,
            max_step: 0.2,
        }
    }

    #[test]
    fn a_chain_pulled_out_of_reach_ends_straight_toward_the_target() {
        let target = [3.0, 4.0];
        let mut x = DVector::from_vec(vec![0.3, 1.4]);
        let report = solve(&mut TwoLinks { target }, 0, &mut x, &options());
        assert_eq!(report.newton.outcome, NewtonOutcome::NoSolution, "{report:?}");
        let toward = target[1].atan2(target[0]);
        assert!(
            (x[0] - toward).abs() < 1e-9 && (x[1] - toward).abs() < 1e-9,
            "{x}"
        );
        assert!((report.newton.residual - 3.0).abs() < 1e-12, "{report:?}");
    }

    #[test]
    fn a_target_in_reach_is_met() {
        let target = [1.2, 0.9];
        let mut x = DVector::from_vec(vec![0.3, 1.4]);
        let report = solve(&mut TwoLinks { target }, 0, &mut x, &options());
        assert_eq!(report.newton.outcome, NewtonOutcome::Converged, "{report:?}");
        assert!(report.newton.residual <= 1e-12);
    }

    #[test]
    fn a_chain_pulled_straight_away_from_its_target_turns_toward_it() {
        // Straight along +x, pulled toward (−3, 0): a stationary maximum.
        let target = [-3.0, 0.0];
        let mut x = DVector::from_vec(vec![0.0, 0.0]);
        let report = solve(&mut TwoLinks { target }, 0, &mut x, &options());
        assert_eq!(report.newton.outcome, NewtonOutcome::NoSolution, "{report:?}");
        assert!((report.newton.residual - 1.0).abs() < 1e-9, "{report:?}");
    }
}
