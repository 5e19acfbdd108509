//! Can a spatial drawing whose joints do not all hold be assembled, and
//! where do its joints close? The planar [`conflict`](crate::conflict)
//! lifted to space: a least-squares assembly from the drawn pose, every
//! moving body free (six unknowns: a rotation vector and a translation),
//! every joint and constraint its primitive rows, solved by the runtime's
//! Newton–Raphson with SVD steps. The system is a plan's numeric cluster
//! ([`crate::interp::spatial::cluster`]), so its residuals and derivatives
//! are the runtime's rows ([`dofplan_runtime::spatial::rows`]), the ones
//! every spatial plan checks and solves.
//!
//! Ground never moves. The inputs are first held at 0 (their drawn values),
//! so a crank drawn where it belongs stays there and the rest closes around
//! it; if the joints cannot close that way (a crank drawn past the reach of
//! the loop), the inputs are released, as the planar assembly always does
//! (they only choose among the poses that close).
//!
//! - It converges: the mechanism assembles, only the drawing is off, and
//!   the poses say where every marker goes.
//! - It stops at a least-squares point with a gap: no pose near the drawn
//!   one closes every joint, and the joints still open there (with the
//!   inputs released) are the ones in conflict.

use dofplan_runtime::numeric::cluster::options;
use dofplan_runtime::numeric::{Equations, Newton, NewtonOptions, NewtonOutcome};
use dofplan_runtime::spatial::{dot, norm, sub, Pose3, Vec3};
use nalgebra::{DMatrix, DVector};

use super::{list, short, split, CONFLICT_SHARE, MAX_ITERATIONS};
use crate::interp::spatial::cluster::{system, System};
use crate::model::spatial::equations::equations;
use crate::model::spatial::Drawn;
use crate::model::spatial::Mechanism;
use crate::model::{Diagnostic, MarkerId, ModelError, Open, DRAWN_TOLERANCE};
use crate::numeric::spatial::released;
use crate::plan::spatial::{CheckRow, Cluster, ClusterRow, Param};

/// Above this many moving bodies the dense assembly is not run (its SVD
/// grows with the cube of the unknowns, six a body); the errors say so.
pub const MAX_REVIEWED_BODIES: usize = 80;

/// What the least-squares assembly of a spatial drawing found.
#[derive(Clone, Debug, PartialEq)]
pub enum Assembly {
    /// Every joint and constraint closes (to the drawn-pose tolerance).
    Closes {
        /// Body poses of the assembled mechanism (relative to the drawing),
        /// in mechanism order; fixed bodies' are the identity.
        poses: Vec<Pose3>,
        /// How far the marker that moves most is from where it is drawn.
        moved: f64,
        /// Whether the inputs stayed at 0 (their drawn values); false when
        /// the joints close only with the inputs free, or there are none.
        inputs_held: bool,
    },
    /// A least-squares point with a gap (the inputs released): no pose
    /// near the drawn one closes every joint.
    Conflict {
        /// The residual's Euclidean norm there (length units: angular rows
        /// count as arcs at the mechanism's size).
        gap: f64,
        /// The joints and constraints left open there, with their own gap,
        /// in file order ("joint C", "constraint K").
        open: Vec<(String, f64)>,
    },
    /// Newton could not tell (iteration budget spent while still making
    /// progress, or a non-finite value): nothing is claimed.
    Undecided,
}

/// Assembles a spatial mechanism by least squares from the drawn pose:
/// with the inputs held at 0 first, then, if that does not close, with
/// them released.
pub fn assemble(m: &Mechanism) -> Assembly {
    let mut held = m.clone();
    held.sweep = None;
    if !m.inputs.is_empty() {
        if let found @ Assembly::Closes { .. } = least_squares(&held, false) {
            return found;
        }
    }
    least_squares(&released(m), true)
}

/// The assembly's system in lengths, as the planar assembly's: rotation
/// unknowns as arcs at the mechanism's size and angular rows (sines) times
/// the size. Newton's minimum-norm steps then weigh a turn by how far it
/// moves the body, and [`split`] reads every singular value alike.
struct Scaled<'s, 'a> {
    inner: &'s mut System<'a>,
    /// Per unknown: 1/size for a rotation, 1 for a translation.
    arc: Vec<f64>,
    /// Per row: the size for a sine, 1 for a length.
    row: Vec<f64>,
    /// The inner system's unknowns.
    x: DVector<f64>,
}

impl Scaled<'_, '_> {
    /// The inner system's unknowns at `x`.
    fn inner_x(&self, x: &DVector<f64>) -> DVector<f64> {
        x.component_mul(&DVector::from_column_slice(&self.arc))
    }
}

impl Equations for Scaled<'_, '_> {
    fn unknowns(&self) -> usize {
        self.arc.len()
    }
    fn equations(&self) -> usize {
        self.row.len()
    }
    fn eval(&mut self, x: &DVector<f64>, r: &mut DVector<f64>, jacobian: Option<&mut DMatrix<f64>>) {
        self.x = self.inner_x(x);
        match jacobian {
            Some(j) => {
                self.inner.eval(&self.x, r, Some(&mut *j));
                for (k, a) in self.arc.iter().enumerate() {
                    for (i, s) in self.row.iter().enumerate() {
                        j[(i, k)] *= s * a;
                    }
                }
            }
            None => self.inner.eval(&self.x, r, None),
        }
        for (ri, s) in r.iter_mut().zip(&self.row) {
            *ri *= s;
        }
    }
}

/// The least-squares assembly of `m` with its inputs (if any) at 0.
/// `decides`: whether a gap is a conflict (else only a closure counts).
fn least_squares(m: &Mechanism, decides: bool) -> Assembly {
    let size = m.size();
    let eqs = equations(m);
    let params: Vec<Param> = (0..m.bodies.len())
        .filter(|&b| !m.bodies[b].fixed)
        .map(|body| Param::Free { body })
        .collect();
    let cluster = Cluster {
        params,
        rows: eqs
            .iter()
            .map(|e| ClusterRow::Equation(CheckRow::of(e, 0, size)))
            .collect(),
        size,
    };
    // Every body is free: six unknowns each, its rotation vector first
    // (`cluster::moved`), then its translation.
    let arc: Vec<f64> = (0..cluster.unknowns())
        .map(|k| if k % 6 < 3 { 1.0 / size } else { 1.0 })
        .collect();
    let row: Vec<f64> = eqs
        .iter()
        .flat_map(|e| std::iter::repeat_n(if e.linear() { 1.0 } else { size }, e.kind.rows()))
        .collect();
    let drawn = vec![Pose3::IDENTITY; m.bodies.len()];
    let inputs = vec![0.0; m.inputs.len()];
    let mut inner = system(&drawn, &[], &cluster, &inputs);
    let mut system = Scaled {
        inner: &mut inner,
        x: DVector::zeros(arc.len()),
        arc,
        row,
    };
    let (unknowns, count) = (system.unknowns(), system.equations());
    let tolerance = DRAWN_TOLERANCE * size;
    let options = NewtonOptions {
        max_iterations: MAX_ITERATIONS,
        ..options(size)
    };
    let mut newton = Newton::new(unknowns, count);
    let mut x = DVector::zeros(unknowns);
    let report = newton.solve(&mut system, &mut x, &options);
    let mut r = DVector::zeros(count);
    let mut j = DMatrix::zeros(count, unknowns);
    system.eval(&x, &mut r, Some(&mut j));
    let finite = |r: &DVector<f64>, j: &DMatrix<f64>| r.iter().chain(j.iter()).all(|v| v.is_finite());
    if !finite(&r, &j) {
        return Assembly::Undecided;
    }
    let mut unsettled = report.outcome == NewtonOutcome::NotConverged;
    if report.outcome == NewtonOutcome::NoSolution && r.norm() > tolerance {
        // As in the plane: Newton stops short of the least-squares point of
        // an inconsistent redundancy; steps leaving the conflict's own
        // directions out finish the way.
        if let Some((_, Some(cutoff))) = split(&j, &r, size) {
            let polish = NewtonOptions {
                rank_cutoff: cutoff,
                ..options
            };
            unsettled = newton.solve(&mut system, &mut x, &polish).outcome == NewtonOutcome::NotConverged;
            system.eval(&x, &mut r, Some(&mut j));
            if !finite(&r, &j) {
                return Assembly::Undecided;
            }
        }
    }
    if r.norm() <= tolerance {
        let at = system.inner_x(&x);
        inner.place(at.as_slice());
        let poses = inner.poses.clone();
        let moved = m
            .all_markers()
            .map(|id| {
                let p = m.marker(id).at;
                norm(sub(poses[id.body].world(p), p))
            })
            .fold(0.0, f64::max);
        return Assembly::Closes {
            poses,
            moved,
            inputs_held: !m.inputs.is_empty(),
        };
    }
    if unsettled || !decides {
        return Assembly::Undecided;
    }
    let Some((settled, _)) = split(&j, &r, size) else {
        return Assembly::Undecided;
    };
    let mut gaps: Vec<(String, f64)> = Vec::new();
    let mut at = 0;
    for e in &eqs {
        let n = e.kind.rows();
        let g = settled.rows(at, n).norm();
        at += n;
        match gaps.iter_mut().find(|(o, _)| *o == e.origin) {
            Some((_, sum)) => *sum = sum.hypot(g),
            None => gaps.push((e.origin.clone(), g)),
        }
    }
    let largest = gaps.iter().map(|(_, g)| *g).fold(0.0, f64::max);
    let floor = tolerance.max(CONFLICT_SHARE * largest);
    let open: Vec<(String, f64)> = gaps.into_iter().filter(|(_, g)| *g > floor).collect();
    if open.is_empty() {
        return Assembly::Undecided;
    }
    Assembly::Conflict { gap: r.norm(), open }
}

/// The two markers of a joint or constraint ("joint C", "constraint K").
pub(crate) fn markers_of(m: &Mechanism, origin: &str) -> Option<[MarkerId; 2]> {
    if let Some(name) = origin.strip_prefix("joint ") {
        return m.joints.iter().find(|j| j.name == name).map(|j| j.markers);
    }
    let name = origin.strip_prefix("constraint ")?;
    m.constraints.iter().find(|c| c.name == name).map(|c| c.markers)
}

/// `[x, y, z]` to six decimals.
pub(crate) fn point(p: Vec3) -> String {
    format!("[{}, {}, {}]", short(p[0]), short(p[1]), short(p[2]))
}

/// Where the joint or constraint `origin` closes in the assembled `poses`:
/// each of its markers that moves, from where to where and how far, and
/// the axis it turns to.
fn closing(m: &Mechanism, origin: &str, poses: &[Pose3]) -> Option<String> {
    let markers = markers_of(m, origin)?;
    let size = m.size();
    let tiny = 0.25 * DRAWN_TOLERANCE * size;
    let to = |id: MarkerId| poses[id.body].world(m.marker(id).at);
    let mut parts = Vec::new();
    for id in markers {
        let (from, to) = (m.marker(id).at, to(id));
        let d = norm(sub(to, from));
        if d > tiny {
            parts.push(format!(
                "{} moves from {} to {} ({})",
                m.marker_name(id),
                point(from),
                point(to),
                crate::format::length(d)
            ));
        }
    }
    let same = norm(sub(to(markers[0]), to(markers[1]))) <= tiny;
    let mut text = if same {
        format!(" at {}", point(to(markers[0])))
    } else {
        String::new()
    };
    // The axis the first marker's z turns to, if it carries one and turns.
    if let Some(axes) = m.marker(markers[0]).axes {
        let z = poses[markers[0].body].dir(axes.z);
        if (1.0 - dot(z, axes.z)).abs() * size > tiny {
            text.push_str(&format!(" with its axis along {}", point(z)));
        }
    }
    if parts.is_empty() {
        parts.push("none of its markers moves".into());
    }
    Some(format!("{text}: {}", parts.join(", ")))
}

/// The mechanism if every joint holds in the drawn pose; otherwise the
/// errors `load_any_str` gives: the open joints, each with what the
/// least-squares assembly says (where it closes, or the joints in
/// conflict).
pub fn assembled(drawn: Drawn) -> Result<Mechanism, ModelError> {
    let Drawn {
        mechanism,
        mut open,
        opened,
    } = drawn;
    if open.is_empty() {
        return Ok(mechanism);
    }
    review(&mechanism, &opened, &mut open);
    Err(ModelError { diagnostics: open })
}

/// Adds to each "does not hold in the drawn pose" error what the
/// least-squares assembly says: where the joint closes (which markers move
/// where), or which joints are in conflict.
pub(crate) fn review(m: &Mechanism, open: &[Open], diags: &mut [Diagnostic]) {
    let mut add = |i: usize, hint: &str| {
        let d = &mut diags[i];
        d.help = Some(match d.help.take() {
            Some(h) => format!("{h}; {hint}"),
            None => hint.to_string(),
        });
    };
    let moving = m.moving();
    if moving > MAX_REVIEWED_BODIES {
        for o in open {
            add(
                o.diagnostic,
                &format!(
                    "whether the rest of the mechanism lets it close was not checked: the least-squares assembly \
                     runs on at most {MAX_REVIEWED_BODIES} moving bodies, and this mechanism has {moving}"
                ),
            );
        }
        return;
    }
    match assemble(m) {
        Assembly::Closes {
            poses,
            moved,
            inputs_held,
        } => {
            let inputs = match (m.inputs.is_empty(), inputs_held) {
                (true, _) => "",
                (false, true) => ", the inputs at their drawn values",
                (false, false) => ", the inputs free (held at their drawn values the joints do not close)",
            };
            // A joint with several open primitives has one error each: say
            // where it closes once.
            let mut said: Vec<&str> = Vec::new();
            for o in open {
                if said.contains(&o.origin.as_str()) {
                    continue;
                }
                said.push(&o.origin);
                let at = closing(m, &o.origin, &poses).unwrap_or_default();
                add(
                    o.diagnostic,
                    &format!(
                        "the mechanism does assemble with {} closed{at}; no marker moves more than {} from the \
                         drawing{inputs}: only the drawing is off (`dofplan assemble` moves the markers there)",
                        o.origin,
                        crate::format::length(moved)
                    ),
                );
            }
        }
        Assembly::Conflict { gap, open: conflict } => {
            let names: Vec<String> = conflict.iter().map(|(o, _)| o.clone()).collect();
            let gaps: Vec<String> = conflict
                .iter()
                .map(|(o, g)| format!("{o} open by {g:.1e}"))
                .collect();
            let subject = if names.len() == 1 {
                format!(
                    "{} is in conflict with the rest of the mechanism: no pose near the drawn one closes it",
                    names[0]
                )
            } else {
                format!(
                    "{} are in conflict: no pose near the drawn one closes them all",
                    list(&names)
                )
            };
            for o in open {
                add(
                    o.diagnostic,
                    &format!(
                        "{subject} (least-squares gap {gap:.1e}; at that pose {}); a redundant joint must be \
                         exactly consistent: redraw it so every joint holds, or remove one of these joints",
                        gaps.join(", ")
                    ),
                );
            }
        }
        Assembly::Undecided => {
            for o in open {
                add(
                    o.diagnostic,
                    "whether the mechanism assembles could not be told: the least-squares assembly from the drawn \
                     pose did not settle; draw the markers nearer to where the joints close",
                );
            }
        }
    }
}
