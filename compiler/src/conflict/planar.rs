//! The conflict diagnosis of a planar file: the least-squares assembly from
//! the drawn pose, and which joints and constraints cannot all close.

use dofplan_runtime::numeric::{Equations, Newton, NewtonOptions, NewtonOutcome};
use dofplan_runtime::planar::cluster::{self, Param, System};
use dofplan_runtime::planar::Pose;
use nalgebra::{DMatrix, DVector};

use crate::model::planar::equations::equations;
use crate::model::{
    ConstraintKind, Diagnostic, Drawn, JointKind, Location, Mechanism, ModelError, Note, Open,
    DRAWN_TOLERANCE,
};

use super::{list, short, split, CONFLICT_SHARE, MAX_ITERATIONS};

/// Mobile bodies up to which the loader assembles a file whose joints do
/// not all hold (`review`): the dense assembly takes about 0.5 s of CPU
/// at this size on the development machine, and grows with its cube.
pub const MAX_REVIEWED_BODIES: usize = 80;

/// What the least-squares assembly from the drawn pose found.
#[derive(Clone, Debug, PartialEq)]
pub enum Assembly {
    /// Every joint and constraint closes (to the drawn-pose tolerance).
    Closes {
        /// Body poses of the assembled mechanism, in mechanism order.
        poses: Vec<Pose>,
        /// How far the marker that moves most is from where it is drawn.
        moved: f64,
    },
    /// A least-squares point with a gap: no pose near the drawn one closes
    /// every joint.
    Conflict {
        /// The residual's Euclidean norm there (length units).
        gap: f64,
        /// The joints and constraints left open there, with their own gap,
        /// in file order ("joint E", "constraint c1").
        open: Vec<(String, f64)>,
    },
    /// Newton could not tell (iteration budget spent while still making
    /// progress, or a non-finite value): nothing is claimed.
    Undecided,
}

/// Assembles the mechanism by least squares from the drawn pose.
pub fn assemble(m: &Mechanism) -> Assembly {
    let mut free = m.clone();
    free.inputs.clear();
    let sourced = equations(&free);
    let rows: Vec<_> = sourced.iter().map(|s| s.eq.row()).collect();
    let params: Vec<Param> = (0..m.bodies.len())
        .filter(|&b| !m.bodies[b].fixed)
        .map(|body| Param::Free { body })
        .collect();
    let size = m.size();
    let tolerance = DRAWN_TOLERANCE * size;
    let mut poses = vec![Pose::IDENTITY; m.bodies.len()];
    let (mut system, mut x) = System::new(&mut poses, &params, &rows, &[], size);
    let (unknowns, count) = (system.unknowns(), system.equations());
    let options = NewtonOptions {
        max_iterations: MAX_ITERATIONS,
        ..cluster::options(size)
    };
    let mut newton = Newton::new(unknowns, count);
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
        // Newton stops once the residual stops halving, which near an
        // inconsistent redundancy is before the least-squares point: the
        // Jacobian there is nearly singular in the direction the conflict
        // pulls, and full steps along it are rejected. Steps that leave the
        // conflict's directions out (a rank cut-off between the two groups
        // of singular values) then reach the least-squares point quickly.
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
    drop(system);
    if r.norm() <= tolerance {
        let moved = m
            .all_markers()
            .map(|id| {
                let (at, w) = (m.marker(id).at, poses[id.body].world(m.marker(id).at));
                (w[0] - at[0]).hypot(w[1] - at[1])
            })
            .fold(0.0, f64::max);
        return Assembly::Closes { poses, moved };
    }
    if unsettled {
        return Assembly::Undecided;
    }
    let Some((settled, _)) = split(&j, &r, size) else {
        return Assembly::Undecided;
    };
    let mut gaps: Vec<(String, f64)> = Vec::new();
    let mut row = 0;
    for (s, eq) in sourced.iter().zip(&rows) {
        let n = eq.count();
        let g = settled.rows(row, n).norm();
        row += n;
        match gaps.iter_mut().find(|(o, _)| *o == s.origin) {
            Some((_, sum)) => *sum = sum.hypot(g),
            None => gaps.push((s.origin.clone(), g)),
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

/// The mechanism if every joint holds in the drawn pose; otherwise the
/// errors [`load_str`](super::load_str) gives: the open joints, revised by the
/// least-squares assembly (the drawing is only off, or the joints named
/// in conflict).
pub fn assembled(drawn: Drawn) -> Result<Mechanism, ModelError> {
    let Drawn {
        mechanism,
        mut open,
        opened,
        places,
    } = drawn;
    if open.is_empty() {
        return Ok(mechanism);
    }
    // By origin ("joint B"), named only now that they are needed.
    let places: Vec<(String, Location)> = (mechanism.joints.iter())
        .map(|j| format!("joint {}", j.name))
        .chain(
            mechanism
                .constraints
                .iter()
                .map(|c| format!("constraint {}", c.name)),
        )
        .zip(places)
        .collect();
    review(&mechanism, &opened, &places, &mut open);
    Err(ModelError { diagnostics: open })
}

/// Revises the loader's "does not hold in the drawn pose" errors of
/// `open` (the file's only errors) by assembling the mechanism:
///
/// - if it assembles, each keeps its message, and its help says so (with
///   where the joint closes): the drawing is just off;
/// - if joints are in conflict, the errors of the open joints among them
///   become one error at the first one's position, naming every joint in
///   the conflict, with the original messages and the other joints'
///   positions as notes (`places`: every joint's and constraint's
///   position, by origin).
///
/// The assembly is a dense least-squares solve, cubic in the number of
/// bodies: above [`MAX_REVIEWED_BODIES`] mobile bodies it is not run, and
/// each error's help says so.
pub(crate) fn review(
    m: &Mechanism,
    open: &[Open],
    places: &[(String, Location)],
    diags: &mut Vec<Diagnostic>,
) {
    let mobile = m.bodies.iter().filter(|b| !b.fixed).count();
    if mobile > MAX_REVIEWED_BODIES {
        let hint = format!(
            "whether the rest of the mechanism lets it close was not checked: the least-squares assembly \
             that tells a misdrawn joint from joints in conflict runs on at most {MAX_REVIEWED_BODIES} mobile \
             bodies, and this mechanism has {mobile}"
        );
        for o in open {
            let d = &mut diags[o.diagnostic];
            d.help = Some(match d.help.take() {
                Some(h) => format!("{h}; {hint}"),
                None => hint.clone(),
            });
        }
        return;
    }
    match assemble(m) {
        Assembly::Closes { poses, moved } => {
            for o in open {
                let at = closing_point(m, &o.origin, &poses)
                    .map(|p| format!(" (at [{}, {}])", short(p[0]), short(p[1])))
                    .unwrap_or_default();
                let hint = format!(
                    "the mechanism does assemble with {} closed{at}, no marker moving more than {moved:.2e} \
                     from the drawing: only the drawing is off",
                    o.origin
                );
                let d = &mut diags[o.diagnostic];
                d.help = Some(match d.help.take() {
                    Some(h) => format!("{h}; {hint}"),
                    None => hint,
                });
            }
        }
        Assembly::Conflict { gap, open: conflict } => {
            let names: Vec<String> = conflict.iter().map(|(o, _)| o.clone()).collect();
            let folded: Vec<&Open> = open.iter().filter(|o| names.contains(&o.origin)).collect();
            // At the first open joint in the conflict (else the first open
            // one, whose own error then stays too).
            let Some(at) = folded.first().copied().or(open.first()).map(|o| o.diagnostic) else {
                return;
            };
            let mut notes: Vec<Note> = folded
                .iter()
                .map(|o| Note {
                    location: diags[o.diagnostic].location.clone(),
                    message: diags[o.diagnostic].message.clone(),
                })
                .collect();
            for (origin, g) in &conflict {
                if folded.iter().any(|o| o.origin == *origin) {
                    continue;
                }
                if let Some((_, location)) = places.iter().find(|(o, _)| o == origin) {
                    notes.push(Note {
                        location: location.clone(),
                        message: format!(
                            "{origin} is in the conflict: open by {g:.1e} at the least-squares pose"
                        ),
                    });
                }
            }
            // In file order, like the joints themselves.
            notes.sort_by_key(|n| match &n.location {
                Location::Span(span) => span.start,
                _ => usize::MAX,
            });
            let message = if names.len() == 1 {
                format!(
                    "{} is in conflict with the rest of the mechanism: no pose near the drawn one closes it \
                     (least-squares gap {gap:.1e})",
                    names[0]
                )
            } else {
                format!(
                    "{} are in conflict: no pose near the drawn one closes them all (least-squares gap {gap:.1e})",
                    list(&names)
                )
            };
            let conflict_error = Diagnostic {
                file: diags[at].file.clone(),
                location: diags[at].location.clone(),
                message,
                notes,
                help: Some(
                    "a redundant link must be exactly consistent (e.g. parallel and equal to the link it \
                     duplicates): redraw it so every joint holds, or remove one of these joints"
                        .into(),
                ),
            };
            if folded.is_empty() {
                diags.insert(at, conflict_error);
            } else {
                // The open joints' errors are now notes of this one.
                // `at` is the first of them: the others all come after it.
                let folded: Vec<usize> = folded.iter().map(|o| o.diagnostic).collect();
                diags[at] = conflict_error;
                let mut k = 0;
                diags.retain(|_| {
                    let keep = k == at || !folded.contains(&k);
                    k += 1;
                    keep
                });
            }
        }
        Assembly::Undecided => {}
    }
}

/// Where a revolute joint or coincident constraint closes in an assembled
/// pose (its first marker there); none for the others.
fn closing_point(m: &Mechanism, origin: &str, poses: &[Pose]) -> Option<[f64; 2]> {
    let markers = if let Some(name) = origin.strip_prefix("joint ") {
        let j = m.joints.iter().find(|j| j.name == name)?;
        (j.kind == JointKind::Revolute).then_some(j.markers)?
    } else {
        let name = origin.strip_prefix("constraint ")?;
        let c = m.constraints.iter().find(|c| c.name == name)?;
        (c.kind == ConstraintKind::Coincident).then_some(c.markers)?
    };
    let id = markers[0];
    Some(poses[id.body].world(m.marker(id).at))
}
