//! A gear pair's (or rack and pinion's) residual: how far a frame's poses
//! are from rolling without slip.
//!
//! A pose holds a body's angle only modulo a turn, and a ratio that is not
//! a whole number cannot be checked on wrapped angles: two turns of a
//! pinion in a 1:3 pair leave the gear two thirds of a turn on, not where
//! one turn would. So the check works on each body's turn since the
//! drawing *unwrapped*, derived from the model alone (not from the plan):
//! fixed bodies do not turn, an angle input turns its joint's second body
//! by the input from its first, a prismatic joint or an offset constraint
//! keeps two bodies' angles equal, and a gear pair relates its gears'
//! turns on their carrier by its ratio. The residual compares each gear's
//! turn in the poses with the turn so derived (as an arc of its pitch
//! circle), and a rack's slide with its pinion's turn.

use dofplan_runtime::planar::{Point, Pose};

use super::{relative_angle, wrap};
use crate::model::planar::gears::{Gear, GearKind};
use crate::model::{ConstraintKind, InputKind, JointKind, Mechanism};

/// Each body's turn since the drawing (radians, unwrapped) where the
/// inputs and gear pairs fix it, `None` elsewhere (a body a loop closes).
pub fn turns(m: &Mechanism, inputs: &[f64]) -> Vec<Option<f64>> {
    let mut turn: Vec<Option<f64>> = m.bodies.iter().map(|b| b.fixed.then_some(0.0)).collect();
    // Bodies whose angles are equal, and angle inputs: (first, second,
    // the second's turn from the first's).
    let mut links: Vec<(usize, usize, f64)> = Vec::new();
    for (j, joint) in m.joints.iter().enumerate() {
        let [a, b] = joint.markers.map(|id| id.body);
        match joint.kind {
            JointKind::Prismatic => links.push((a, b, 0.0)),
            JointKind::Revolute => {
                let input = m
                    .inputs
                    .iter()
                    .position(|i| i.joint == j && i.kind == InputKind::Angle);
                if let Some(k) = input {
                    links.push((a, b, inputs[k].to_radians()));
                }
            }
        }
    }
    for c in m.constraints.iter().filter(|c| c.kind == ConstraintKind::Offset) {
        links.push((c.markers[0].body, c.markers[1].body, 0.0));
    }
    // Each pass fixes at least one more body or ends: at most one pass a
    // body.
    loop {
        let mut grew = false;
        for &(a, b, by) in &links {
            match (turn[a], turn[b]) {
                (Some(ta), None) => turn[b] = Some(ta + by),
                (None, Some(tb)) => turn[a] = Some(tb - by),
                _ => continue,
            }
            grew = true;
        }
        for gear in m.gears.iter().filter(|g| matches!(g.kind, GearKind::Gear { .. })) {
            let [a, b] = gear.bodies;
            let carrier = gear.carrier.map_or(Some(0.0), |c| turn[c]);
            let ratio = gear.ratio();
            let found = match (turn[a], turn[b], carrier) {
                (Some(ta), None, Some(tc)) => (b, tc + ratio * (ta - tc)),
                (None, Some(tb), Some(tc)) => (a, tc + (tb - tc) / ratio),
                // Both gears known, the arm not: tb - tc = ratio (ta - tc).
                (Some(ta), Some(tb), None) if ratio != 1.0 => {
                    let c = gear.carrier.expect("a fixed carrier is known");
                    (c, (tb - ratio * ta) / (1.0 - ratio))
                }
                _ => continue,
            };
            turn[found.0] = Some(found.1);
            grew = true;
        }
        if !grew {
            return turn;
        }
    }
}

/// How far `poses` are from `gear` rolling without slip, as a length: the
/// largest arc of a pitch circle between a gear's turn in the poses and
/// the turn [`turns`] derives (`turns`: that function's result at the
/// frame's inputs), and the relation between the derived turns; for a
/// rack and pinion, the pinion's arc and the rack's slide off its
/// pinion's. A body whose turn is not derived (one a loop closes) is
/// checked by the wrapped angles where the ratio is a whole number of
/// turns either way, and not at all otherwise (0).
pub fn residual(m: &Mechanism, gear: &Gear, poses: &[Pose], turns: &[Option<f64>]) -> f64 {
    let [a, b] = gear.bodies;
    // A fixed carrier: any fixed body (all stand still together).
    let carrier = gear
        .carrier
        .unwrap_or_else(|| m.bodies.iter().position(|body| body.fixed).unwrap_or(0));
    let turn_of = |k: usize| turns[k].zip(turns[carrier]).map(|(t, tc)| t - tc);
    let rel = |k: usize| relative_angle(poses, carrier, k);
    // The arc between the pose's turn and the derived one.
    let arc = |k: usize, radius: f64| turn_of(k).map_or(0.0, |t| wrap(rel(k) - t).abs() * radius);
    let ratio = gear.ratio();
    match gear.kind {
        GearKind::Gear { radii, .. } => {
            let rolled = match (turn_of(a), turn_of(b)) {
                (Some(ta), Some(tb)) => (tb - ratio * ta).abs() * radii[1],
                // Wrapped angles: b's turn is ratio × a's modulo a turn
                // when the ratio is a whole number.
                _ if ratio.fract() == 0.0 => wrap(rel(b) - ratio * rel(a)).abs() * radii[1],
                _ if (1.0 / ratio).fract() == 0.0 => wrap(rel(a) - rel(b) / ratio).abs() * radii[0],
                _ => 0.0,
            };
            arc(a, radii[0]).max(arc(b, radii[1])).max(rolled)
        }
        GearKind::RackPinion { radius, dir, .. } => {
            let slide = slide(&poses[carrier], &poses[b], gear.centres[1], dir);
            let rolled = turn_of(a).map_or(0.0, |t| (slide - ratio * t).abs());
            arc(a, radius).max(rolled)
        }
    }
}

/// How far the rack's marker (drawn at `at`) has slid along `dir` (the
/// carrier's axes) since the drawing.
fn slide(carrier: &Pose, rack: &Pose, at: Point, dir: Point) -> f64 {
    let w = rack.world(at);
    let v = carrier
        .rot
        .inverse()
        .apply([w[0] - carrier.at[0], w[1] - carrier.at[1]]);
    (v[0] - at[0]) * dir[0] + (v[1] - at[1]) * dir[1]
}
