//! Tests of Newton–Raphson and of the rank decisions.

use nalgebra::{DMatrix, DVector};

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
    circles(vec![([1.0, 2.0], 3.0), ([4.0, 6.0], 4.0)])(&DVector::from_row_slice(&[6.0, 0.0]), &mut r, None);
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

/// The rates' linear solve, `−J⁺·f`, against the pseudo-inverse on wide,
/// square and tall Jacobians, well conditioned (through the Cholesky
/// factor) and not (through the SVD), and infinite where `J` has lost rank.
#[test]
fn implicit_rates_are_the_minimum_norm_least_squares_motion() {
    let entry = |i: usize, j: usize| ((i * 7 + j * 13) % 11) as f64 - 5.0 + 0.3 * (i as f64) * (j as f64);
    for (m, n) in [(2, 3), (4, 4), (5, 3), (2, 6)] {
        for conditioning in [1.0, 1e-4] {
            let mut j = DMatrix::from_fn(m, n, entry);
            // Scale the last row (wide) or column (tall) down: a poorly
            // conditioned Jacobian, not yet singular.
            if m <= n {
                j.row_mut(m - 1).scale_mut(conditioning);
            } else {
                j.column_mut(n - 1).scale_mut(conditioning);
            }
            // A consistent right-hand side for the tall case.
            let f = if m > n {
                &j * DVector::from_fn(n, |i, _| 1.0 + i as f64)
            } else {
                DVector::from_fn(m, |i, _| 0.5 - i as f64)
            };
            let expect = -(pseudo_inverse(&j, 1e-14) * &f);
            let got = Implicit::new(&j).solve(&f);
            assert!(
                (&got - &expect).norm() <= 1e-9 * expect.norm(),
                "{m}x{n} at {conditioning}: {got} vs {expect}"
            );
        }
    }
    // Rank lost: a row the sum of two others.
    let mut j = DMatrix::from_fn(3, 4, entry);
    let sum = j.row(0) + j.row(1);
    j.row_mut(2).copy_from(&sum);
    let implicit = Implicit::new(&j);
    assert!(implicit.singular());
    assert!(implicit
        .solve(&DVector::from_element(3, 1.0))
        .iter()
        .all(|x| x.is_infinite()));
}

#[test]
fn lu_solves_with_pivoting_and_refuses_a_singular_matrix() {
    use super::lu_solve;
    // [[0, 2], [3, 1]] y = [4, 5]: y = (1, 2), the first pivot zero.
    let (mut a, mut b) = ([0.0, 2.0, 3.0, 1.0], [4.0, 5.0]);
    assert!(lu_solve(&mut a, &mut b, 2));
    assert!((b[0] - 1.0).abs() < 1e-15 && (b[1] - 2.0).abs() < 1e-15, "{b:?}");
    let (mut a, mut b) = ([1.0, 2.0, 2.0, 4.0], [1.0, 1.0]);
    assert!(!lu_solve(&mut a, &mut b, 2));
}
