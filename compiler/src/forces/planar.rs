//! A planar frame's input forces by virtual work (see the module above).

use dofplan_runtime::planar::Pose;
use dofplan_runtime::scalar::Jet2;

use super::plan::{ForcePlan, System};
use crate::interp::planar::InterpState;
use crate::interp::{Interpreter, RateError};
use crate::model::planar::loads::LoadKind;
use crate::model::{InputKind, MarkerId, Mechanism};

/// How the mechanism moves at the frame, for the loads that depend on it
/// (dampers) and the bodies' inertia: each input's rate and acceleration
/// in its own units per second (degrees for an angle, as
/// [`Interpreter::rates`] takes them).
#[derive(Clone, Copy, Debug)]
pub struct Moving<'a> {
    /// Each input's rate.
    pub rates: &'a [f64],
    /// Each input's acceleration.
    pub accelerations: &'a [f64],
}

/// The force (slide) or torque (angle, per radian) each input must supply
/// at the frame `state` was solved to, for the mechanism to hold there
/// (`moving` None: statics, no inertia, dampers idle) or to move as
/// `moving` says (kinetostatics: d'Alembert). Positive in the input's
/// positive direction. An error where the plan's rates are not defined (a
/// dead point).
pub fn input_forces(
    m: &Mechanism,
    interp: &Interpreter,
    state: &InterpState,
    inputs: &[f64],
    moving: Option<Moving>,
) -> Result<Vec<f64>, RateError> {
    super::by_virtual_work(
        &m.inputs,
        moving.map(|mv| (mv.rates, mv.accelerations)),
        |r, a| interp.rates(state, inputs, r, a),
        |v, actual| power(m, v, actual),
    )
}

/// The power every load delivers (and with `actual` motion, the bodies'
/// d'Alembert inertia) at the virtual motion `v` (its first derivatives).
fn power(m: &Mechanism, v: &[Pose<Jet2>], actual: Option<&[Pose<Jet2>]>) -> f64 {
    let loads = &m.loads;
    let at = |id: MarkerId| v[id.body].world(m.marker(id).at);
    let mut p = 0.0;
    for load in &loads.applied {
        p += match &load.kind {
            LoadKind::Force {
                marker,
                force,
                body_axes,
            } => {
                let f = if *body_axes {
                    let r = &v[marker.body].rot;
                    [
                        r.c.v * force[0] - r.s.v * force[1],
                        r.s.v * force[0] + r.c.v * force[1],
                    ]
                } else {
                    *force
                };
                let x = at(*marker);
                f[0] * x[0].d + f[1] * x[1].d
            }
            LoadKind::Torque { body, torque } => torque * omega(&v[*body]),
            LoadKind::Spring {
                markers,
                stiffness,
                free_length,
            } => {
                let (length, rate) = stretch(at(markers[0]), at(markers[1]));
                -stiffness * (length - free_length) * rate
            }
            LoadKind::Damper { markers, damping } => {
                let speed = actual.map_or(0.0, |a| {
                    let w = |id: MarkerId| a[id.body].world(m.marker(id).at);
                    stretch(w(markers[0]), w(markers[1])).1
                });
                let (_, rate) = stretch(at(markers[0]), at(markers[1]));
                -damping * speed * rate
            }
            LoadKind::TorsionSpring {
                joint,
                stiffness,
                free_angle,
            } => {
                let [a, b] = m.joints[*joint].markers.map(|id| &v[id.body]);
                let turn = relative_turn(a, b);
                -stiffness * (turn - free_angle) * (omega(b) - omega(a))
            }
        };
    }
    for (b, pose) in v.iter().enumerate() {
        let Some((f, torque)) = weight(m, b, actual) else {
            continue;
        };
        let c = pose.world(m.loads.mass(b).map_or([0.0; 2], |mass| mass.centre));
        p += f[0] * c[0].d + f[1] * c[1].d + torque * omega(pose);
    }
    p
}

/// What body `b`'s mass puts on it, at its centre: gravity's force and,
/// with `actual` motion, d'Alembert's (minus the mass times the centre's
/// acceleration) and its torque (minus the inertia times the angular
/// acceleration). `None` for a body without mass.
fn weight(m: &Mechanism, b: usize, actual: Option<&[Pose<Jet2>]>) -> Option<([f64; 2], f64)> {
    let mass = m.loads.mass(b)?;
    let mut f = (m.loads.gravity).map_or([0.0; 2], |g| [mass.mass * g[0], mass.mass * g[1]]);
    let mut torque = 0.0;
    if let Some(a) = actual {
        let ca = a[b].world(mass.centre);
        f[0] -= mass.mass * ca[0].dd;
        f[1] -= mass.mass * ca[1].dd;
        torque -= mass.inertia * alpha(&a[b]);
    }
    Some((f, torque))
}

/// A body's angular rate from its pose's jet: for a unit (c, s), ω = c·ṡ −
/// s·ċ.
fn omega(p: &Pose<Jet2>) -> f64 {
    p.rot.c.v * p.rot.s.d - p.rot.s.v * p.rot.c.d
}

/// A body's angular acceleration: α = c·s̈ − s·c̈.
fn alpha(p: &Pose<Jet2>) -> f64 {
    p.rot.c.v * p.rot.s.dd - p.rot.s.v * p.rot.c.dd
}

/// The distance between two points and its rate.
fn stretch(a: [Jet2; 2], b: [Jet2; 2]) -> (f64, f64) {
    let d = [b[0].v - a[0].v, b[1].v - a[1].v];
    let length = d[0].hypot(d[1]);
    if length == 0.0 {
        return (0.0, 0.0);
    }
    let rate = (d[0] * (b[0].d - a[0].d) + d[1] * (b[1].d - a[1].d)) / length;
    (length, rate)
}

/// How far body `b` has turned relative to body `a` since the drawing,
/// in radians in (−π, π].
fn relative_turn(a: &Pose<Jet2>, b: &Pose<Jet2>) -> f64 {
    let (ca, sa, cb, sb) = (a.rot.c.v, a.rot.s.v, b.rot.c.v, b.rot.s.v);
    (sb * ca - cb * sa).atan2(cb * ca + sb * sa)
}

/// A frame's joint reactions, with the input forces the same equations
/// give.
#[derive(Clone, Debug, PartialEq)]
pub struct Reactions {
    /// Per joint: the force its first body exerts on its second, in world
    /// axes (at a prismatic joint, square to the rail).
    pub forces: Vec<[f64; 2]>,
    /// Per joint: the moment its first body exerts on its second (0 at a
    /// revolute joint, which carries none).
    pub moments: Vec<f64>,
    /// Per input: its force or torque, from every body's equilibrium (the
    /// same as [`input_forces`]' virtual work where both are defined).
    pub inputs: Vec<f64>,
    /// The joints whose reactions the equations do not fix (an
    /// over-constrained mechanism: a redundant joint shares its load
    /// with others in any proportion); the values given are then the
    /// least-norm ones.
    pub indeterminate: Vec<usize>,
    /// The largest force or moment left unbalanced on a body: round-off
    /// where the mechanism can be held, more where it cannot (a freedom no
    /// input holds).
    pub residual: f64,
    /// What the mechanism does to the ground (every fixed body): the force
    /// `[fx, fy]` and the moment about the origin, through its joints, its
    /// inputs' reactions and the loads anchored to the ground. Held still
    /// this is the weight and the loads; running, the d'Alembert part is
    /// the shaking force and moment.
    pub shaking: [f64; 3],
}

/// The plan for the reaction unknowns of `m` (see `forces/plan.rs`), from
/// its equations at the drawn pose; `None` for a mechanism with primitive
/// constraints, whose forces are not modelled yet.
pub fn force_plan(m: &Mechanism) -> Option<ForcePlan> {
    if !m.constraints.is_empty() {
        return None;
    }
    let drawn = vec![Pose::IDENTITY; m.bodies.len()];
    Some(ForcePlan::new(&equilibrium(m, &drawn).0))
}

/// The joint reactions at `poses` from every moving body's force and
/// moment equilibrium under the file's loads (with `actual` motion, the
/// bodies' d'Alembert inertia and the dampers too): three equations per
/// moving body, two unknowns per joint and one per input, solved as
/// `plan` says (block by block, or by least squares, least norm where
/// the mechanism is over-constrained). `None` for a mechanism with
/// primitive constraints, whose forces are not modelled yet.
pub fn reactions(
    m: &Mechanism,
    plan: &ForcePlan,
    poses: &[Pose],
    actual: Option<&[Pose<Jet2>]>,
) -> Option<Reactions> {
    if !m.constraints.is_empty() {
        return None;
    }
    let (system, rows) = equilibrium(m, poses);
    let normals: Vec<[f64; 2]> = (m.joints.iter())
        .map(|j| match j.kind {
            crate::model::JointKind::Revolute => [0.0; 2],
            crate::model::JointKind::Prismatic => normal(m, poses, j.markers[0]),
        })
        .collect();
    let mut w = vec![0.0; system.rows];
    let mut on_ground = [0.0; 3];
    for (b, wrench) in applied(m, poses, actual).into_iter().enumerate() {
        for k in 0..3 {
            match rows[b] {
                Some(r) => w[r + k] = wrench[k],
                None => on_ground[k] += wrench[k],
            }
        }
    }
    let solved = plan.solve(&system, &w);
    let shaking = system.on_ground(solved.x.as_slice(), 3);
    let mut r = reactions_of(m, solved, &normals);
    r.shaking = [0, 1, 2].map(|k| shaking[k] + on_ground[k]);
    Some(r)
}

/// The equilibrium equations at `poses` (the loads aside: the right-hand
/// side) and each body's first row (`None` for a fixed body).
fn equilibrium(m: &Mechanism, poses: &[Pose]) -> (System, Vec<Option<usize>>) {
    let rows: Vec<Option<usize>> = {
        let mut next = 0;
        (m.bodies.iter())
            .map(|b| {
                (!b.fixed).then(|| {
                    next += 3;
                    next - 3
                })
            })
            .collect()
    };
    let n_rows = rows.iter().flatten().count() * 3;
    let mut system = System::new(n_rows, 2 * m.joints.len() + m.inputs.len());
    // A force `f` at `p` on body `b` (and minus it on `other`), as column `col`.
    let mut put = |col: usize, b: usize, other: usize, f: [f64; 2], p: [f64; 2], torque: f64| {
        for (body, sign) in [(b, 1.0), (other, -1.0)] {
            let (column, r) = match rows[body] {
                Some(r) => (&mut system.columns[col], r),
                None => (&mut system.ground[col], 0),
            };
            column.push((r, sign * f[0]));
            column.push((r + 1, sign * f[1]));
            column.push((r + 2, sign * (p[0] * f[1] - p[1] * f[0] + torque)));
        }
    };
    let at = |id: MarkerId| poses[id.body].world(m.marker(id).at);
    for (j, joint) in m.joints.iter().enumerate() {
        let [first, second] = joint.markers;
        let p = at(second);
        match joint.kind {
            crate::model::JointKind::Revolute => {
                put(2 * j, second.body, first.body, [1.0, 0.0], p, 0.0);
                put(2 * j + 1, second.body, first.body, [0.0, 1.0], p, 0.0);
            }
            crate::model::JointKind::Prismatic => {
                let n = normal(m, poses, first);
                put(2 * j, second.body, first.body, n, p, 0.0);
                put(2 * j + 1, second.body, first.body, [0.0, 0.0], p, 1.0);
            }
        }
    }
    for (i, input) in m.inputs.iter().enumerate() {
        let [first, second] = m.joints[input.joint].markers;
        let col = 2 * m.joints.len() + i;
        match input.kind {
            InputKind::Angle => put(col, second.body, first.body, [0.0, 0.0], at(second), 1.0),
            InputKind::Slide => {
                let n = normal(m, poses, first);
                put(col, second.body, first.body, [n[1], -n[0]], at(second), 0.0);
            }
        }
    }
    (system, rows)
}

/// The reactions a solution gives; `normals`: each prismatic joint's rail
/// normal at the frame.
fn reactions_of(m: &Mechanism, solved: super::Solved, normals: &[[f64; 2]]) -> Reactions {
    let super::Solved { x, residual, fixed } = solved;
    let joints = m.joints.len();
    Reactions {
        forces: (0..joints)
            .map(|j| match m.joints[j].kind {
                crate::model::JointKind::Revolute => [x[2 * j], x[2 * j + 1]],
                crate::model::JointKind::Prismatic => [x[2 * j] * normals[j][0], x[2 * j] * normals[j][1]],
            })
            .collect(),
        moments: (0..joints)
            .map(|j| match m.joints[j].kind {
                crate::model::JointKind::Revolute => 0.0,
                crate::model::JointKind::Prismatic => x[2 * j + 1],
            })
            .collect(),
        inputs: (0..m.inputs.len()).map(|i| x[2 * joints + i]).collect(),
        indeterminate: (0..joints)
            .filter(|&j| !(fixed[2 * j] && fixed[2 * j + 1]))
            .collect(),
        residual,
        shaking: [0.0; 3],
    }
}

/// The unit normal (the rail's direction turned a quarter counter-clockwise)
/// of the rail marker `rail` at `poses`.
fn normal(m: &Mechanism, poses: &[Pose], rail: MarkerId) -> [f64; 2] {
    let d = m.marker(rail).unit_dir().unwrap_or([1.0, 0.0]);
    let r = &poses[rail.body].rot;
    let world = [r.c * d[0] - r.s * d[1], r.s * d[0] + r.c * d[1]];
    [-world[1], world[0]]
}

/// Every body's applied wrench (force, and moment about the origin) from
/// the loads, gravity and, with `actual` motion, d'Alembert's inertia and
/// the dampers.
fn applied(m: &Mechanism, poses: &[Pose], actual: Option<&[Pose<Jet2>]>) -> Vec<[f64; 3]> {
    let mut w = vec![[0.0; 3]; m.bodies.len()];
    let mut add = |b: usize, f: [f64; 2], p: [f64; 2], torque: f64| {
        w[b][0] += f[0];
        w[b][1] += f[1];
        w[b][2] += p[0] * f[1] - p[1] * f[0] + torque;
    };
    let at = |id: MarkerId| poses[id.body].world(m.marker(id).at);
    for load in &m.loads.applied {
        match &load.kind {
            LoadKind::Force {
                marker,
                force,
                body_axes,
            } => {
                let r = &poses[marker.body].rot;
                let f = if *body_axes {
                    [r.c * force[0] - r.s * force[1], r.s * force[0] + r.c * force[1]]
                } else {
                    *force
                };
                add(marker.body, f, at(*marker), 0.0);
            }
            LoadKind::Torque { body, torque } => add(*body, [0.0; 2], [0.0; 2], *torque),
            LoadKind::Spring {
                markers,
                stiffness,
                free_length,
            } => {
                let (p, q) = (at(markers[0]), at(markers[1]));
                let (len, u) = towards(p, q);
                let t = stiffness * (len - free_length);
                // A tension pulls each end toward the other.
                add(markers[0].body, [t * u[0], t * u[1]], p, 0.0);
                add(markers[1].body, [-t * u[0], -t * u[1]], q, 0.0);
            }
            LoadKind::Damper { markers, damping } => {
                let Some(a) = actual else { continue };
                let w = |id: MarkerId| a[id.body].world(m.marker(id).at);
                let t = damping * stretch(w(markers[0]), w(markers[1])).1;
                let (p, q) = (at(markers[0]), at(markers[1]));
                let (_, u) = towards(p, q);
                add(markers[0].body, [t * u[0], t * u[1]], p, 0.0);
                add(markers[1].body, [-t * u[0], -t * u[1]], q, 0.0);
            }
            LoadKind::TorsionSpring {
                joint,
                stiffness,
                free_angle,
            } => {
                let [first, second] = m.joints[*joint].markers;
                let (ra, rb) = (&poses[first.body].rot, &poses[second.body].rot);
                let turn = (rb.s * ra.c - rb.c * ra.s).atan2(rb.c * ra.c + rb.s * ra.s);
                let torque = stiffness * (turn - free_angle);
                add(second.body, [0.0; 2], [0.0; 2], -torque);
                add(first.body, [0.0; 2], [0.0; 2], torque);
            }
        }
    }
    for (b, pose) in poses.iter().enumerate() {
        let Some((f, torque)) = weight(m, b, actual) else {
            continue;
        };
        let c = pose.world(m.loads.mass(b).map_or([0.0; 2], |mass| mass.centre));
        add(b, f, c, torque);
    }
    w
}

/// The distance from `p` to `q` and the unit vector from `p` toward `q`
/// (0 where they meet).
fn towards(p: [f64; 2], q: [f64; 2]) -> (f64, [f64; 2]) {
    let d = [q[0] - p[0], q[1] - p[1]];
    let len = d[0].hypot(d[1]);
    if len == 0.0 {
        return (0.0, [0.0; 2]);
    }
    (len, [d[0] / len, d[1] / len])
}

pub use super::Advantage;

/// [`Advantage`] at the frame `state` was solved to; `None` for a
/// mechanism with more or fewer than one input.
pub fn advantage(
    m: &Mechanism,
    interp: &Interpreter,
    state: &InterpState,
    inputs: &[f64],
) -> Option<Result<Advantage, RateError>> {
    let size = m.size();
    super::mechanical_advantage(
        &m.inputs,
        size,
        |unit| interp.rates(state, inputs, unit, &[0.0]),
        |v| (0..m.joints.len()).map(|j| Some(joint_rate(m, v, j))).collect(),
        |v| {
            (m.all_markers())
                .map(|id| {
                    let p = v[id.body].world(m.marker(id).at);
                    p[0].d.hypot(p[1].d)
                })
                .collect()
        },
    )
}

/// Joint `j`'s relative turn or slide rate at the motion `v`, with the
/// scale of its round-off (1 for a turn, the mechanism's size for a slide).
fn joint_rate(m: &Mechanism, v: &[Pose<Jet2>], j: usize) -> (f64, f64) {
    let joint = &m.joints[j];
    let [first, second] = joint.markers;
    match joint.kind {
        crate::model::JointKind::Revolute => (omega(&v[second.body]) - omega(&v[first.body]), 1.0),
        crate::model::JointKind::Prismatic => {
            // The slider's marker against the rail's material point under
            // it (fixed in the rail's body), along the rail.
            let p = v[second.body].world(m.marker(second).at);
            let (a, r) = (&v[first.body], &v[first.body].rot);
            let off = [p[0].v - a.at[0].v, p[1].v - a.at[1].v];
            let under_local = [r.c.v * off[0] + r.s.v * off[1], -r.s.v * off[0] + r.c.v * off[1]];
            let under = a.world(under_local);
            let d = m.marker(first).unit_dir().unwrap_or([1.0, 0.0]);
            let dir = [r.c.v * d[0] - r.s.v * d[1], r.s.v * d[0] + r.c.v * d[1]];
            (
                dir[0] * (p[0].d - under[0].d) + dir[1] * (p[1].d - under[1].d),
                m.size(),
            )
        }
    }
}
