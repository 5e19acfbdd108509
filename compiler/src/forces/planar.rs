//! A planar frame's input forces by virtual work (see the module above).

use dofplan_runtime::planar::Pose;
use dofplan_runtime::scalar::Jet2;

use dofplan_runtime::planar::forces::{self as frame, Block as RtBlock, Lean, Load, Mass, Table, Unknown};

use super::plan::{ForcePlan, System};
use crate::interp::planar::InterpState;
use crate::interp::{Interpreter, RateError};
use crate::model::planar::loads::LoadKind;
use crate::model::planar::slots::Shape;
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
    /// Per slot: the force the slotted body exerts on the pin, square to
    /// the slot, in world axes.
    pub slots: Vec<[f64; 2]>,
    /// Per gear pair: the tooth force its first gear (a rack's pinion)
    /// exerts on its second, in world axes, along the line of action.
    pub teeth: Vec<[f64; 2]>,
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

/// A mechanism's forces as the runtime solves them each frame
/// (`dofplan_runtime::planar::forces::Table`), made once from the file:
/// each body's equation rows, the force unknowns (two per joint, then one
/// per input), the loads and the masses. The interpreter borrows it as a
/// table; the compiled module's `solve_forces` is emitted from it.
#[derive(Clone, Debug, PartialEq)]
pub struct Described {
    /// Per body: its first equation row (`None`: fixed).
    pub rows: Vec<Option<usize>>,
    /// Equation rows: three per moving body.
    pub n_rows: usize,
    /// The unknowns.
    pub unknowns: Vec<Unknown>,
    /// The loads.
    pub loads: Vec<Load>,
    /// The bodies with mass.
    pub masses: Vec<Mass>,
    /// Gravity's acceleration (0 without `[gravity]`).
    pub gravity: [f64; 2],
    /// Each gear pair's tooth force leaned the negative way.
    pub leaning: Vec<Lean>,
    /// Per body, its local origin: where its moment equation is taken
    /// about when the force plan chose no pin.
    pub origins: Vec<[f64; 2]>,
}

impl Described {
    /// The runtime's table of it, with the force plan's blocks and moment
    /// points (`runtime_blocks`).
    pub fn table<'a>(&'a self, plan: &'a RuntimePlan<'a>) -> Table<'a> {
        Table {
            rows: &self.rows,
            n_rows: self.n_rows,
            unknowns: &self.unknowns,
            loads: &self.loads,
            masses: &self.masses,
            gravity: self.gravity,
            blocks: &plan.blocks,
            leaning: &self.leaning,
            about: match plan.about {
                [] => &self.origins,
                about => about,
            },
        }
    }
}

/// The runtime's share of a force plan: its blocks in order, and each
/// body's moment point (empty: each body's local origin).
pub struct RuntimePlan<'a> {
    /// The blocks (none for least squares).
    pub blocks: Vec<RtBlock<'a>>,
    /// Per body, the local point its moment equation is about.
    pub about: &'a [[f64; 2]],
}

/// The runtime's blocks of a force plan (none for least squares) and
/// where its bodies' moments are taken.
pub fn runtime_blocks(plan: &ForcePlan) -> RuntimePlan<'_> {
    RuntimePlan {
        blocks: (plan.blocks().iter())
            .map(|b| RtBlock {
                rows: &b.rows,
                cols: &b.cols,
            })
            .collect(),
        about: plan.about(),
    }
}

/// The force unknowns of `m`: two per joint, one per input, one per slot,
/// one per gear pair (leaning as `signs` says: 1 the way a positive
/// tangential force leans it, −1 the other).
fn unknowns(m: &Mechanism, signs: &[f64]) -> Vec<Unknown> {
    let local = |id: MarkerId| m.marker(id).at;
    let dir = |id: MarkerId| m.marker(id).unit_dir().unwrap_or([1.0, 0.0]);
    let mut unknowns =
        Vec::with_capacity(2 * m.joints.len() + m.inputs.len() + m.slots.len() + m.gears.len());
    for joint in &m.joints {
        let [a, b] = joint.markers;
        let (first, second, at) = (a.body, b.body, local(b));
        match joint.kind {
            crate::model::JointKind::Revolute => {
                for axis in 0..2 {
                    unknowns.push(Unknown::Pin {
                        first,
                        second,
                        at,
                        axis,
                    });
                }
            }
            crate::model::JointKind::Prismatic => {
                unknowns.push(Unknown::Across {
                    first,
                    second,
                    at,
                    dir: dir(a),
                });
                unknowns.push(Unknown::Moment { first, second });
            }
        }
    }
    for input in &m.inputs {
        let [a, b] = m.joints[input.joint].markers;
        let (first, second) = (a.body, b.body);
        unknowns.push(match input.kind {
            InputKind::Angle => Unknown::Moment { first, second },
            InputKind::Slide => Unknown::Along {
                first,
                second,
                at: local(b),
                dir: dir(a),
            },
        });
    }
    // A pin in a slot carries a force across the slot (frictionless):
    // square to a straight slot, along an arc's radius.
    for slot in &m.slots {
        let [a, b] = slot.markers;
        unknowns.push(match slot.shape {
            Shape::Straight => Unknown::Across {
                first: a.body,
                second: b.body,
                at: local(b),
                dir: m.marker(a).unit_dir().unwrap_or([1.0, 0.0]),
            },
            Shape::Arc { .. } => Unknown::Radial {
                first: a.body,
                second: b.body,
                centre: local(a),
                at: local(b),
            },
        });
    }
    for (g, gear) in m.gears.iter().enumerate() {
        let mesh = gear.mesh();
        let lean = signs[g] * mesh.lean;
        // The carrier's own frame: a fixed body stands for the frame.
        let carrier = gear.carrier.unwrap_or_else(|| {
            let joint = &m.joints[gear.pivots[0]];
            joint
                .markers
                .iter()
                .find(|id| id.body != gear.bodies[0])
                .expect("a joint of two bodies")
                .body
        });
        unknowns.push(Unknown::Mesh {
            first: gear.bodies[0],
            second: gear.bodies[1],
            carrier,
            at: mesh.at,
            dir: [
                mesh.tangent[0] + lean * mesh.radial[0],
                mesh.tangent[1] + lean * mesh.radial[1],
            ],
        });
    }
    unknowns
}

/// [`Described`] of `m`: each gear pair's tooth force leaning the way a
/// positive tangential force leans it, and the other way in
/// [`Described::leaning`]: the teeth always push apart, so the line of
/// action a pair's force takes depends on which way it drives.
pub fn describe(m: &Mechanism) -> Described {
    let mut next = 0;
    let rows: Vec<Option<usize>> = (m.bodies.iter())
        .map(|b| {
            (!b.fixed).then(|| {
                next += 3;
                next - 3
            })
        })
        .collect();
    let local = |id: MarkerId| m.marker(id).at;
    let unknowns = unknowns(m, &vec![1.0; m.gears.len()]);
    let negative = self::unknowns(m, &vec![-1.0; m.gears.len()]);
    let first = 2 * m.joints.len() + m.inputs.len() + m.slots.len();
    let leaning = (first..first + m.gears.len())
        .map(|unknown| Lean {
            unknown,
            other: negative[unknown],
        })
        .collect();
    let end = |id: MarkerId| (id.body, local(id));
    let loads = (m.loads.applied.iter())
        .map(|load| match &load.kind {
            LoadKind::Force {
                marker,
                force,
                body_axes,
            } => Load::Force {
                body: marker.body,
                at: local(*marker),
                force: *force,
                body_axes: *body_axes,
            },
            LoadKind::Torque { body, torque } => Load::Torque {
                body: *body,
                torque: *torque,
            },
            LoadKind::Spring {
                markers,
                stiffness,
                free_length,
            } => Load::Spring {
                a: end(markers[0]),
                b: end(markers[1]),
                stiffness: *stiffness,
                free_length: *free_length,
            },
            LoadKind::Damper { markers, damping } => Load::Damper {
                a: end(markers[0]),
                b: end(markers[1]),
                damping: *damping,
            },
            LoadKind::TorsionSpring {
                joint,
                stiffness,
                free_angle,
            } => {
                let [a, b] = m.joints[*joint].markers;
                Load::TorsionSpring {
                    first: a.body,
                    second: b.body,
                    stiffness: *stiffness,
                    free_angle: *free_angle,
                }
            }
        })
        .collect();
    let masses = (0..m.bodies.len())
        .filter_map(|b| {
            m.loads.mass(b).map(|mass| Mass {
                body: b,
                centre: mass.centre,
                mass: mass.mass,
                inertia: mass.inertia,
            })
        })
        .collect();
    Described {
        rows,
        n_rows: next,
        unknowns,
        loads,
        masses,
        gravity: m.loads.gravity.unwrap_or([0.0; 2]),
        leaning,
        origins: vec![[0.0; 2]; m.bodies.len()],
    }
}

/// The plan for the reaction unknowns of `m` (see `forces/plan.rs`), from
/// its equations at the drawn pose; `None` for a mechanism with primitive
/// constraints, whose forces are not modelled yet.
///
/// Each moving body's moment equation is taken about one of its pins (or
/// its local origin), chosen for the smallest blocks: a pin's reaction
/// leaves the moment equation of each body it joins when that is taken
/// about the pin, so a four-bar's coupler about its crank pin and its
/// rocker about the ground pin give the coupler–rocker pin's force from
/// two equations, then each other pin's from two more, one unknown at a
/// time, where moments about one point tie all six together. Every
/// choice is tried where there are at most 4096 (four moving bodies of
/// four pins each and more), else each body's in turn until none helps.
pub fn force_plan(m: &Mechanism) -> Option<ForcePlan> {
    if !m.constraints.is_empty() {
        return None;
    }
    let d = describe(m);
    let no_pins = vec![None; m.bodies.len()];
    let best = about_pins(m, &d);
    let plan = ForcePlan::new(&structure(m, &d, &best)).with_about(about_points(m, &best));
    if matches!(plan, ForcePlan::LeastSquares(_)) && best != no_pins {
        // Regular by structure, singular in numbers as drawn: moments
        // about each body's origin, as every body's moment was taken
        // before the choice.
        return Some(ForcePlan::new(&structure(m, &d, &no_pins)).with_about(about_points(m, &no_pins)));
    }
    Some(plan)
}

/// Per body, the revolute joint whose pin its moment equation is taken
/// about (`None`: its local origin), for the smallest blocks (the sum of
/// their squared sizes, then the largest).
fn about_pins(m: &Mechanism, d: &Described) -> Vec<Option<usize>> {
    let mut choices: Vec<Vec<Option<usize>>> = vec![vec![None]; m.bodies.len()];
    for (j, joint) in m.joints.iter().enumerate() {
        if joint.kind == crate::model::JointKind::Revolute {
            for id in joint.markers {
                if !m.bodies[id.body].fixed && !choices[id.body].contains(&Some(j)) {
                    choices[id.body].push(Some(j));
                }
            }
        }
    }
    let score = |about: &[Option<usize>]| {
        ForcePlan::structural_sizes(&structure(m, d, about)).map(|sizes| {
            let squares: usize = sizes.iter().map(|k| k * k).sum();
            (squares, sizes.iter().copied().max().unwrap_or(0))
        })
    };
    let mut best: Vec<Option<usize>> = vec![None; m.bodies.len()];
    let Some(mut best_score) = score(&best) else {
        return best;
    };
    let combinations = choices.iter().try_fold(1usize, |n, c| n.checked_mul(c.len()));
    if combinations.is_some_and(|n| n <= 4096) {
        let mut pick = vec![0usize; choices.len()];
        loop {
            let about: Vec<Option<usize>> = pick.iter().zip(&choices).map(|(&i, c)| c[i]).collect();
            if let Some(s) = score(&about).filter(|s| *s < best_score) {
                (best, best_score) = (about, s);
            }
            // The next combination, the first body's choice fastest.
            let Some(b) = (0..pick.len()).find(|&b| pick[b] + 1 < choices[b].len()) else {
                return best;
            };
            pick[b] += 1;
            pick[..b].iter_mut().for_each(|p| *p = 0);
        }
    }
    loop {
        let mut better = false;
        for b in 0..choices.len() {
            for &c in &choices[b] {
                let mut about = best.clone();
                about[b] = c;
                if let Some(s) = score(&about).filter(|s| *s < best_score) {
                    (best, best_score, better) = (about, s, true);
                }
            }
        }
        if !better {
            return best;
        }
    }
}

/// Per body, the local point `about` names: its own marker of that
/// joint, or its origin.
fn about_points(m: &Mechanism, about: &[Option<usize>]) -> Vec<[f64; 2]> {
    (about.iter().enumerate())
        .map(|(b, j)| match j {
            Some(j) => {
                let id = m.joints[*j]
                    .markers
                    .into_iter()
                    .find(|id| id.body == b)
                    .expect("a pin of the body");
                m.marker(id).at
            }
            None => [0.0; 2],
        })
        .collect()
}

/// The equilibrium equations at the drawn pose with each body's moment
/// about its pin of `about` (or its origin), holding only the entries
/// that are not zero by construction: a pin's force along x has none in
/// the equations of force along y, nor in the moment equation of a body
/// whose moment is taken about that very pin; a pure moment has only
/// moment entries. The force plan's blocks are this structure's.
fn structure(m: &Mechanism, d: &Described, about: &[Option<usize>]) -> System {
    let drawn = vec![Pose::IDENTITY; m.bodies.len()];
    let points = about_points(m, about);
    let joints = m.joints.len();
    let mut system = System::new(d.n_rows, d.unknowns.len());
    for (c, u) in d.unknowns.iter().enumerate() {
        let w = frame::column(u, &drawn);
        let [first, second] = u.bodies();
        for (body, sign) in [(second, 1.0), (first, -1.0)] {
            let Some(r) = d.rows[body] else {
                for (k, v) in w.iter().enumerate() {
                    system.ground[c].push((k, sign * v));
                }
                continue;
            };
            let at_pin = c < 2 * joints && about[body] == Some(c / 2);
            let present = match u {
                Unknown::Pin { axis, .. } => [*axis == 0, *axis == 1, !at_pin],
                Unknown::Moment { .. } => [false, false, true],
                _ => [true; 3],
            };
            let w = frame::moved(w, points[body]);
            for k in (0..3).filter(|&k| present[k]) {
                system.columns[c].push((r + k, sign * w[k]));
            }
        }
    }
    system
}

/// The joint reactions at `poses` from every moving body's force and
/// moment equilibrium under the file's loads (with `actual` motion, the
/// bodies' d'Alembert inertia and the dampers too): three equations per
/// moving body, two unknowns per joint and one per input, solved as
/// `plan` says (block by block by the runtime, as a compiled
/// `solve_forces` does; by least squares where the plan has no blocks or
/// one is singular at this frame, least norm where the mechanism is
/// over-constrained). `None` for a mechanism with primitive constraints,
/// whose forces are not modelled yet.
pub fn reactions(
    m: &Mechanism,
    plan: &ForcePlan,
    poses: &[Pose],
    actual: Option<&[Pose<Jet2>]>,
) -> Option<Reactions> {
    if !m.constraints.is_empty() {
        return None;
    }
    // A gear pair's line of action depends on the sign of its force: solve
    // leaning every pair the positive way, then again with the pairs that
    // came out negative leaned the other (`frame::lean_by_sign`, as the
    // compiled `solve_forces` does; a pair's sign seldom depends on
    // another's lean, which moves only the pivots' radial loads).
    let described = describe(m);
    let blocks = runtime_blocks(plan);
    let table = described.table(&blocks);
    let found = reactions_of(&table, m, poses, actual);
    let mut leaned = described.unknowns.clone();
    if !frame::lean_by_sign(&table, &found.x, &mut leaned) {
        return Some(found.reactions);
    }
    let table = Table {
        unknowns: &leaned,
        ..table
    };
    Some(reactions_of(&table, m, poses, actual).reactions)
}

/// [`reactions`] by the table `t` of `m` (its gear pairs leaning as its
/// unknowns say), and the unknowns it solved.
struct Leaning {
    reactions: Reactions,
    x: Vec<f64>,
}

fn reactions_of(table: &Table, m: &Mechanism, poses: &[Pose], actual: Option<&[Pose<Jet2>]>) -> Leaning {
    let blocks = table.blocks;
    let mut applied = vec![[0.0; 3]; m.bodies.len()];
    frame::applied(table, poses, actual, &mut applied);
    let mut rhs = vec![0.0; table.n_rows];
    let ground = frame::right_hand_side(table, poses, &applied, &mut rhs);
    // The loads on the rows, each body's moment about the world origin as
    // `equilibrium` takes it: `system x = -w`.
    let mut w = vec![0.0; table.n_rows];
    for (b, load) in applied.iter().enumerate() {
        if let Some(r) = table.rows[b] {
            w[r..r + 3].copy_from_slice(load);
        }
    }
    let system = equilibrium(table, poses);
    let by_blocks = (!blocks.is_empty())
        .then(|| {
            let mut x = vec![0.0; table.unknowns.len()];
            let largest = blocks.iter().map(|b| b.rows.len()).max().unwrap_or(0);
            let mut scratch = vec![0.0; frame::scratch_len(largest)];
            frame::solve_blocks(table, poses, &mut rhs, &mut x, &mut scratch).then_some(x)
        })
        .flatten();
    let super::Solved { x, residual, fixed } = ForcePlan::solved(&system, &w, by_blocks);
    let x = x.as_slice();
    let joints = m.joints.len();
    let (forces, moments) = (0..joints)
        .map(|j| frame::joint_reaction(table, poses, x, j))
        .unzip();
    let on = frame::on_ground(table, poses, x);
    let inputs = m.inputs.len();
    let slots = (0..m.slots.len())
        .map(|k| {
            let u = 2 * joints + inputs + k;
            let w = frame::column(&table.unknowns[u], poses);
            [x[u] * w[0], x[u] * w[1]]
        })
        .collect();
    let teeth = (0..m.gears.len())
        .map(|g| {
            let u = 2 * joints + inputs + m.slots.len() + g;
            let w = frame::column(&table.unknowns[u], poses);
            [x[u] * w[0], x[u] * w[1]]
        })
        .collect();
    Leaning {
        reactions: Reactions {
            forces,
            moments,
            inputs: x[2 * joints..2 * joints + inputs].to_vec(),
            slots,
            teeth,
            indeterminate: (0..joints)
                .filter(|&j| !(fixed[2 * j] && fixed[2 * j + 1]))
                .collect(),
            residual,
            shaking: [0, 1, 2].map(|k| on[k] + ground[k]),
        },
        x: x.to_vec(),
    }
}

/// The equilibrium equations at `poses` (the loads aside: the right-hand
/// side) in sparse columns, each unknown's the runtime's
/// [`frame::column()`].
fn equilibrium(d: &Table, poses: &[Pose]) -> System {
    let mut system = System::new(d.n_rows, d.unknowns.len());
    for (c, u) in d.unknowns.iter().enumerate() {
        let w = frame::column(u, poses);
        let [first, second] = u.bodies();
        for (body, sign) in [(second, 1.0), (first, -1.0)] {
            let (column, r) = match d.rows[body] {
                Some(r) => (&mut system.columns[c], r),
                None => (&mut system.ground[c], 0),
            };
            for (k, v) in w.iter().enumerate() {
                column.push((r + k, sign * v));
            }
        }
    }
    system
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
