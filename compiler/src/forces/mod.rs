//! Forces from the plan: what each input must supply for a mechanism to
//! hold, or to run at a given speed, under its masses, gravity and loads
//! (`[loads.NAME]`, `model::loads`), and what each joint carries.
//!
//! Input forces by virtual work with the plan's exact rates: the input
//! force `Q_i` is minus the power every load (and, running, every body's
//! d'Alembert inertia) delivers per unit rate of input `i`, the others
//! held; the derivatives are the plan's own (`Interpreter::rates`), not
//! differences. One pass of the plan's rates per input and one for the
//! motion itself.
//!
//! Joint reactions from every moving body's force and moment equilibrium:
//! one linear system per frame in the joints' reaction components (those
//! each joint kind can carry) and the inputs' forces, solved by least
//! squares (`least_norm`): least norm where the mechanism is
//! over-constrained, which then names the joints whose share is not
//! fixed. Each dimension builds its system (`planar.rs`, `spatial.rs`).

pub mod plan;
pub mod planar;
pub mod spatial;

use nalgebra::{DMatrix, DVector};

use crate::interp::RateError;
use crate::model::{Input, InputKind};

/// Each input's generalised force by virtual work, in either dimension:
/// `rates(r)` runs the plan's rates at input rates `r` (the frame's own
/// motion when `actual` is given), `power(v, a)` is the power the loads
/// (and with `a`, the bodies' d'Alembert inertia) deliver at the virtual
/// motion `v`; the force is minus that power per unit rate of the input.
pub(crate) fn by_virtual_work<P>(
    inputs: &[Input],
    actual: Option<(&[f64], &[f64])>,
    rates: impl Fn(&[f64], &[f64]) -> Result<Vec<P>, RateError>,
    power: impl Fn(&[P], Option<&[P]>) -> f64,
) -> Result<Vec<f64>, RateError> {
    let zero = vec![0.0; inputs.len()];
    let actual = match actual {
        Some((r, a)) => Some(rates(r, a)?),
        None => None,
    };
    (0..inputs.len())
        .map(|i| {
            // A unit of the input per second: a radian (in degrees) for an
            // angle, so that the derivatives are per radian.
            let mut unit = zero.clone();
            unit[i] = match inputs[i].kind {
                InputKind::Angle => 1f64.to_degrees(),
                InputKind::Slide => 1.0,
            };
            let virtual_ = rates(&unit, &zero)?;
            Ok(-power(&virtual_, actual.as_deref()))
        })
        .collect()
}

/// The least-norm solution of `a x = -w`, with how well it holds and which
/// unknowns it fixes.
pub(crate) struct Solved {
    /// The solution.
    pub x: DVector<f64>,
    /// The largest component of `a x + w` (round-off where the system can
    /// be met).
    pub residual: f64,
    /// Per unknown: whether the equations fix it (its axis lies in the
    /// matrix's row space), rather than leave it to a choice.
    pub fixed: Vec<bool>,
}

/// Solves `a x = -w` by the SVD, least norm and least squares.
pub(crate) fn least_norm(a: &DMatrix<f64>, w: &DVector<f64>) -> Solved {
    let (rows, cols) = a.shape();
    let svd = a.clone().svd(true, true);
    let largest = svd.singular_values.iter().copied().fold(0.0f64, f64::max);
    let tol = largest * 1e-10 * rows.max(cols) as f64;
    // Both factors were asked for, so the solve cannot fail; zeros (and
    // the residual saying so) if it ever did.
    let x = svd.solve(&(-w), tol).unwrap_or_else(|_| DVector::zeros(cols));
    let residual = if rows == 0 { 0.0 } else { (a * &x + w).amax() };
    // An unknown is fixed by the equations when its axis lies in the
    // matrix's row space (the right singular vectors of non-zero singular
    // values); otherwise some other solution moves it.
    let fixed: Vec<bool> = match &svd.v_t {
        Some(v_t) => (0..cols)
            .map(|c| {
                let inside: f64 = (0..v_t.nrows())
                    .filter(|&k| svd.singular_values[k] > tol)
                    .map(|k| v_t[(k, c)] * v_t[(k, c)])
                    .sum();
                inside > 1.0 - 1e-9
            })
            .collect(),
        None => vec![false; cols],
    };
    Solved { x, residual, fixed }
}
