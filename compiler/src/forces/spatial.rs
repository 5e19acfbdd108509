//! A spatial frame's input forces by virtual work and its joint reactions
//! from every body's equilibrium (see the module above): the planar
//! analysis lifted to space, with forces and torques as 3-vectors, each
//! body's inertia a tensor carried by its rotation, and each joint kind
//! carrying the components of force and moment its freedoms leave.

use dofplan_runtime::scalar::Jet2;
use dofplan_runtime::spatial::{add, cross, dot, norm, scale, sub, Pose3, Rot3, Vec3};

use super::plan::{ForcePlan, System};
use crate::interp::spatial::{InterpState, Interpreter};
use crate::interp::RateError;
use crate::model::spatial::equations::{joint_frames, Frame};
use crate::model::spatial::loads::LoadKind;
use crate::model::spatial::{JointKind, Mechanism};
use crate::model::{InputKind, MarkerId};

pub use super::planar::Moving;
pub use super::Advantage;

/// The force (slide) or torque (angle, per radian) each input must supply
/// at the frame `state` was solved to, for the mechanism to hold there
/// (`moving` None: statics) or to move as `moving` says (kinetostatics:
/// d'Alembert, with each body's inertia tensor). Positive in the input's
/// positive direction. An error where the plan's rates are not defined.
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

/// [`Advantage`] at the frame `state` was solved to; `None` for a
/// mechanism with more or fewer than one input. A joint's is about its
/// one freedom: a revolute or helical joint's turn about its axis, a
/// prismatic joint's slide along it; a joint with more than one relative
/// freedom (cylindrical, universal, spherical, planar) or none (fixed)
/// has none.
pub fn advantage(
    m: &Mechanism,
    interp: &Interpreter,
    state: &InterpState,
    inputs: &[f64],
) -> Option<Result<Advantage, RateError>> {
    super::mechanical_advantage(
        &m.inputs,
        m.size(),
        |unit| interp.rates(state, inputs, unit, &[0.0]),
        |v| (0..m.joints.len()).map(|j| joint_rate(m, v, j)).collect(),
        |v| {
            (m.all_markers())
                .map(|id| norm(rate(v[id.body].world(m.marker(id).at))))
                .collect()
        },
    )
}

/// Joint `j`'s relative turn or slide rate at the motion `v` along its
/// axis, with the scale of its round-off (1 for a turn, the mechanism's
/// size for a slide); `None` for a joint without exactly one freedom.
fn joint_rate(m: &Mechanism, v: &[Pose3<Jet2>], j: usize) -> Option<(f64, f64)> {
    let joint = &m.joints[j];
    let [first, second] = joint.markers.map(|id| id.body);
    let values: Vec<Pose3> = v.iter().map(Pose3::value).collect();
    let z = joint_axes(m, j, &values)[2];
    match joint.kind {
        JointKind::Revolute | JointKind::Helical => {
            Some((dot(sub(omega(&v[second]), omega(&v[first])), z), 1.0))
        }
        JointKind::Prismatic => {
            // The second marker against the first body's material point
            // under it, along the axis.
            let own = v[second].world(m.marker(joint.markers[1]).at);
            let arm = sub(own.map(|c| c.v), values[first].pos);
            let under = add(rate(v[first].pos), cross(omega(&v[first]), arm));
            Some((dot(sub(rate(own), under), z), m.size()))
        }
        _ => None,
    }
}

/// The power every load delivers (and with `actual` motion, the bodies'
/// d'Alembert inertia) at the virtual motion `v` (its first derivatives).
fn power(m: &Mechanism, v: &[Pose3<Jet2>], actual: Option<&[Pose3<Jet2>]>) -> f64 {
    let at = |poses: &[Pose3<Jet2>], id: MarkerId| poses[id.body].world(m.marker(id).at);
    let values: Vec<Pose3> = v.iter().map(Pose3::value).collect();
    let mut p = 0.0;
    for load in &m.loads.applied {
        p += match &load.kind {
            LoadKind::Force {
                marker,
                force,
                body_axes,
            } => {
                let f = world_force(&values[marker.body], *force, *body_axes);
                dot(f, rate(at(v, *marker)))
            }
            LoadKind::Torque { body, torque } => dot(*torque, omega(&v[*body])),
            LoadKind::Spring {
                markers,
                stiffness,
                free_length,
            } => {
                let (length, rate) = stretch(at(v, markers[0]), at(v, markers[1]));
                -stiffness * (length - free_length) * rate
            }
            LoadKind::Damper { markers, damping } => {
                let speed = actual.map_or(0.0, |a| stretch(at(a, markers[0]), at(a, markers[1])).1);
                let (_, rate) = stretch(at(v, markers[0]), at(v, markers[1]));
                -damping * speed * rate
            }
            LoadKind::TorsionSpring {
                joint,
                stiffness,
                free_angle,
            } => {
                let (turn, axis) = relative_turn(m, *joint, &values);
                let [a, b] = m.joints[*joint].markers.map(|id| id.body);
                -stiffness * (turn - free_angle) * dot(axis, sub(omega(&v[b]), omega(&v[a])))
            }
        };
    }
    for (b, pose) in v.iter().enumerate() {
        let Some((f, torque)) = weight(m, b, &values[b], actual) else {
            continue;
        };
        let c = pose.world(m.loads.mass(b).map_or([0.0; 3], |mass| mass.centre));
        p += dot(f, rate(c)) + dot(torque, omega(pose));
    }
    p
}

/// A force given in world axes, or in the axes of the body at `pose`.
fn world_force(pose: &Pose3, force: Vec3, body_axes: bool) -> Vec3 {
    if body_axes {
        pose.rot.apply(force)
    } else {
        force
    }
}

/// What body `b`'s mass puts on it, at its centre: gravity's force and,
/// with `actual` motion, d'Alembert's (minus the mass times the centre's
/// acceleration) and its torque, minus `I·α + ω × I·ω` with the inertia
/// tensor turned with the body (`R I Rᵀ`). `None` for a body without mass.
fn weight(m: &Mechanism, b: usize, pose: &Pose3, actual: Option<&[Pose3<Jet2>]>) -> Option<(Vec3, Vec3)> {
    let mass = m.loads.mass(b)?;
    let mut f = (m.loads.gravity).map_or([0.0; 3], |g| scale(g, mass.mass));
    let mut torque = [0.0; 3];
    if let Some(a) = actual {
        let ca = a[b].world(mass.centre);
        f = sub(f, scale(ca.map(|c| c.dd), mass.mass));
        let inertia = world_inertia(&pose.rot, &mass.inertia);
        let (w, alpha) = (omega(&a[b]), alpha(&a[b]));
        torque = sub(torque, add(mul(&inertia, alpha), cross(w, mul(&inertia, w))));
    }
    Some((f, torque))
}

/// `R I Rᵀ`: an inertia tensor given in the drawn axes, in the world's.
fn world_inertia(r: &Rot3, inertia: &[[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut out = [[0.0; 3]; 3];
    for (i, row) in out.iter_mut().enumerate() {
        for (j, cell) in row.iter_mut().enumerate() {
            *cell = (0..3)
                .map(|k| (0..3).map(|l| r.m[i][k] * inertia[k][l] * r.m[j][l]).sum::<f64>())
                .sum();
        }
    }
    out
}

/// A matrix times a vector.
fn mul(a: &[[f64; 3]; 3], v: Vec3) -> Vec3 {
    [dot(a[0], v), dot(a[1], v), dot(a[2], v)]
}

/// A point's velocity from its jet.
fn rate(p: Vec3<Jet2>) -> Vec3 {
    p.map(|c| c.d)
}

/// The axial vector of the skew part of `a·rᵀ` (its rows `a`, `r`): ω
/// from (Ṙ, R), α from (R̈, R), since `Ṙ Rᵀ = [ω]×` and `R̈ Rᵀ = [α]× +
/// [ω]×²` whose second term is symmetric.
fn axial(a: impl Fn(usize, usize) -> f64, r: impl Fn(usize, usize) -> f64) -> Vec3 {
    let prod = |i: usize, j: usize| (0..3).map(|k| a(i, k) * r(j, k)).sum::<f64>();
    [
        0.5 * (prod(2, 1) - prod(1, 2)),
        0.5 * (prod(0, 2) - prod(2, 0)),
        0.5 * (prod(1, 0) - prod(0, 1)),
    ]
}

/// A body's angular velocity (world axes) from its pose's jet.
fn omega(p: &Pose3<Jet2>) -> Vec3 {
    axial(|i, k| p.rot.m[i][k].d, |j, k| p.rot.m[j][k].v)
}

/// A body's angular acceleration (world axes) from its pose's jet.
fn alpha(p: &Pose3<Jet2>) -> Vec3 {
    axial(|i, k| p.rot.m[i][k].dd, |j, k| p.rot.m[j][k].v)
}

/// The distance between two points and its rate.
fn stretch(a: Vec3<Jet2>, b: Vec3<Jet2>) -> (f64, f64) {
    let d = sub(b.map(|c| c.v), a.map(|c| c.v));
    let length = norm(d);
    if length == 0.0 {
        return (0.0, 0.0);
    }
    (length, dot(d, sub(rate(b), rate(a))) / length)
}

/// A joint's frames (its first marker's point and axes, its second's) at
/// `poses`.
fn frames(m: &Mechanism, joint: usize, poses: &[Pose3]) -> [Frame; 2] {
    let j = &m.joints[joint];
    let drawn = joint_frames(j, |id| m.marker(id).at, |id| m.marker(id).axes);
    [0, 1].map(|k| drawn[k].moved(&poses[j.markers[k].body]))
}

/// A joint's first marker's axes `[x, y, z]` (z its axis) in world axes
/// at `poses`: what the joint's reaction components are along.
pub fn joint_axes(m: &Mechanism, joint: usize, poses: &[Pose3]) -> [Vec3; 3] {
    let a = frames(m, joint, poses)[0].axes;
    [a.x, a.y(), a.z]
}

/// How far a joint that turns about one axis (revolute, cylindrical) has
/// turned its second body relative to its first since the drawing, in
/// radians in (−π, π], about its axis (the first marker's z, world).
fn relative_turn(m: &Mechanism, joint: usize, poses: &[Pose3]) -> (f64, Vec3) {
    let j = &m.joints[joint];
    let [first, _] = frames(m, joint, poses);
    // The first marker's x as each body carries it: they agree as drawn.
    let x = joint_frames(j, |id| m.marker(id).at, |id| m.marker(id).axes)[0]
        .axes
        .x;
    let [a, b] = j.markers.map(|id| poses[id.body].dir(x));
    let z = first.axes.z;
    (dot(z, cross(a, b)).atan2(dot(a, b)), z)
}

/// A frame's joint reactions, with the input forces the same equations
/// give.
#[derive(Clone, Debug, PartialEq)]
pub struct Reactions {
    /// Per joint: the force its first body exerts on its second, world
    /// axes, at the second marker.
    pub forces: Vec<Vec3>,
    /// Per joint: the moment its first body exerts on its second about
    /// the second marker (0 where the joint carries none: a spherical
    /// joint, and about a joint's free axes).
    pub moments: Vec<Vec3>,
    /// Per input: its force or torque, from every body's equilibrium (the
    /// same as [`input_forces`]' virtual work where both are defined).
    pub inputs: Vec<f64>,
    /// The joints whose reactions the equations do not fix (an
    /// over-constrained mechanism); the values given are then the
    /// least-norm ones.
    pub indeterminate: Vec<usize>,
    /// The largest force or moment left unbalanced on a body.
    pub residual: f64,
    /// What the mechanism does to the ground (every fixed body): the force
    /// and the moment about the origin, `[fx, fy, fz, mx, my, mz]`.
    pub shaking: [f64; 6],
}

/// The force and moment directions a joint of this kind carries, in its
/// first marker's axes (`x`, `y`, `z`) at the frame, each a unit wrench
/// `(force, moment)`; `z2` is the second marker's z (a universal joint's
/// cross pin) and `lead` a helical joint's advance per radian.
fn carried(kind: JointKind, axes: [Vec3; 3], z2: Vec3, lead: f64) -> Vec<(Vec3, Vec3)> {
    let [x, y, z] = axes;
    let o = [0.0; 3];
    let force = |d: Vec3| (d, o);
    let moment = |d: Vec3| (o, d);
    match kind {
        JointKind::Revolute => vec![force(x), force(y), force(z), moment(x), moment(y)],
        JointKind::Prismatic => vec![force(x), force(y), moment(x), moment(y), moment(z)],
        JointKind::Cylindrical => vec![force(x), force(y), moment(x), moment(y)],
        JointKind::Spherical => vec![force(x), force(y), force(z)],
        JointKind::Universal => {
            // The one turn a cross pin stops: about the axis across both
            // pins.
            let n = cross(z, z2);
            let len = norm(n);
            let n = if len > 0.0 { scale(n, 1.0 / len) } else { x };
            vec![force(x), force(y), force(z), moment(n)]
        }
        JointKind::Planar => vec![force(z), moment(x), moment(y)],
        JointKind::Fixed => vec![force(x), force(y), force(z), moment(x), moment(y), moment(z)],
        // A screw's thread pushes along the axis and twists about it in
        // one ratio: no power on the screw motion (`f·lead + m = 0`).
        JointKind::Helical => vec![force(x), force(y), moment(x), moment(y), (z, scale(z, -lead))],
    }
}

/// The plan for the reaction unknowns of `m` (see `forces/plan.rs`), from
/// its equations at the drawn pose; `None` for a mechanism with primitive
/// constraints, whose forces are not modelled yet.
pub fn force_plan(m: &Mechanism) -> Option<ForcePlan> {
    if !m.constraints.is_empty() {
        return None;
    }
    let drawn = vec![Pose3::IDENTITY; m.bodies.len()];
    Some(ForcePlan::new(&equilibrium(m, &drawn).system))
}

/// A frame's equilibrium equations (the loads aside) and how to read
/// their unknowns.
struct Equilibrium {
    system: System,
    /// Each body's first row (`None` for a fixed body).
    rows: Vec<Option<usize>>,
    /// Per joint: its first unknown and its unit wrenches.
    joints: Vec<(usize, Vec<(Vec3, Vec3)>)>,
    /// The first input's unknown.
    inputs: usize,
}

/// The equilibrium equations at `poses`: six per moving body, one unknown
/// per component each joint carries and one per input.
fn equilibrium(m: &Mechanism, poses: &[Pose3]) -> Equilibrium {
    let rows: Vec<Option<usize>> = {
        let mut next = 0;
        (m.bodies.iter())
            .map(|b| {
                (!b.fixed).then(|| {
                    next += 6;
                    next - 6
                })
            })
            .collect()
    };
    let n_rows = rows.iter().flatten().count() * 6;
    // Each joint's unit wrenches, at its second marker.
    let joint_wrenches: Vec<(Vec3, Vec<(Vec3, Vec3)>)> = (0..m.joints.len())
        .map(|j| {
            let [_, second] = frames(m, j, poses);
            let lead = m.joints[j].pitch / std::f64::consts::TAU;
            let axes = joint_axes(m, j, poses);
            (second.at, carried(m.joints[j].kind, axes, second.axes.z, lead))
        })
        .collect();
    let n_cols = joint_wrenches.iter().map(|(_, w)| w.len()).sum::<usize>() + m.inputs.len();
    let mut system = System::new(n_rows, n_cols);
    // A wrench (force `f` at `p`, moment `mo`) on body `b` and minus it on
    // `other`, as column `col`.
    let mut put = |col: usize, b: usize, other: usize, (f, mo): (Vec3, Vec3), p: Vec3| {
        let about = add(cross(p, f), mo);
        for (body, sign) in [(b, 1.0), (other, -1.0)] {
            let (column, r) = match rows[body] {
                Some(r) => (&mut system.columns[col], r),
                None => (&mut system.ground[col], 0),
            };
            for k in 0..3 {
                column.push((r + k, sign * f[k]));
                column.push((r + 3 + k, sign * about[k]));
            }
        }
    };
    let mut col = 0;
    let mut joints = Vec::with_capacity(m.joints.len());
    for (j, (p, wrenches)) in joint_wrenches.into_iter().enumerate() {
        let [first, second] = m.joints[j].markers.map(|id| id.body);
        for (k, &w) in wrenches.iter().enumerate() {
            put(col + k, second, first, w, p);
        }
        joints.push((col, wrenches));
        col = joints.last().map_or(0, |(c, w)| c + w.len());
    }
    for (i, input) in m.inputs.iter().enumerate() {
        let [first, second] = frames(m, input.joint, poses);
        let [b1, b2] = m.joints[input.joint].markers.map(|id| id.body);
        let z = first.axes.z;
        let w = match input.kind {
            InputKind::Angle => ([0.0; 3], z),
            InputKind::Slide => (z, [0.0; 3]),
        };
        put(col + i, b2, b1, w, second.at);
    }
    Equilibrium {
        system,
        rows,
        joints,
        inputs: col,
    }
}

/// The joint reactions at `poses` from every moving body's force and
/// moment equilibrium under the file's loads (with `actual` motion, the
/// bodies' d'Alembert inertia and the dampers too), solved as `plan` says
/// (block by block, or by least squares, least norm where the mechanism is
/// over-constrained). `None` for a mechanism with primitive constraints,
/// whose forces are not modelled yet.
pub fn reactions(
    m: &Mechanism,
    plan: &ForcePlan,
    poses: &[Pose3],
    actual: Option<&[Pose3<Jet2>]>,
) -> Option<Reactions> {
    if !m.constraints.is_empty() {
        return None;
    }
    let e = equilibrium(m, poses);
    let mut w = vec![0.0; e.system.rows];
    let mut on_ground = [0.0; 6];
    for (b, wrench) in applied(m, poses, actual).into_iter().enumerate() {
        for k in 0..6 {
            match e.rows[b] {
                Some(r) => w[r + k] = wrench[k],
                None => on_ground[k] += wrench[k],
            }
        }
    }
    let super::Solved { x, residual, fixed } = plan.solve(&e.system, &w);
    let shaking = e.system.on_ground(x.as_slice(), 6);
    let mut r = Reactions {
        forces: Vec::with_capacity(m.joints.len()),
        moments: Vec::with_capacity(m.joints.len()),
        inputs: (0..m.inputs.len()).map(|i| x[e.inputs + i]).collect(),
        indeterminate: Vec::new(),
        residual,
        shaking: [0, 1, 2, 3, 4, 5].map(|k| shaking[k] + on_ground[k]),
    };
    for (j, (first, wrenches)) in e.joints.iter().enumerate() {
        let (mut f, mut mo) = ([0.0; 3], [0.0; 3]);
        for (k, (wf, wm)) in wrenches.iter().enumerate() {
            let amount = x[first + k];
            f = add(f, scale(*wf, amount));
            mo = add(mo, scale(*wm, amount));
        }
        r.forces.push(f);
        r.moments.push(mo);
        if !(0..wrenches.len()).all(|k| fixed[first + k]) {
            r.indeterminate.push(j);
        }
    }
    Some(r)
}

/// Every body's applied wrench (force, and moment about the origin:
/// `[fx, fy, fz, mx, my, mz]`) from the loads, gravity and, with `actual`
/// motion, d'Alembert's inertia and the dampers.
fn applied(m: &Mechanism, poses: &[Pose3], actual: Option<&[Pose3<Jet2>]>) -> Vec<[f64; 6]> {
    let mut w = vec![[0.0; 6]; m.bodies.len()];
    let mut add_to = |b: usize, f: Vec3, p: Vec3, torque: Vec3| {
        let about = add(cross(p, f), torque);
        for k in 0..3 {
            w[b][k] += f[k];
            w[b][3 + k] += about[k];
        }
    };
    let at = |id: MarkerId| poses[id.body].world(m.marker(id).at);
    let o = [0.0; 3];
    for load in &m.loads.applied {
        match &load.kind {
            LoadKind::Force {
                marker,
                force,
                body_axes,
            } => add_to(
                marker.body,
                world_force(&poses[marker.body], *force, *body_axes),
                at(*marker),
                o,
            ),
            LoadKind::Torque { body, torque } => add_to(*body, o, o, *torque),
            LoadKind::Spring {
                markers,
                stiffness,
                free_length,
            } => {
                let (p, q) = (at(markers[0]), at(markers[1]));
                let (len, u) = towards(p, q);
                let t = stiffness * (len - free_length);
                // A tension pulls each end toward the other.
                add_to(markers[0].body, scale(u, t), p, o);
                add_to(markers[1].body, scale(u, -t), q, o);
            }
            LoadKind::Damper { markers, damping } => {
                let Some(a) = actual else { continue };
                let wa = |id: MarkerId| a[id.body].world(m.marker(id).at);
                let t = damping * stretch(wa(markers[0]), wa(markers[1])).1;
                let (p, q) = (at(markers[0]), at(markers[1]));
                let (_, u) = towards(p, q);
                add_to(markers[0].body, scale(u, t), p, o);
                add_to(markers[1].body, scale(u, -t), q, o);
            }
            LoadKind::TorsionSpring {
                joint,
                stiffness,
                free_angle,
            } => {
                let (turn, axis) = relative_turn(m, *joint, poses);
                let torque = scale(axis, stiffness * (turn - free_angle));
                let [first, second] = m.joints[*joint].markers.map(|id| id.body);
                add_to(second, o, o, scale(torque, -1.0));
                add_to(first, o, o, torque);
            }
        }
    }
    for (b, pose) in poses.iter().enumerate() {
        let Some((f, torque)) = weight(m, b, pose, actual) else {
            continue;
        };
        let c = pose.world(m.loads.mass(b).map_or([0.0; 3], |mass| mass.centre));
        add_to(b, f, c, torque);
    }
    w
}

/// The distance from `p` to `q` and the unit vector from `p` toward `q`
/// (0 where they meet).
fn towards(p: Vec3, q: Vec3) -> (f64, Vec3) {
    let d = sub(q, p);
    let len = norm(d);
    if len == 0.0 {
        return (0.0, [0.0; 3]);
    }
    (len, scale(d, 1.0 / len))
}
