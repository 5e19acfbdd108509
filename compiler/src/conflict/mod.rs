//! Can a mechanism whose joints do not all hold in the drawn pose be
//! assembled at all? (Brunkhart §2.1.3–2.1.4: an over-constrained linkage
//! assembles only if its redundant parts are exactly consistent.)
//!
//! A least-squares assembly from the drawn pose answers it: every mobile
//! body free (three unknowns), every joint and constraint an equation
//! (inputs are not: they only choose a pose among those that close), solved
//! by the runtime's Newton–Raphson with SVD steps — the same residuals as
//! pure Newton and the numeric clusters.
//!
//! - It converges: the mechanism assembles with every joint closed, so only
//!   the drawing is off.
//! - It stops at a least-squares point with a gap: no pose near the drawn
//!   one closes every joint. (Newton calls the residual stagnant a little
//!   short of that point; steps that leave out the conflict's own
//!   directions then finish the way, see `split`.) The joints and constraints whose equations stay
//!   open there are the ones in conflict; a joint that can close on its own
//!   (a link on a single pin, a dyad that still reaches) is closed at a
//!   least-squares point, so it is not named.
//!
//! The loader asks this about a file whose only errors are joints that do
//! not hold in the drawn pose (`review`), and turns the answer into its
//! diagnostics.

pub mod planar;
pub mod spatial;

pub use planar::{assemble, assembled, Assembly};

use std::path::Path;

use nalgebra::{DMatrix, DVector, SVD};

use crate::model::{DrawnModel, Format, Mechanism, Model, ModelError};

/// Newton iterations the assembly may take: far more than a frame's 50, as
/// the drawn pose can be a poor start and this runs once per file.
pub(crate) const MAX_ITERATIONS: u32 = 200;

/// A joint or constraint is in the conflict when its gap at the
/// least-squares point is above both
///
/// - `DRAWN_TOLERANCE × size`, the loader's own tolerance for a joint that
///   holds (a joint closed to it is closed), and
/// - `CONFLICT_SHARE ×` the largest gap of any joint. At the least-squares
///   point a joint that can close is closed to rounding (1e-11 of the gap
///   on the V-link of fig. 13); if Newton stops short of that point, such a
///   joint keeps a remainder that shrinks with the distance to it (about
///   4e-4 of the gap where the plain Newton solve stops on the V-link).
///   Joints over which the conflict is spread take shares of order one
///   (1/2 to 1 on the table of fig. 14b), so 1e-3 separates the two.
pub(crate) const CONFLICT_SHARE: f64 = 1e-3;

/// Splits the residual `r` at a pose with Jacobian `j` into what motion
/// can remove and what it cannot: returns the part no motion of the
/// mechanism's own size removes (to first order), and a relative rank
/// cut-off between the singular values of the two parts, if they are apart.
///
/// In the singular basis `r = Σ (uᵢ·r) uᵢ + (the part outside the range of
/// J)`, the first-order motion removing the i-th part has length
/// `|uᵢ·r| / σᵢ` (every unknown is a length: angles count as arcs at the
/// mechanism's size). A part whose motion is within the mechanism's size is
/// what Newton still closes; one that would take a larger motion is the
/// conflict (at the least-squares point itself its σᵢ is 0), and so is the
/// part outside the range. At a least-squares point the returned part is
/// the residual itself.
pub(crate) fn split(j: &DMatrix<f64>, r: &DVector<f64>, size: f64) -> Option<(DVector<f64>, Option<f64>)> {
    let mut settled = r.clone();
    if j.ncols() == 0 || j.nrows() == 0 {
        return Some((settled, None));
    }
    let svd = SVD::try_new(j.clone(), true, false, f64::EPSILON, 10_000)?;
    let u = svd.u.as_ref()?;
    let top = svd.singular_values.max();
    let (mut removable, mut conflict) = (f64::INFINITY, 0.0_f64);
    for (i, &sigma) in svd.singular_values.iter().enumerate() {
        let c = u.column(i).dot(r);
        if c.abs() <= sigma * size {
            settled -= u.column(i) * c;
            removable = removable.min(sigma / top);
        } else {
            conflict = conflict.max(sigma / top);
        }
    }
    // The geometric mean: as far (in ratio) from either group. None when a
    // group is empty or the conflict's singular values are exactly zero
    // (Newton's own cut-off already leaves them out).
    let apart = conflict > 0.0 && conflict < removable && removable.is_finite();
    let cutoff = apart.then(|| (conflict * removable).sqrt());
    Some((settled, cutoff))
}

/// Reads and validates a (planar) mechanism file; joints open as drawn
/// are diagnosed ([`assembled`]).
pub fn load_file(path: &Path) -> Result<Mechanism, ModelError> {
    assembled(crate::model::load_file_drawn(path)?)
}

/// Validates a (planar) mechanism given as text; `file_name` is used in
/// errors. Joints open as drawn are diagnosed ([`assembled`]).
pub fn load_str(file_name: &str, text: &str, format: Format) -> Result<Mechanism, ModelError> {
    assembled(crate::model::load_str_drawn(file_name, text, format)?)
}

/// Reads and validates a mechanism file of either dimension; joints open
/// as drawn are diagnosed.
pub fn load_any(path: &Path) -> Result<Model, ModelError> {
    any(crate::model::load_any_drawn(path)?)
}

/// Validates a mechanism of either dimension given as text; `file_name` is
/// used in errors. Joints open as drawn are diagnosed.
pub fn load_any_str(file_name: &str, text: &str, format: Format) -> Result<Model, ModelError> {
    any(crate::model::load_any_str_drawn(file_name, text, format)?)
}

/// A mechanism of either dimension, once its open joints are diagnosed.
fn any(drawn: DrawnModel) -> Result<Model, ModelError> {
    match drawn {
        DrawnModel::Planar(d) => assembled(d).map(Model::Planar),
        DrawnModel::Spatial(d) => spatial::assembled(d).map(Model::Spatial),
    }
}

/// "joints E, F, B" when all are joints (or all constraints), else the
/// origins as they are.
pub(crate) fn list(origins: &[String]) -> String {
    for (kind, plural) in [("joint ", "joints "), ("constraint ", "constraints ")] {
        if origins.iter().all(|o| o.starts_with(kind)) {
            let names: Vec<&str> = origins.iter().map(|o| &o[kind.len()..]).collect();
            return format!("{plural}{}", names.join(", "));
        }
    }
    origins.join(", ")
}

/// A coordinate to six decimals, without trailing zeros.
pub(crate) fn short(v: f64) -> String {
    let s = format!("{v:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" {
        "0".into()
    } else {
        s.into()
    }
}
