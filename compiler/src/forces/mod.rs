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

/// The unit rate of an input: a radian per second (in degrees) for an
/// angle, so that the derivatives are per radian; a length unit for a
/// slide.
fn unit_rate(input: &Input) -> f64 {
    match input.kind {
        InputKind::Angle => 1f64.to_degrees(),
        InputKind::Slide => 1.0,
    }
}

/// The mechanical advantage at a frame of a mechanism with one input:
/// what an ideal (frictionless, massless) mechanism gives out per unit of
/// what the input puts in, from the plan's exact rates.
#[derive(Clone, Debug, PartialEq)]
pub struct Advantage {
    /// Per joint (`None` for the driven joint, where the joint does not
    /// move with the input, or a spatial joint with more than one relative
    /// freedom): the torque (a turn) or force (a slide) it can hold per
    /// unit input torque or force, `|dq / dφ|` with `φ` the joint's
    /// relative turn or slide.
    pub joints: Vec<Option<f64>>,
    /// Per marker (`None` where it does not move with the input): the
    /// force it can exert along its path per unit input torque or force,
    /// `1 / |dP / dq|`.
    pub markers: Vec<Option<f64>>,
}

/// [`Advantage`] in either dimension, for a mechanism with exactly one
/// input (`None` otherwise): `rates(r)` runs the plan's rates at input
/// rate `r`; `joint_rate(v, j)` is joint `j`'s relative turn or slide rate
/// at the motion `v` with the scale below which it is round-off (`None`
/// for a joint without one); `marker_speeds(v)` every marker's speed.
/// `size` is the mechanism's, the scale of a length's rate.
pub(crate) fn mechanical_advantage<P>(
    inputs: &[Input],
    size: f64,
    rates: impl Fn(&[f64]) -> Result<Vec<P>, RateError>,
    joint_rates: impl Fn(&[P]) -> Vec<Option<(f64, f64)>>,
    marker_speeds: impl Fn(&[P]) -> Vec<f64>,
) -> Option<Result<Advantage, RateError>> {
    let [input] = inputs else {
        return None;
    };
    let v = match rates(&[unit_rate(input)]) {
        Ok(v) => v,
        Err(e) => return Some(Err(e)),
    };
    // A rate below round-off is no motion: relative to the mechanism's
    // size for a length, absolute for a turn (radians per radian).
    let inverse = |rate: f64, scale: f64| (rate.abs() > 1e-12 * scale).then(|| 1.0 / rate.abs());
    let joints = (joint_rates(&v).into_iter().enumerate())
        .map(|(j, rate)| {
            let (rate, scale) = rate?;
            if input.joint == j {
                return None;
            }
            inverse(rate, scale)
        })
        .collect();
    let markers = (marker_speeds(&v).into_iter())
        .map(|speed| inverse(speed, size))
        .collect();
    Some(Ok(Advantage { joints, markers }))
}

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
            let mut unit = zero.clone();
            unit[i] = unit_rate(&inputs[i]);
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
