//! Forces on spatial mechanisms against independent computations: the
//! Cardan joint's input torque against its velocity ratio's closed form,
//! the excavator's cylinder forces against a moment balance about each
//! pivot written here, every body's force and moment balance under the
//! reactions, and the running mechanisms' input power against the rate of
//! their energy by central differences.

use dofplan::forces::spatial::{advantage, force_plan, input_forces, reactions, Moving, Reactions};
use dofplan::interp::spatial::Interpreter;
use dofplan::model::spatial::loads::LoadKind;
use dofplan::model::spatial::{JointKind, Mechanism};
use dofplan::model::{Format, InputKind, Model};
use dofplan::simulate::spatial::residual;
use dofplan::simulate::{input_rates, sweep_requests};
use dofplan_runtime::real::Jet2;
use dofplan_runtime::spatial::{add, cross, dot, norm, scale, sub, Pose3, Vec3};
use dofplan_runtime::{Driver, Options};
use dofplan_tests::{mechanisms_dir, plan_spatial};

/// A bundled spatial file with loads (`mechanisms/loads/`).
fn load(name: &str) -> Mechanism {
    match dofplan::load_any(&mechanisms_dir().join(format!("loads/{name}.toml"))) {
        Ok(Model::Spatial(m)) => m,
        Ok(Model::Planar(_)) => panic!("{name} is planar"),
        Err(e) => panic!("{e}"),
    }
}

/// The frames of the file's sweep, solved and held to their joints, with
/// the input forces at each (held still, or moving as `moving` says).
fn sweep_forces(m: &Mechanism, moving: Option<Moving>) -> Vec<(Vec<f64>, Vec<Pose3>, Vec<f64>)> {
    let interp = Interpreter::new(plan_spatial(m));
    let mut d = Driver::new(interp.clone(), Options::default());
    let sweep = m.sweep.as_ref().unwrap();
    sweep_requests(sweep, m.inputs.len())
        .map(|requested| {
            assert!(d.frame(&requested).is_solved(), "{}: {requested:?}", m.name);
            let res = residual(m, d.poses(), d.inputs());
            assert!(res < 1e-10 * m.size(), "{}: residual {res:e}", m.name);
            let q = input_forces(m, &interp, d.state(), d.inputs(), moving).unwrap();
            (d.inputs().to_vec(), d.poses().to_vec(), q)
        })
        .collect()
}

#[test]
fn a_cardan_joint_s_input_torque_is_the_load_times_its_velocity_ratio() {
    // Held still against 10 N m on the output shaft, the input needs
    // 10 w2/w1 = 10 cos b / (1 - sin^2 b cos^2 theta): the shafts' weight
    // acts on their axes and asks nothing.
    let m = load("cardan_torque");
    let beta = 30f64.to_radians();
    let frames = sweep_forces(&m, None);
    assert_eq!(frames.len(), 361);
    for (inputs, _, q) in &frames {
        let theta = inputs[0].to_radians();
        let expected = 10.0 * beta.cos() / (1.0 - beta.sin().powi(2) * theta.cos().powi(2));
        assert!(
            (q[0] - expected).abs() < 1e-10 * expected,
            "theta {}: {} against {expected}",
            inputs[0],
            q[0]
        );
    }
}

/// World point of body `b`'s drawn point `at`.
fn world(poses: &[Pose3], b: usize, at: Vec3) -> Vec3 {
    poses[b].world(at)
}

/// The moment about `pivot`, along `axis`, of the weights of `bodies` and
/// of the file's forces on them.
fn moment_about(m: &Mechanism, poses: &[Pose3], bodies: &[usize], pivot: Vec3, axis: Vec3) -> f64 {
    let g = m.loads.gravity.unwrap();
    let mut moment = [0.0; 3];
    for &b in bodies {
        if let Some(mass) = m.loads.mass(b) {
            let c = world(poses, b, mass.centre);
            moment = add(moment, cross(sub(c, pivot), scale(g, mass.mass)));
        }
    }
    for load in &m.loads.applied {
        if let LoadKind::Force { marker, force, .. } = &load.kind {
            if bodies.contains(&marker.body) {
                let x = world(poses, marker.body, m.marker(*marker).at);
                moment = add(moment, cross(sub(x, pivot), *force));
            }
        }
    }
    dot(moment, axis)
}

#[test]
fn the_excavator_s_cylinders_hold_the_moment_about_their_pivots() {
    // Each cylinder is a massless two-force member pushing along the line
    // of its pins; about the pivot it turns, its push balances the moment
    // of everything it holds up. The slew drive holds vertical loads
    // about a vertical axis: nothing.
    let m = load("excavator_load");
    let body = |name: &str| m.bodies.iter().position(|b| b.name == name).unwrap();
    let point = |name: &str| m.marker(m.find_marker(name).unwrap()).at;
    let (turret, boom, stick, bucket) = (body("turret"), body("boom"), body("stick"), body("bucket"));
    let (barrels, rods) = (
        [body("boom_barrel"), body("stick_barrel")],
        [body("boom_rod"), body("stick_rod")],
    );
    assert!(barrels.iter().chain(&rods).all(|&b| m.loads.mass(b).is_none()));
    let input = |name: &str| m.inputs.iter().position(|i| i.name == name).unwrap();
    let mut largest = 0.0f64;
    for (_, poses, q) in sweep_forces(&m, None) {
        // The stick cylinder: pins on the boom (barrel) and the stick (rod),
        // the stick turning about its pivot on the boom.
        let p2 = world(&poses, stick, point("stick.stick_pivot"));
        let r2 = world(&poses, stick, point("stick.stick_rod"));
        let q2 = world(&poses, boom, point("boom.stick_barrel"));
        let (u2, y2) = (
            scale(sub(r2, q2), 1.0 / norm(sub(r2, q2))),
            poses[boom].dir([0.0, 1.0, 0.0]),
        );
        let stick_force =
            -moment_about(&m, &poses, &[stick, bucket], p2, y2) / dot(cross(sub(r2, p2), u2), y2);
        // The boom cylinder: pins on the turret and the boom, which carries
        // the stick, the bucket and the stick cylinder.
        let p1 = world(&poses, boom, point("boom.boom_pivot"));
        let r1 = world(&poses, boom, point("boom.boom_rod"));
        let q1 = world(&poses, turret, point("turret.boom_barrel"));
        let (u1, y1) = (
            scale(sub(r1, q1), 1.0 / norm(sub(r1, q1))),
            poses[turret].dir([0.0, 1.0, 0.0]),
        );
        let boom_force =
            -moment_about(&m, &poses, &[boom, stick, bucket], p1, y1) / dot(cross(sub(r1, p1), u1), y1);
        let scale_of = boom_force.abs().max(stick_force.abs());
        largest = largest.max(scale_of);
        assert!(
            (q[input("boom_cyl")] - boom_force).abs() < 1e-9 * scale_of,
            "{q:?} {boom_force}"
        );
        assert!(
            (q[input("stick_cyl")] - stick_force).abs() < 1e-9 * scale_of,
            "{q:?} {stick_force}"
        );
        assert!(
            q[input("slew")].abs() < 1e-9 * scale_of,
            "slew {}",
            q[input("slew")]
        );
    }
    assert!(largest > 1e4, "the cylinders carry tonnes: {largest}");
}

/// Every moving body's net force and moment (about the origin) from the
/// file's loads, its weight and the reactions `r` with the inputs' forces
/// and torques applied along each driven joint's axis, summed here from
/// the joints' own geometry; the largest component, and the largest load.
fn imbalance(m: &Mechanism, poses: &[Pose3], r: &Reactions) -> (f64, f64) {
    let mut net = vec![[0.0; 6]; m.bodies.len()];
    let mut largest = 0.0f64;
    let mut put = |b: usize, f: Vec3, at: Vec3, moment: Vec3| {
        let about = add(cross(at, f), moment);
        for k in 0..3 {
            net[b][k] += f[k];
            net[b][3 + k] += about[k];
        }
    };
    let g = m.loads.gravity.unwrap_or([0.0; 3]);
    for (b, mass) in m.loads.masses.iter().enumerate() {
        if let Some(mass) = mass {
            put(b, scale(g, mass.mass), world(poses, b, mass.centre), [0.0; 3]);
        }
    }
    for load in &m.loads.applied {
        match &load.kind {
            LoadKind::Force { marker, force, .. } => put(
                marker.body,
                *force,
                world(poses, marker.body, m.marker(*marker).at),
                [0.0; 3],
            ),
            LoadKind::Torque { body, torque } => put(*body, [0.0; 3], [0.0; 3], *torque),
            other => panic!("this check covers forces and torques, not {}", other.name()),
        }
    }
    for (j, joint) in m.joints.iter().enumerate() {
        let [a, b] = joint.markers;
        let at = world(poses, b.body, m.marker(b).at);
        largest = largest.max(norm(r.forces[j])).max(norm(r.moments[j]));
        put(b.body, r.forces[j], at, r.moments[j]);
        put(a.body, scale(r.forces[j], -1.0), at, scale(r.moments[j], -1.0));
    }
    for (i, input) in m.inputs.iter().enumerate() {
        let [a, b] = m.joints[input.joint].markers;
        let axis = poses[a.body].dir(m.marker(a).axes.unwrap().z);
        let at = world(poses, b.body, m.marker(b).at);
        let (f, t) = match input.kind {
            InputKind::Angle => ([0.0; 3], scale(axis, r.inputs[i])),
            InputKind::Slide => (scale(axis, r.inputs[i]), [0.0; 3]),
        };
        put(b.body, f, at, t);
        put(a.body, scale(f, -1.0), at, scale(t, -1.0));
    }
    let worst = (0..m.bodies.len())
        .filter(|&b| !m.bodies[b].fixed)
        .flat_map(|b| net[b])
        .fold(0.0f64, |w, v| w.max(v.abs()));
    (worst, largest)
}

#[test]
fn reactions_balance_every_body_and_give_the_virtual_work_input_forces() {
    for name in ["cardan_torque", "excavator_load"] {
        let m = load(name);
        for (_, poses, q) in sweep_forces(&m, None) {
            let r = reactions(&m, &force_plan(&m).unwrap(), &poses, None).unwrap();
            let (worst, largest) = imbalance(&m, &poses, &r);
            assert!(
                worst < 1e-10 * largest * m.size(),
                "{name}: unbalanced by {worst:e} of {largest}"
            );
            assert!(r.residual < 1e-10 * largest * m.size(), "{name}: {}", r.residual);
            for (a, b) in r.inputs.iter().zip(&q) {
                assert!(
                    (a - b).abs() < 1e-9 * largest,
                    "{name}: equilibrium {a} against virtual work {b}"
                );
            }
        }
    }
}

#[test]
fn redundant_joints_reactions_are_not_unique_and_are_said_to_be() {
    // The Cardan cross's centre on both shaft axes repeats 3 equations:
    // how the axial and weight loads split among A, B and U is a choice.
    // The excavator's cylinder loops are planar: their joints' shares
    // across the plane are a choice, the slew bearing's and the bucket's
    // mount are not.
    let m = load("cardan_torque");
    let (_, poses, _) = &sweep_forces(&m, None)[10];
    let names = |m: &Mechanism, r: &Reactions| -> Vec<String> {
        r.indeterminate
            .iter()
            .map(|&j| m.joints[j].name.clone())
            .collect()
    };
    assert_eq!(
        names(&m, &reactions(&m, &force_plan(&m).unwrap(), poses, None).unwrap()),
        ["A", "B", "U"]
    );
    let m = load("excavator_load");
    let (_, poses, _) = &sweep_forces(&m, None)[10];
    let r = reactions(&m, &force_plan(&m).unwrap(), poses, None).unwrap();
    let found = names(&m, &r);
    assert!(
        !found.contains(&"slew_bearing".to_string()) && !found.contains(&"bucket_mount".to_string()),
        "{found:?}"
    );
    assert!(
        found.contains(&"boom_cylinder".to_string()) && found.contains(&"stick_cylinder".to_string()),
        "{found:?}"
    );
    // What is fixed is fixed: the bucket mount carries the bucket's weight
    // and the payload.
    let mount = m.joints.iter().position(|j| j.name == "bucket_mount").unwrap();
    assert_eq!(m.joints[mount].kind, JointKind::Fixed);
    let bucket = m.bodies.iter().position(|b| b.name == "bucket").unwrap();
    let weight = m.loads.mass(bucket).unwrap().mass * 9.81 + 5000.0;
    let f = r.forces[mount];
    assert!(f[0].abs() < 1e-9 * weight && f[1].abs() < 1e-9 * weight, "{f:?}");
    assert!((f[2] - weight).abs() < 1e-9 * weight, "{f:?} against {weight}");
}

type M3 = [[f64; 3]; 3];

/// The angular velocity of a jet pose: the axial vector of `Ṙ Rᵀ`.
fn omega(p: &Pose3<Jet2>) -> Vec3 {
    let m = &p.rot.m;
    let w: M3 = std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| m[i][k].d * m[j][k].v).sum()));
    [w[2][1], w[0][2], w[1][0]]
}

/// The kinetic energy, the potential energy of gravity and the file's
/// forces, and the power of its torques, at a frame.
fn energies(m: &Mechanism, p: &[Pose3<Jet2>]) -> (f64, f64, f64) {
    energies_with(m, p, true)
}

/// [`energies`], leaving springs and dampers to the caller unless
/// `strict` (then they are refused).
fn energies_with(m: &Mechanism, p: &[Pose3<Jet2>], strict: bool) -> (f64, f64, f64) {
    let g = m.loads.gravity.unwrap_or([0.0; 3]);
    let (mut kinetic, mut potential, mut torque_power) = (0.0, 0.0, 0.0);
    for (b, mass) in m.loads.masses.iter().enumerate() {
        let Some(mass) = mass else { continue };
        let c = p[b].world(mass.centre);
        let (v, x) = (c.map(|x| x.d), c.map(|x| x.v));
        // ω in the body's drawn axes, where the tensor is given.
        let w = omega(&p[b]);
        let r = &p[b].rot.m;
        let local: Vec3 = std::array::from_fn(|k| (0..3).map(|i| r[i][k].v * w[i]).sum());
        let iw: Vec3 = std::array::from_fn(|i| dot(mass.inertia[i], local));
        kinetic += 0.5 * mass.mass * dot(v, v) + 0.5 * dot(local, iw);
        potential -= mass.mass * dot(g, x);
    }
    for load in &m.loads.applied {
        match &load.kind {
            LoadKind::Force { marker, force, .. } => {
                potential -= dot(*force, p[marker.body].world(m.marker(*marker).at).map(|x| x.v))
            }
            LoadKind::Torque { body, torque } => torque_power += dot(*torque, omega(&p[*body])),
            other if !strict => {
                let _ = other;
            }
            other if !strict => {
                let _ = other;
            }
            other => panic!("this check covers forces and torques, not {}", other.name()),
        }
    }
    (kinetic, potential, torque_power)
}

/// The mechanical energy at a frame, and the power of the torques.
fn energy(m: &Mechanism, p: &[Pose3<Jet2>]) -> (f64, f64) {
    let (kinetic, potential, torque_power) = energies(m, p);
    (kinetic + potential, torque_power)
}

#[test]
fn running_mechanisms_input_power_is_their_energy_s_rate() {
    // Driven along the sweep with the first input at 3 rad/s (the others
    // in proportion): sum Q_i u_i-dot = dE/dt - the torques' power, dE/dt
    // by a fourth-order central difference along the sweep.
    for name in ["cardan_torque", "excavator_load"] {
        let m = load(name);
        let interp = Interpreter::new(plan_spatial(&m));
        let sweep = m.sweep.clone().unwrap();
        let rates = input_rates(&m.inputs, &sweep, 3.0);
        let zero = vec![0.0; m.inputs.len()];
        let moving = Moving {
            rates: &rates,
            accelerations: &zero,
        };
        // Each input's rate per second in its force's units: radians for
        // an angle.
        let per_second: Vec<f64> = (m.inputs.iter().zip(&rates))
            .map(|(i, r)| match i.kind {
                InputKind::Angle => r.to_radians(),
                InputKind::Slide => *r,
            })
            .collect();
        let mut d = Driver::new(interp.clone(), Options::default());
        let start: Vec<f64> = sweep_requests(&sweep, m.inputs.len()).next().unwrap();
        let mut at = |t: f64| -> (Vec<Pose3<Jet2>>, Vec<f64>) {
            let u: Vec<f64> = start.iter().zip(&rates).map(|(s, r)| s + r * t).collect();
            assert!(d.frame(&u).is_solved());
            let jets = interp.rates(d.state(), d.inputs(), &rates, &zero).unwrap();
            let q = input_forces(&m, &interp, d.state(), d.inputs(), Some(moving)).unwrap();
            (jets, q)
        };
        // The sweep's span in seconds at these rates.
        let primary = sweep.primary();
        let span = ((primary.to - primary.from) / rates[primary.input]).abs();
        let h = 1e-3 * span / 20.0;
        let (mut worst, mut largest) = (0.0f64, 0.0f64);
        for k in 1..20 {
            let t = span * k as f64 / 20.0;
            let mut e = |dt: f64| energy(&m, &at(t + dt).0).0;
            let de_dt = (-e(2.0 * h) + 8.0 * e(h) - 8.0 * e(-h) + e(-2.0 * h)) / (12.0 * h);
            let (jets, q) = at(t);
            let torque_power = energy(&m, &jets).1;
            let input: f64 = q.iter().zip(&per_second).map(|(q, r)| q * r).sum();
            largest = largest.max(input.abs());
            worst = worst.max((input - (de_dt - torque_power)).abs());
        }
        assert!(largest > 1.0, "{name}: the loads do work: {largest}");
        assert!(worst < 1e-8 * largest, "{name}: worst {worst:e} of {largest}");
    }
}

#[test]
fn each_cylinder_s_running_force_is_lagrange_s() {
    // The energy balance sees only the total power, and a gyroscopic
    // torque does none; Lagrange's equations give each input's force:
    // Q_i = d/dt dT/du_i-dot - dT/du_i + dV/du_i, with T(u, u-dot) and
    // V(u) from the jets and every derivative by central differences (T
    // is quadratic in u-dot, so its derivative there is exact). In the
    // inputs' own units (per degree for the slew), then per radian.
    let m = load("excavator_load");
    let interp = Interpreter::new(plan_spatial(&m));
    let sweep = m.sweep.clone().unwrap();
    let rates = input_rates(&m.inputs, &sweep, 3.0);
    let zero = vec![0.0; m.inputs.len()];
    let n = m.inputs.len();
    let mut d = Driver::new(interp.clone(), Options::default());
    let mut state_at = |u: &[f64], udot: &[f64]| -> (f64, f64) {
        assert!(d.frame(u).is_solved());
        let jets = interp.rates(d.state(), d.inputs(), udot, &zero).unwrap();
        let (kinetic, potential, _) = energies(&m, &jets);
        (kinetic, potential)
    };
    let start: Vec<f64> = sweep_requests(&sweep, n).next().unwrap();
    let path = |t: f64| -> Vec<f64> { start.iter().zip(&rates).map(|(s, r)| s + r * t).collect() };
    let stencil = |f: &mut dyn FnMut(f64) -> f64, h: f64| {
        (-f(2.0 * h) + 8.0 * f(h) - 8.0 * f(-h) + f(-2.0 * h)) / (12.0 * h)
    };
    let primary = sweep.primary();
    let span = ((primary.to - primary.from) / rates[primary.input]).abs();
    let mut checked = 0;
    for k in [3, 9, 15] {
        let t = span * k as f64 / 20.0;
        let moving = Moving {
            rates: &rates,
            accelerations: &zero,
        };
        let mut d2 = Driver::new(interp.clone(), Options::default());
        assert!(d2.frame(&path(t)).is_solved());
        let q = input_forces(&m, &interp, d2.state(), d2.inputs(), Some(moving)).unwrap();
        for i in 0..n {
            // dT/du_i-dot at (u, u-dot): T is a quadratic form in u-dot.
            let mut momentum = |t: f64| {
                let (mut plus, mut minus) = (rates.clone(), rates.clone());
                plus[i] += 1.0;
                minus[i] -= 1.0;
                (state_at(&path(t), &plus).0 - state_at(&path(t), &minus).0) / 2.0
            };
            let h_t = 1e-3 * span / 20.0;
            let d_momentum = stencil(&mut |dt| momentum(t + dt), h_t);
            let h_u = if m.inputs[i].kind == InputKind::Angle {
                1e-3
            } else {
                1e-5
            };
            let mut moved = |du: f64, part: usize| {
                let mut u = path(t);
                u[i] += du;
                let e = state_at(&u, &rates);
                if part == 0 {
                    e.0
                } else {
                    e.1
                }
            };
            let dt_du = stencil(&mut |du| moved(du, 0), h_u);
            let dv_du = stencil(&mut |du| moved(du, 1), h_u);
            let mut lagrange = d_momentum - dt_du + dv_du;
            if m.inputs[i].kind == InputKind::Angle {
                lagrange = lagrange.to_degrees();
            }
            let size = q.iter().fold(1.0f64, |a, v| a.max(v.abs()));
            assert!(
                (q[i] - lagrange).abs() < 1e-6 * size,
                "t {t}, input {}: {} against Lagrange's {lagrange}",
                m.inputs[i].name,
                q[i]
            );
            checked += 1;
        }
    }
    assert_eq!(checked, 9);
}

#[test]
fn a_cardan_joint_s_mechanical_advantage_is_its_velocity_ratio_s_inverse() {
    // Per unit input torque the output shaft holds w1/w2 = (1 - sin^2 b
    // cos^2 theta) / cos b, and its tip (half a unit off its axis) exerts
    // that over 0.5 along its circle; the cross (two freedoms) and the
    // driven joint have none, the ground's markers do not move.
    let m = load("cardan_torque");
    let interp = Interpreter::new(plan_spatial(&m));
    let mut d = Driver::new(interp.clone(), Options::default());
    let joint = |n: &str| m.joints.iter().position(|j| j.name == n).unwrap();
    let marker = |n: &str| m.all_markers().position(|id| m.marker_name(id) == n).unwrap();
    let beta = 30f64.to_radians();
    for k in 0..36 {
        let theta = 10.0 * k as f64 + 3.0;
        assert!(d.frame(&[theta]).is_solved());
        let a = advantage(&m, &interp, d.state(), d.inputs()).unwrap().unwrap();
        let t = theta.to_radians();
        let ratio = (1.0 - beta.sin().powi(2) * t.cos().powi(2)) / beta.cos();
        let b = a.joints[joint("B")].unwrap();
        assert!(
            (b - ratio).abs() < 1e-10 * ratio,
            "B at {theta}: {b} against {ratio}"
        );
        let tip = a.markers[marker("shaft2.tip")].unwrap();
        assert!((tip - ratio / 0.5).abs() < 1e-10 * ratio, "tip at {theta}");
        assert_eq!((a.joints[joint("A")], a.joints[joint("U")]), (None, None));
        assert_eq!(a.markers[marker("ground.B")], None);
    }
}

/// A slider-crank drawn in space (crank 1, rod 3.5, track offset 0.25,
/// the crank drawn at 30 degrees): its prismatic joint's advantage.
const SPATIAL_SLIDER_CRANK: &str = r#"name = "spatial_slider_crank"
dimension = 3

[bodies.ground]
fixed = true
markers.O = { at = [0.0, 0.0, 0.0], z = [0.0, 0.0, 1.0] }
markers.T = { at = [0.0, 0.25, 0.0], z = [1.0, 0.0, 0.0] }

[bodies.crank]
markers.O = { at = [0.0, 0.0, 0.0], z = [0.0, 0.0, 1.0] }
markers.B = { at = [0.8660254037844387, 0.49999999999999994, 0.0], z = [0.0, 0.0, 1.0] }

[bodies.rod]
markers.B = { at = [0.8660254037844387, 0.49999999999999994, 0.0], z = [0.0, 0.0, 1.0] }
markers.C = { at = [4.357085414726674, 0.25, 0.0], z = [0.0, 0.0, 1.0] }

[bodies.slider]
markers.C = { at = [4.357085414726674, 0.25, 0.0], z = [0.0, 0.0, 1.0] }
markers.T = { at = [4.357085414726674, 0.25, 0.0], z = [1.0, 0.0, 0.0] }

[joints.O]
kind = "revolute"
markers = ["ground.O", "crank.O"]
[joints.B]
kind = "revolute"
markers = ["crank.B", "rod.B"]
[joints.C]
kind = "revolute"
markers = ["rod.C", "slider.C"]
[joints.S]
kind = "prismatic"
markers = ["ground.T", "slider.T"]

[inputs.theta]
kind = "angle"
joint = "O"
"#;

#[test]
fn a_spatial_slider_s_mechanical_advantage_is_the_slider_crank_s_closed_form() {
    // Per unit crank torque the slider holds 1 / |dx/dphi| along its track,
    // x = r cos(phi) + sqrt(l^2 - (r sin(phi) - e)^2): the prismatic joint's
    // slide against the ground's material point under it, and with the
    // joint's markers swapped (the slider carrying the track, the ground
    // sliding on it) the same number: the slider's material point under
    // the ground's marker moves with the slider.
    let swapped = SPATIAL_SLIDER_CRANK.replace(r#"["ground.T", "slider.T"]"#, r#"["slider.T", "ground.T"]"#);
    assert_ne!(swapped, SPATIAL_SLIDER_CRANK);
    for text in [SPATIAL_SLIDER_CRANK, &swapped] {
        slider_advantage(text);
    }
}

fn slider_advantage(text: &str) {
    let Ok(Model::Spatial(m)) = dofplan::load_any_str("sc.toml", text, Format::Toml) else {
        panic!("loads");
    };
    let interp = Interpreter::new(plan_spatial(&m));
    let mut d = Driver::new(interp.clone(), Options::default());
    let slide = m.joints.iter().position(|j| j.name == "S").unwrap();
    let (r, l, e) = (1.0f64, 3.5f64, 0.25f64);
    for k in 0..24 {
        let theta = 15.0 * k as f64 + 2.0;
        assert!(d.frame(&[theta]).is_solved());
        assert!(residual(&m, d.poses(), d.inputs()) < 1e-10);
        let a = advantage(&m, &interp, d.state(), d.inputs()).unwrap().unwrap();
        let phi = (30.0 + theta).to_radians();
        let root = (l * l - (r * phi.sin() - e).powi(2)).sqrt();
        let dx = -r * phi.sin() - (r * phi.sin() - e) * r * phi.cos() / root;
        let got = a.joints[slide].unwrap();
        assert!(
            (got - 1.0 / dx.abs()).abs() < 1e-9 / dx.abs(),
            "S at {theta}: {got} against {}",
            1.0 / dx.abs()
        );
    }
}

#[test]
fn speeding_up_the_cardan_drive_adds_its_generalised_mass_times_the_acceleration() {
    // Q(w, a) - Q(w, 0) = M(theta) a, M = sum m |dc/dtheta|^2 + w^T I w
    // per unit input rate, w the axial vector of dR/dtheta R^T (body axes
    // for the tensor), every derivative a central difference of solved
    // poses; gravity and the resisting torque depend on the pose alone.
    let m = load("cardan_torque");
    let interp = Interpreter::new(plan_spatial(&m));
    let (mut d, mut near) = (
        Driver::new(interp.clone(), Options::default()),
        Driver::new(interp.clone(), Options::default()),
    );
    let (w, a) = (3.0f64, 40.0f64);
    let rates = [w.to_degrees()];
    let accelerations = [a.to_degrees()];
    let h = 1e-4f64;
    let per_radian = 2.0 * h.to_radians();
    for k in 0..24 {
        let theta = 15.0 * k as f64 + 4.0;
        let mut poses = |t: f64| {
            assert!(near.frame(&[t]).is_solved());
            near.poses().to_vec()
        };
        let (ahead, behind) = (poses(theta + h), poses(theta - h));
        let mut mass_of = 0.0;
        for (b, mass) in m.loads.masses.iter().enumerate() {
            let Some(mass) = mass else { continue };
            let v = scale(
                sub(ahead[b].world(mass.centre), behind[b].world(mass.centre)),
                1.0 / per_radian,
            );
            // dR R^T (world), then into the body's drawn axes: R^T w.
            let (ra, rb) = (&ahead[b].rot.m, &behind[b].rot.m);
            let dr = |i: usize, k: usize| (ra[i][k] - rb[i][k]) / per_radian;
            let r = |i: usize, k: usize| 0.5 * (ra[i][k] + rb[i][k]);
            let s = |i: usize, j: usize| (0..3).map(|k| dr(i, k) * r(j, k)).sum::<f64>();
            let world_w = [s(2, 1), s(0, 2), s(1, 0)];
            let local: Vec3 = std::array::from_fn(|k| (0..3).map(|i| r(i, k) * world_w[i]).sum());
            mass_of +=
                mass.mass * dot(v, v) + dot(local, std::array::from_fn(|i| dot(mass.inertia[i], local)));
        }
        let mut q = |acc: &[f64]| {
            assert!(d.frame(&[theta]).is_solved());
            let moving = Moving {
                rates: &rates,
                accelerations: acc,
            };
            input_forces(&m, &interp, d.state(), d.inputs(), Some(moving)).unwrap()[0]
        };
        let (steady, speeding) = (q(&[0.0]), q(&accelerations));
        let want = mass_of * a;
        assert!(
            (speeding - steady - want).abs() < 1e-6 * want.abs(),
            "theta {theta}: {} against {want}",
            speeding - steady
        );
    }
}

/// The Cardan drive with a spring from the ground to the output shaft's
/// tip, a damper between the two shafts' tips and a torsion spring on the
/// output shaft's bearing.
fn cardan_with_springs() -> Mechanism {
    let text = std::fs::read_to_string(mechanisms_dir().join("loads/cardan_torque.toml")).unwrap()
        + r#"
[loads.spring]
kind = "spring"
markers = ["ground.A", "shaft2.tip"]
stiffness = 40.0
free_length = 3.0

[loads.damper]
kind = "damper"
markers = ["shaft1.tip", "shaft2.tip"]
damping = 6.0

[loads.bearing]
kind = "torsion-spring"
joint = "B"
stiffness = 5.0
free_angle = 20.0
"#;
    match dofplan::load_any_str("cardan_springs.toml", &text, Format::Toml) {
        Ok(Model::Spatial(m)) => m,
        _ => panic!("loads"),
    }
}

/// A revolute joint's turn from the drawing: the relative rotation
/// `R_aᵀ R_b` is a turn about the first marker's z (body a's axes), its
/// sine the axial vector of its skew part along z, its cosine from its
/// trace.
fn revolute_turn(m: &Mechanism, joint: usize, p: &[Pose3]) -> f64 {
    let [ia, ib] = m.joints[joint].markers;
    let (ra, rb) = (&p[ia.body].rot.m, &p[ib.body].rot.m);
    let rel = |i: usize, j: usize| (0..3).map(|k| ra[k][i] * rb[k][j]).sum::<f64>();
    let axial = [
        0.5 * (rel(2, 1) - rel(1, 2)),
        0.5 * (rel(0, 2) - rel(2, 0)),
        0.5 * (rel(1, 0) - rel(0, 1)),
    ];
    let z = m.marker(ia).axes.expect("a revolute joint's marker has axes").z;
    dot(axial, z).atan2(0.5 * (rel(0, 0) + rel(1, 1) + rel(2, 2) - 1.0))
}

#[test]
fn springs_a_damper_and_a_torsion_spring_balance_the_running_energy() {
    // Q w = dE/dt - the torques' power + the damper's loss, E now with the
    // springs' energy: the spring's 1/2 k (L - L0)^2 from the tips' solved
    // positions, the torsion spring's 1/2 k (phi - phi0)^2 with phi from
    // the output shaft's rotation (`revolute_turn`), the damper's loss
    // c (dL/dt)^2. Over the first 160 degrees, where the bearing's turn
    // stays inside (-180, 180] as the torsion spring measures it.
    let m = cardan_with_springs();
    let interp = Interpreter::new(plan_spatial(&m));
    let bearing = m.joints.iter().position(|j| j.name == "B").unwrap();
    let w = 3.0f64;
    let rates = [w.to_degrees()];
    let moving = Moving {
        rates: &rates,
        accelerations: &[0.0],
    };
    let mut d = Driver::new(interp.clone(), Options::default());
    let end = |p: &[Pose3<Jet2>], name: &str| {
        let id = m.find_marker(name).unwrap();
        p[id.body].world(m.marker(id).at)
    };
    let mut at = |t: f64| -> (f64, f64, f64, f64) {
        assert!(d.frame(&[(w * t).to_degrees()]).is_solved());
        let jets = interp.rates(d.state(), d.inputs(), &rates, &[0.0]).unwrap();
        let (kinetic, potential, torque_power) = energies_with(&m, &jets, false);
        let values: Vec<Pose3> = jets.iter().map(Pose3::value).collect();
        let (a, b) = (end(&jets, "ground.A"), end(&jets, "shaft2.tip"));
        let length = norm(sub(b.map(|c| c.v), a.map(|c| c.v)));
        let turn = revolute_turn(&m, bearing, &values);
        let springs = 0.5 * 40.0 * (length - 3.0).powi(2) + 0.5 * 5.0 * (turn - 20f64.to_radians()).powi(2);
        let (a, b) = (end(&jets, "shaft1.tip"), end(&jets, "shaft2.tip"));
        let gap = sub(b.map(|c| c.v), a.map(|c| c.v));
        let gap_rate = dot(gap, sub(b.map(|c| c.d), a.map(|c| c.d))) / norm(gap);
        let q = input_forces(&m, &interp, d.state(), d.inputs(), Some(moving)).unwrap()[0];
        (
            kinetic + potential + springs,
            torque_power,
            6.0 * gap_rate * gap_rate,
            q,
        )
    };
    let h = 1e-4;
    let (mut worst, mut largest) = (0.0f64, 0.0f64);
    for k in 1..16 {
        let t = (10.0 * k as f64).to_radians() / w;
        let mut e = |dt: f64| at(t + dt).0;
        let de_dt = (-e(2.0 * h) + 8.0 * e(h) - 8.0 * e(-h) + e(-2.0 * h)) / (12.0 * h);
        let (_, torque_power, loss, q) = at(t);
        largest = largest.max((q * w).abs());
        worst = worst.max((q * w - (de_dt - torque_power + loss)).abs());
    }
    assert!(largest > 10.0, "the loads do work: {largest}");
    assert!(worst < 1e-8 * largest, "worst {worst:e} of {largest}");
}
