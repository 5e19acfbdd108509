//! A planar frame's joint reactions and input forces from every moving
//! body's force and moment equilibrium: the per-frame half of the force
//! plan, shared by the interpreter and compiled modules' `solve_forces`.
//!
//! The compiler describes a mechanism's forces once, as a [`Table`]: its
//! force unknowns (each joint's reaction components, each input's force
//! or torque) with the bodies they act between, its loads and masses, and
//! the blocks its force plan solves in order (a perfect matching of
//! equations to unknowns and the strongly connected components of what
//! each needs). Each frame, [`applied`] gives every body's load,
//! [`column()`] each unknown's share in the equations at the frame's poses,
//! and [`solve_blocks`] the unknowns block by block, each a dense solve
//! of its own size, on the caller's scratch (no allocation).
//!
//! Equations: three per moving body (force x, force y, moment about the
//! body's [`Table::about`] point), in body order; a fixed body's share
//! goes to the shaking force instead (its moment about the world origin).
//! Unknown `u` enters as a unit wrench on its `second` body and minus it
//! on its `first`: a reaction is the force the joint's first body exerts
//! on its second.

use super::{Point, Pose};
use crate::numeric::lu_solve;
use crate::scalar::Jet2;

/// One force unknown: what a unit of it does to the two bodies it acts
/// between.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Unknown {
    /// A force along world x (`axis` 0) or y (1) at `at` (a marker of
    /// `second`, local): a revolute joint's reaction components.
    Pin {
        /// The joint's first body.
        first: usize,
        /// Its second body.
        second: usize,
        /// The second marker, local.
        at: Point,
        /// 0 for x, 1 for y.
        axis: usize,
    },
    /// A force across the rail `dir` of `first` (a unit direction in
    /// `first`'s axes, turned a quarter counter-clockwise) at `at`: a
    /// prismatic joint's reaction.
    Across {
        /// The rail's body.
        first: usize,
        /// The slider's.
        second: usize,
        /// The slider's marker, local.
        at: Point,
        /// The rail's direction, `first`'s axes.
        dir: Point,
    },
    /// A pure moment: a prismatic joint's, or an angle input's torque.
    Moment {
        /// The first body.
        first: usize,
        /// The second body.
        second: usize,
    },
    /// A tooth force between two gears (or a pinion and its rack) at the
    /// pitch point `at` of their carrier, along `dir` in the carrier's
    /// axes: the common tangent leaned by the pressure angle, not of unit
    /// length (the unknown is the force's tangential component).
    Mesh {
        /// The first gear (the pinion of a rack).
        first: usize,
        /// The second gear (the rack).
        second: usize,
        /// The body both turn (or slide) on; a fixed one stands still.
        carrier: usize,
        /// The pitch point, the carrier's local coordinates.
        at: Point,
        /// The force on `second` per unit, the carrier's axes.
        dir: Point,
    },
    /// A force along the radius of a circular slot of `first` about
    /// `centre`, at the pin `at` of `second` (positive pushing the pin
    /// outward): a pin in an arc slot's reaction.
    Radial {
        /// The slot's body.
        first: usize,
        /// The pin's.
        second: usize,
        /// The slot's centre, `first`'s local coordinates.
        centre: Point,
        /// The pin, `second`'s local coordinates.
        at: Point,
    },
    /// A force along the rail `dir` of `first` at `at`: a slide input's.
    Along {
        /// The rail's body.
        first: usize,
        /// The slider's.
        second: usize,
        /// The slider's marker, local.
        at: Point,
        /// The rail's direction, `first`'s axes.
        dir: Point,
    },
}

impl Unknown {
    /// The two bodies: `[first, second]`.
    pub fn bodies(&self) -> [usize; 2] {
        match *self {
            Unknown::Pin { first, second, .. }
            | Unknown::Across { first, second, .. }
            | Unknown::Moment { first, second }
            | Unknown::Mesh { first, second, .. }
            | Unknown::Radial { first, second, .. }
            | Unknown::Along { first, second, .. } => [first, second],
        }
    }
}

/// A load the file gives, its markers as (body, local point).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Load {
    /// A constant force at a point of a body, in world axes or (`body_axes`)
    /// turning with the body.
    Force {
        /// The body.
        body: usize,
        /// The point, local.
        at: Point,
        /// The force.
        force: Point,
        /// Given in the body's axes.
        body_axes: bool,
    },
    /// A constant torque on a body.
    Torque {
        /// The body.
        body: usize,
        /// Counter-clockwise positive.
        torque: f64,
    },
    /// A linear spring between two points: tension `stiffness × (length −
    /// free_length)` pulls them together.
    Spring {
        /// First end.
        a: (usize, Point),
        /// Second end.
        b: (usize, Point),
        /// Force per length.
        stiffness: f64,
        /// Length at which it pulls nothing.
        free_length: f64,
    },
    /// A linear damper between two points: tension `damping × d(length)/dt`
    /// (idle held still).
    Damper {
        /// First end.
        a: (usize, Point),
        /// Second end.
        b: (usize, Point),
        /// Force per (length per second).
        damping: f64,
    },
    /// A torsion spring at a revolute joint: `stiffness × (φ − free_angle)`
    /// resisting the turn φ of `second` relative to `first` since the
    /// drawing (radians, in (−π, π]).
    TorsionSpring {
        /// The joint's first body.
        first: usize,
        /// Its second body.
        second: usize,
        /// Torque per radian.
        stiffness: f64,
        /// Radians.
        free_angle: f64,
    },
}

/// A body's mass, for gravity and (running) d'Alembert's inertia.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mass {
    /// The body.
    pub body: usize,
    /// Its centre of mass, local.
    pub centre: Point,
    /// Its mass.
    pub mass: f64,
    /// Its moment of inertia about the centre.
    pub inertia: f64,
}

/// A gear pair's tooth force leaned the other way: the teeth always push
/// apart, so a pair's line of action leans by the pressure angle one way
/// for a positive tangential force and the other for a negative one. The
/// table's own unknown leans the positive way; a frame whose force comes
/// out negative is solved again with `other` in its place (the blocks'
/// shape is the same, only the direction differs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lean {
    /// The gear pair's unknown in [`Table::unknowns`].
    pub unknown: usize,
    /// The same tooth force leaning the negative way.
    pub other: Unknown,
}

/// One block of the force plan: equations and the unknowns they fix
/// together, as many of each.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Block<'a> {
    /// Equation rows.
    pub rows: &'a [usize],
    /// Unknowns.
    pub cols: &'a [usize],
}

/// A mechanism's forces as the compiler describes them once.
#[derive(Clone, Copy, Debug)]
pub struct Table<'a> {
    /// Per body: its first equation row (`None`: fixed, the ground).
    pub rows: &'a [Option<usize>],
    /// How many equation rows (3 per moving body).
    pub n_rows: usize,
    /// The unknowns: two per joint (`2j`, `2j + 1`), then one per input.
    pub unknowns: &'a [Unknown],
    /// The loads.
    pub loads: &'a [Load],
    /// The bodies with mass.
    pub masses: &'a [Mass],
    /// Gravity's acceleration.
    pub gravity: Point,
    /// The blocks, in the order they are solved (empty: the plan solves
    /// by least squares, which is the compiler's).
    pub blocks: &'a [Block<'a>],
    /// Per body, the point (local) its moment equation is taken about: a
    /// pin of the body where the force plan chose one, whose reaction
    /// then leaves that equation (a dyad's moments about its outer pins
    /// give its middle pin's force alone: two unknowns, not six); the
    /// body's local origin otherwise.
    pub about: &'a [Point],
    /// Each gear pair's tooth force leaned the negative way (none without
    /// gear pairs).
    pub leaning: &'a [Lean],
}

/// Where the frame's forces `x` make a gear pair's tangential force
/// negative, `unknowns` becomes the table's unknowns with that pair's
/// [`Lean::other`] in place, to solve the frame again with (`false`, and
/// `unknowns` untouched, where every pair leans the table's way).
/// `unknowns` is as long as the table's.
#[inline(always)]
pub fn lean_by_sign(t: &Table, x: &[f64], unknowns: &mut [Unknown]) -> bool {
    let mut leaned = false;
    for lean in t.leaning.iter().filter(|l| x[l.unknown] < 0.0) {
        if !leaned {
            unknowns.copy_from_slice(t.unknowns);
            leaned = true;
        }
        unknowns[lean.unknown] = lean.other;
    }
    leaned
}

/// The largest block [`solve_blocks`] solves: its scratch is a `k × k`
/// matrix and `k` right-hand sides.
pub const fn scratch_len(largest_block: usize) -> usize {
    largest_block * largest_block + largest_block
}

/// A wrench `[fx, fy, m]` (moment about the world origin) of the force
/// `f` at the world point `p` plus a pure `torque`.
#[inline(always)]
fn wrench(f: Point, p: Point, torque: f64) -> [f64; 3] {
    [f[0], f[1], p[0] * f[1] - p[1] * f[0] + torque]
}

/// The wrench `w` (moment about the world origin) with its moment taken
/// about the world point `p` instead.
#[inline(always)]
pub fn moved(w: [f64; 3], p: Point) -> [f64; 3] {
    [w[0], w[1], w[2] - (p[0] * w[1] - p[1] * w[0])]
}

/// Where body `b`'s moment equation is taken about, in the world.
#[inline(always)]
fn about(t: &Table, poses: &[Pose], b: usize) -> Point {
    poses[b].world(t.about[b])
}

/// A local direction of a body in world axes.
#[inline(always)]
fn turned(pose: &Pose, d: Point) -> Point {
    let r = &pose.rot;
    [r.c * d[0] - r.s * d[1], r.s * d[0] + r.c * d[1]]
}

/// What a unit of unknown `u` puts on its second body at `poses` (its
/// first body takes minus this).
#[inline(always)]
pub fn column(u: &Unknown, poses: &[Pose]) -> [f64; 3] {
    match *u {
        Unknown::Pin { second, at, axis, .. } => {
            // Not `f[axis] = 1.0`: a store at a computed place, read back
            // whole at once, stalls the read (a tenth of a frame's forces).
            let f = if axis == 0 { [1.0, 0.0] } else { [0.0, 1.0] };
            wrench(f, poses[second].world(at), 0.0)
        }
        Unknown::Across {
            first,
            second,
            at,
            dir,
        } => {
            let d = turned(&poses[first], dir);
            wrench([-d[1], d[0]], poses[second].world(at), 0.0)
        }
        Unknown::Moment { .. } => [0.0, 0.0, 1.0],
        Unknown::Mesh { carrier, at, dir, .. } => {
            wrench(turned(&poses[carrier], dir), poses[carrier].world(at), 0.0)
        }
        Unknown::Radial {
            first,
            second,
            centre,
            at,
        } => {
            let pin = poses[second].world(at);
            wrench(towards(poses[first].world(centre), pin).1, pin, 0.0)
        }
        Unknown::Along {
            first,
            second,
            at,
            dir,
        } => {
            // The normal turned back a quarter: along the rail, so that a
            // positive force pushes the slide's positive way.
            let d = turned(&poses[first], dir);
            wrench(d, poses[second].world(at), 0.0)
        }
    }
}

/// The distance from `p` to `q` and the unit vector from `p` toward `q`
/// (0 where they meet).
#[inline(always)]
fn towards(p: Point, q: Point) -> (f64, Point) {
    let d = [q[0] - p[0], q[1] - p[1]];
    let len = d[0].hypot(d[1]);
    if len == 0.0 {
        return (0.0, [0.0; 2]);
    }
    (len, [d[0] / len, d[1] / len])
}

/// The rate at which the distance between two moving points changes.
#[inline(always)]
fn stretch_rate(a: [Jet2; 2], b: [Jet2; 2]) -> f64 {
    let d = [b[0].v - a[0].v, b[1].v - a[1].v];
    let length = d[0].hypot(d[1]);
    if length == 0.0 {
        return 0.0;
    }
    (d[0] * (b[0].d - a[0].d) + d[1] * (b[1].d - a[1].d)) / length
}

/// Every body's applied wrench into `out` (one per body, zeroed first):
/// the loads and gravity at `poses` and, with `actual` motion (the same
/// poses with their rates), d'Alembert's inertia (`−m a_c`, `−I α`) and
/// the dampers.
#[inline(always)]
pub fn applied(t: &Table, poses: &[Pose], actual: Option<&[Pose<Jet2>]>, out: &mut [[f64; 3]]) {
    for w in out.iter_mut() {
        *w = [0.0; 3];
    }
    let mut add = |b: usize, w: [f64; 3]| {
        for k in 0..3 {
            out[b][k] += w[k];
        }
    };
    for load in t.loads {
        match *load {
            Load::Force {
                body,
                at,
                force,
                body_axes,
            } => {
                let f = if body_axes {
                    turned(&poses[body], force)
                } else {
                    force
                };
                add(body, wrench(f, poses[body].world(at), 0.0));
            }
            Load::Torque { body, torque } => add(body, [0.0, 0.0, torque]),
            Load::Spring {
                a,
                b,
                stiffness,
                free_length,
            } => {
                let (p, q) = (poses[a.0].world(a.1), poses[b.0].world(b.1));
                let (len, u) = towards(p, q);
                let t = stiffness * (len - free_length);
                // A tension pulls each end toward the other.
                add(a.0, wrench([t * u[0], t * u[1]], p, 0.0));
                add(b.0, wrench([-t * u[0], -t * u[1]], q, 0.0));
            }
            Load::Damper { a, b, damping } => {
                let Some(moving) = actual else { continue };
                let t = damping * stretch_rate(moving[a.0].world(a.1), moving[b.0].world(b.1));
                let (p, q) = (poses[a.0].world(a.1), poses[b.0].world(b.1));
                let (_, u) = towards(p, q);
                add(a.0, wrench([t * u[0], t * u[1]], p, 0.0));
                add(b.0, wrench([-t * u[0], -t * u[1]], q, 0.0));
            }
            Load::TorsionSpring {
                first,
                second,
                stiffness,
                free_angle,
            } => {
                let (ra, rb) = (&poses[first].rot, &poses[second].rot);
                let turn = (rb.s * ra.c - rb.c * ra.s).atan2(rb.c * ra.c + rb.s * ra.s);
                let torque = stiffness * (turn - free_angle);
                add(second, [0.0, 0.0, -torque]);
                add(first, [0.0, 0.0, torque]);
            }
        }
    }
    for m in t.masses {
        let mut f = [m.mass * t.gravity[0], m.mass * t.gravity[1]];
        let mut torque = 0.0;
        if let Some(moving) = actual {
            let p = &moving[m.body];
            let c = p.world(m.centre);
            f[0] -= m.mass * c[0].dd;
            f[1] -= m.mass * c[1].dd;
            // α = c·s̈ − s·c̈ for a unit (c, s).
            torque -= m.inertia * (p.rot.c.v * p.rot.s.dd - p.rot.s.v * p.rot.c.dd);
        }
        add(m.body, wrench(f, poses[m.body].world(m.centre), torque));
    }
}

/// The equations' right-hand side from the applied wrenches (`rhs[r]` =
/// minus the load on row `r`, each body's moment about its
/// [`Table::about`] point at `poses`), and what the loads put straight on
/// the ground (fixed bodies): `[fx, fy, m]`, the moment about the world
/// origin.
#[inline(always)]
pub fn right_hand_side(t: &Table, poses: &[Pose], applied: &[[f64; 3]], rhs: &mut [f64]) -> [f64; 3] {
    let mut ground = [0.0; 3];
    for (b, w) in applied.iter().enumerate() {
        match t.rows[b] {
            Some(r) => {
                let w = moved(*w, about(t, poses, b));
                for k in 0..3 {
                    rhs[r + k] = -w[k];
                }
            }
            None => {
                for k in 0..3 {
                    ground[k] += w[k];
                }
            }
        }
    }
    ground
}

/// Solves the unknowns block by block into `x` (every unknown written),
/// `rhs` (from [`right_hand_side`]) consumed as it goes; `scratch` at
/// least [`scratch_len`] of the largest block. `false` where a block is
/// singular at this frame (a dead point, a toggle): `x` then holds no
/// answer.
#[inline(always)]
pub fn solve_blocks(t: &Table, poses: &[Pose], rhs: &mut [f64], x: &mut [f64], scratch: &mut [f64]) -> bool {
    // Each unknown's column, kept from the assembly for the update of the
    // right-hand side after the solve (blocks of up to 16 unknowns; a
    // larger one's columns are computed again).
    let mut kept = [[0.0f64; 3]; 16];
    for block in t.blocks {
        let k = block.rows.len();
        let (a, b) = scratch[..k * k + k].split_at_mut(k * k);
        a.fill(0.0);
        for (j, &c) in block.cols.iter().enumerate() {
            let u = &t.unknowns[c];
            let w = column(u, poses);
            if let Some(slot) = kept.get_mut(j) {
                *slot = w;
            }
            let [first, second] = u.bodies();
            for (body, sign) in [(second, 1.0), (first, -1.0)] {
                let Some(r) = t.rows[body] else { continue };
                let w = moved(w, about(t, poses, body));
                for (i, &row) in block.rows.iter().enumerate() {
                    if (r..r + 3).contains(&row) {
                        a[i * k + j] += sign * w[row - r];
                    }
                }
            }
        }
        for (i, &row) in block.rows.iter().enumerate() {
            b[i] = rhs[row];
        }
        if !lu_solve(a, b, k) {
            return false;
        }
        for (j, &c) in block.cols.iter().enumerate() {
            x[c] = b[j];
            let u = &t.unknowns[c];
            let w = kept.get(j).copied().unwrap_or_else(|| column(u, poses));
            let [first, second] = u.bodies();
            for (body, sign) in [(second, 1.0), (first, -1.0)] {
                if let Some(r) = t.rows[body] {
                    let w = moved(w, about(t, poses, body));
                    for k in 0..3 {
                        rhs[r + k] -= sign * w[k] * b[j];
                    }
                }
            }
        }
    }
    true
}

/// What the unknowns `x` put on the ground (every fixed body): `[fx, fy,
/// m]`, the moment about the world origin.
#[inline(always)]
pub fn on_ground(t: &Table, poses: &[Pose], x: &[f64]) -> [f64; 3] {
    let mut out = [0.0; 3];
    for (u, &xu) in t.unknowns.iter().zip(x) {
        let [first, second] = u.bodies();
        // Most unknowns act between moving bodies: nothing to compute.
        if t.rows[first].is_some() && t.rows[second].is_some() {
            continue;
        }
        let w = column(u, poses);
        for (body, sign) in [(second, 1.0), (first, -1.0)] {
            if t.rows[body].is_none() {
                for k in 0..3 {
                    out[k] += sign * w[k] * xu;
                }
            }
        }
    }
    out
}

/// A block of the force plan is singular at this frame (a toggle, two
/// pins in line): the equations do not fix the forces here.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Singular;

/// Where [`solve_frame`] works: one buffer per body, per equation row,
/// per unknown, and the largest block's [`scratch_len`].
pub struct Work<'a> {
    /// Each body's applied wrench.
    pub applied: &'a mut [[f64; 3]],
    /// The equations' right-hand side.
    pub rhs: &'a mut [f64],
    /// The unknowns.
    pub x: &'a mut [f64],
    /// The block solve's matrix and right-hand side.
    pub scratch: &'a mut [f64],
    /// The unknowns of a frame solved again with gear pairs leaned the
    /// other way ([`lean_by_sign`]): as many as the table's, or none for
    /// a table without gear pairs.
    pub unknowns: &'a mut [Unknown],
}

/// A frame's forces: per joint the force its first body exerts on its
/// second (world axes) and its moment (a prismatic joint's; 0 at a
/// revolute joint), per input its force or torque (positive in the
/// input's positive direction), per pin in a slot and per gear pair
/// their forces, and what the mechanism puts on the ground (`[fx, fy,
/// m]`, the moment about the world origin).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Forces<const NJ: usize, const NI: usize, const NS: usize = 0, const NG: usize = 0> {
    /// Per joint, its reaction.
    pub reactions: [[f64; 2]; NJ],
    /// Per joint, its moment.
    pub moments: [f64; NJ],
    /// Per input, its force or torque.
    pub inputs: [f64; NI],
    /// Per pin in a slot, the force the slotted body exerts on the pin:
    /// square to a straight slot, along an arc's radius.
    pub slots: [[f64; 2]; NS],
    /// Per gear pair (or rack and pinion), the tooth force the first gear
    /// exerts on the second: along the line of action.
    pub teeth: [[f64; 2]; NG],
    /// The force and moment on the ground.
    pub shaking: [f64; 3],
}

impl<const NJ: usize, const NI: usize, const NS: usize, const NG: usize> Default for Forces<NJ, NI, NS, NG> {
    fn default() -> Self {
        Forces {
            reactions: [[0.0; 2]; NJ],
            moments: [0.0; NJ],
            inputs: [0.0; NI],
            slots: [[0.0; 2]; NS],
            teeth: [[0.0; 2]; NG],
            shaking: [0.0; 3],
        }
    }
}

/// Joint `j`'s reaction and moment from the unknowns `x` at `poses`:
/// a revolute joint's two components, a prismatic joint's force across
/// its rail (along the rail's normal) and its moment.
#[inline(always)]
pub fn joint_reaction(t: &Table, poses: &[Pose], x: &[f64], j: usize) -> ([f64; 2], f64) {
    match t.unknowns[2 * j] {
        Unknown::Across { first, dir, .. } => {
            let d = turned(&poses[first], dir);
            ([-d[1] * x[2 * j], d[0] * x[2 * j]], x[2 * j + 1])
        }
        _ => ([x[2 * j], x[2 * j + 1]], 0.0),
    }
}

/// A frame's forces at `poses`, moving as `actual` says (the same poses
/// with their rates; `None` holds it still): the loads, gravity and
/// d'Alembert's inertia, then the blocks in order (again with a gear pair
/// leaned the other way where its force came out negative), into `out`
/// (its joints, inputs, slots and gear pairs as many as the table's). No
/// allocation: `work` is the caller's.
#[inline(always)]
pub fn solve_frame<const NJ: usize, const NI: usize, const NS: usize, const NG: usize>(
    t: &Table,
    poses: &[Pose],
    actual: Option<&[Pose<Jet2>]>,
    work: Work,
    out: &mut Forces<NJ, NI, NS, NG>,
) -> Result<(), Singular> {
    applied(t, poses, actual, work.applied);
    let ground = right_hand_side(t, poses, work.applied, work.rhs);
    if !solve_blocks(t, poses, work.rhs, work.x, work.scratch) {
        return Err(Singular);
    }
    let leaned;
    let t = if lean_by_sign(t, work.x, work.unknowns) {
        leaned = Table {
            unknowns: &*work.unknowns,
            ..*t
        };
        right_hand_side(&leaned, poses, work.applied, work.rhs);
        if !solve_blocks(&leaned, poses, work.rhs, work.x, work.scratch) {
            return Err(Singular);
        }
        &leaned
    } else {
        t
    };
    for j in 0..NJ {
        (out.reactions[j], out.moments[j]) = joint_reaction(t, poses, work.x, j);
    }
    out.inputs.copy_from_slice(&work.x[2 * NJ..2 * NJ + NI]);
    let force = |u: usize| {
        let w = column(&t.unknowns[u], poses);
        [work.x[u] * w[0], work.x[u] * w[1]]
    };
    for (k, slot) in out.slots.iter_mut().enumerate() {
        *slot = force(2 * NJ + NI + k);
    }
    for (g, tooth) in out.teeth.iter_mut().enumerate() {
        *tooth = force(2 * NJ + NI + NS + g);
    }
    let on = on_ground(t, poses, work.x);
    out.shaking = [0, 1, 2].map(|k| on[k] + ground[k]);
    Ok(())
}
