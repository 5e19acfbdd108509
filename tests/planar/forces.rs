//! Input forces by virtual work (`dofplan::forces::planar`) against
//! independent computations: the slider-crank's closed form, a follower
//! force that is a constant torque, a four-bar solved here by circle
//! intersection, and the energy balance of a four-bar with masses,
//! gravity, springs, a torque and a damper running at speed.

use dofplan::forces::planar::{input_forces, Moving};
use dofplan::interp::Interpreter;
use dofplan::load_str;
use dofplan::model::{Format, Mechanism};
use dofplan_runtime::planar::Pose;
use dofplan_runtime::real::Jet2;
use dofplan_runtime::{Driver, FrameStatus, Options};
use dofplan_tests::{load, mechanisms_dir, plan};

/// The input forces at crank angle `theta` (degrees), held still or
/// running as `moving` says.
fn forces_at(m: &Mechanism, driver: &mut Driver<Interpreter>, theta: f64, moving: Option<Moving>) -> f64 {
    assert_eq!(
        driver.frame(&[theta]),
        FrameStatus::Solved,
        "{} at {theta}",
        m.name
    );
    let q = input_forces(m, driver.solver(), driver.state(), driver.inputs(), moving).unwrap();
    q[0]
}

#[test]
fn a_piston_force_needs_the_slider_crank_s_closed_form_torque() {
    // T = -F_x dx_C/dphi, x_C = r cos(phi) + sqrt(l^2 - (r sin(phi) - e)^2),
    // differentiated by hand: dx/dphi = -r sin(phi) - (r sin(phi) - e) r cos(phi) / sqrt(...).
    let m = load("loads/slider_crank_press");
    let mut d = Driver::new(Interpreter::new(plan(&m)), Options::default());
    let (r, l, e, f) = (1.0f64, 3.5f64, 0.25f64, -100.0f64);
    let mut worst = 0.0f64;
    for k in 0..=72 {
        let theta = 5.0 * k as f64;
        let phi = (30.0 + theta).to_radians();
        let root = (l * l - (r * phi.sin() - e).powi(2)).sqrt();
        let dx = -r * phi.sin() - (r * phi.sin() - e) * r * phi.cos() / root;
        let expected = -f * dx;
        let got = forces_at(&m, &mut d, theta, None);
        worst = worst.max((got - expected).abs());
    }
    assert!(worst < 1e-10, "worst {worst:e}");
}

#[test]
fn a_follower_force_square_to_the_crank_is_a_constant_torque() {
    // 10 units on the crank's tip B, in the crank's axes, square to OB
    // (|OB| = 1): a torque of 10 about O at every pose, which the input
    // holds with -10.
    let text = std::fs::read_to_string(mechanisms_dir().join("loads/slider_crank_press.toml")).unwrap();
    let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    let text = text.replace(
        "marker = \"slider.C\"\nforce = [-100.0, 0.0]",
        &format!(
            "marker = \"crank.B\"\nforce = [{}, {}]\naxes = \"body\"",
            -10.0 * s,
            10.0 * c
        ),
    );
    let m = load_str("follower.toml", &text, Format::Toml).unwrap();
    let mut d = Driver::new(Interpreter::new(plan(&m)), Options::default());
    for k in 0..=24 {
        let q = forces_at(&m, &mut d, 15.0 * k as f64, None);
        assert!((q + 10.0).abs() < 1e-12, "{q} at {}", 15 * k);
    }
}

/// The four-bar of `mechanisms/fourbar.toml` solved here: the coupler
/// point at crank angle `theta` (degrees from the drawing), by the circle
/// intersection on the drawn branch.
fn fourbar_p(theta: f64) -> [f64; 2] {
    let (a, b0, c0, d) = ([0.0, 0.0], [1.0f64, 1.0f64], [4.5, 2.5], [4.0, 0.0]);
    let p0 = [3.0, 3.5];
    let crank = b0[0].hypot(b0[1]);
    let (bc, cd) = (
        (c0[0] - b0[0]).hypot(c0[1] - b0[1]),
        (c0[0] - d[0]).hypot(c0[1] - d[1]),
    );
    let t = b0[1].atan2(b0[0]) + theta.to_radians();
    let b = [a[0] + crank * t.cos(), a[1] + crank * t.sin()];
    let (ex, ey) = (d[0] - b[0], d[1] - b[1]);
    let len = ex.hypot(ey);
    let x = (bc * bc - cd * cd + len * len) / (2.0 * len);
    let h = (bc * bc - x * x).sqrt();
    // The drawn branch: C to the left of B -> D (as drawn, C is above BD).
    let c = [
        b[0] + x * ex / len - h * ey / len,
        b[1] + x * ey / len + h * ex / len,
    ];
    // P rides with the coupler: the same coordinates along and across BC.
    let (u0, v0) = (
        [(c0[0] - b0[0]) / bc, (c0[1] - b0[1]) / bc],
        [(p0[0] - b0[0]), (p0[1] - b0[1])],
    );
    let (along, across) = (v0[0] * u0[0] + v0[1] * u0[1], -v0[0] * u0[1] + v0[1] * u0[0]);
    let u = [(c[0] - b[0]) / bc, (c[1] - b[1]) / bc];
    [
        b[0] + along * u[0] - across * u[1],
        b[1] + along * u[1] + across * u[0],
    ]
}

#[test]
fn a_load_on_the_coupler_point_needs_the_hand_virtual_work_torque() {
    // Only the payload: T = -F . dP/dtheta (per radian), dP/dtheta by a
    // central difference of the four-bar solved above.
    let text = std::fs::read_to_string(mechanisms_dir().join("fourbar.toml")).unwrap()
        + "\n[loads.payload]\nkind = \"force\"\nmarker = \"coupler.P\"\nforce = [3.0, -20.0]\n";
    let m = load_str("payload.toml", &text, Format::Toml).unwrap();
    let mut d = Driver::new(Interpreter::new(plan(&m)), Options::default());
    assert!((fourbar_p(0.0)[0] - 3.0).abs() < 1e-12 && (fourbar_p(0.0)[1] - 3.5).abs() < 1e-12);
    let h = 1e-5;
    for k in 0..36 {
        let theta = 10.0 * k as f64;
        let (p1, p0) = (fourbar_p(theta + h), fourbar_p(theta - h));
        let dp = [
            (p1[0] - p0[0]) / (2.0 * h.to_radians()),
            (p1[1] - p0[1]) / (2.0 * h.to_radians()),
        ];
        let expected = -(3.0 * dp[0] - 20.0 * dp[1]);
        let got = forces_at(&m, &mut d, theta, None);
        assert!(
            (got - expected).abs() < 1e-7 * expected.abs().max(1.0),
            "{got} against {expected} at {theta}"
        );
    }
}

/// The mechanical energy of `fourbar_weights` at a frame: kinetic (from
/// the jets' velocities), gravity's, the payload's and the brake's
/// potential, the springs'; and the damper's loss rate (c L-dot^2).
pub(crate) fn energy(m: &Mechanism, p: &[Pose<Jet2>]) -> (f64, f64) {
    use dofplan::model::planar::loads::LoadKind;
    let world = |b: usize, at: [f64; 2]| p[b].world(at);
    let turn = |b: usize| p[b].rot.s.v.atan2(p[b].rot.c.v);
    let omega = |b: usize| p[b].rot.c.v * p[b].rot.s.d - p[b].rot.s.v * p[b].rot.c.d;
    let g = m.loads.gravity.unwrap();
    let (mut e, mut loss) = (0.0, 0.0);
    for (b, mass) in m.loads.masses.iter().enumerate() {
        let Some(mass) = mass else { continue };
        let c = world(b, mass.centre);
        e += 0.5 * mass.mass * (c[0].d * c[0].d + c[1].d * c[1].d) + 0.5 * mass.inertia * omega(b).powi(2);
        e -= mass.mass * (g[0] * c[0].v + g[1] * c[1].v);
    }
    let at = |id: dofplan::model::MarkerId| world(id.body, m.marker(id).at);
    for load in &m.loads.applied {
        match &load.kind {
            LoadKind::Force { marker, force, .. } => {
                let x = at(*marker);
                e -= force[0] * x[0].v + force[1] * x[1].v;
            }
            LoadKind::Torque { body, torque } => e -= torque * turn(*body),
            LoadKind::Spring {
                markers,
                stiffness,
                free_length,
            } => {
                let (a, b) = (at(markers[0]), at(markers[1]));
                let len = (b[0].v - a[0].v).hypot(b[1].v - a[1].v);
                e += 0.5 * stiffness * (len - free_length).powi(2);
            }
            LoadKind::Damper { markers, damping } => {
                let (a, b) = (at(markers[0]), at(markers[1]));
                let d = [b[0].v - a[0].v, b[1].v - a[1].v];
                let len = d[0].hypot(d[1]);
                let rate = (d[0] * (b[0].d - a[0].d) + d[1] * (b[1].d - a[1].d)) / len;
                loss += damping * rate * rate;
            }
            LoadKind::TorsionSpring {
                joint,
                stiffness,
                free_angle,
            } => {
                let [a, b] = m.joints[*joint].markers.map(|id| id.body);
                e += 0.5 * stiffness * (turn(b) - turn(a) - free_angle).powi(2);
            }
        }
    }
    (e, loss)
}

#[test]
fn a_running_four_bar_s_input_power_is_its_energy_s_rate_plus_the_damper_s_loss() {
    // At a constant 2 rad/s: Q * omega = dE/dt + c L-dot^2, dE/dt by a
    // fourth-order central difference of E along the crank angle.
    let m = load("loads/fourbar_weights");
    assert_eq!(m.loads.applied.len(), 5);
    let interp = Interpreter::new(plan(&m));
    let mut d = Driver::new(interp.clone(), Options::default());
    let w = 2.0f64;
    let rates = [w.to_degrees()];
    let moving = Moving {
        rates: &rates,
        accelerations: &[0.0],
    };
    let mut e_at = |theta: f64| {
        assert!(d.frame(&[theta]).is_solved());
        let jets = interp.rates(d.state(), d.inputs(), &rates, &[0.0]).unwrap();
        energy(&m, &jets)
    };
    let mut d2 = Driver::new(interp.clone(), Options::default());
    let h = 0.01f64;
    let mut largest = 0.0f64;
    let mut worst = 0.0f64;
    for k in 0..36 {
        let theta = 10.0 * k as f64 + 3.0;
        let mut e = |dt: f64| e_at(theta + dt).0;
        let de_dtheta = (-e(2.0 * h) + 8.0 * e(h) - 8.0 * e(-h) + e(-2.0 * h)) / (12.0 * h.to_radians());
        let loss = e_at(theta).1;
        let q = forces_at(&m, &mut d2, theta, Some(moving));
        let (input, balance) = (q * w, de_dtheta * w + loss);
        largest = largest.max(input.abs());
        worst = worst.max((input - balance).abs());
    }
    assert!(largest > 10.0, "the loads do work: {largest}");
    assert!(worst < 1e-8 * largest, "worst {worst:e} of {largest}");
}

#[test]
fn statics_leave_out_inertia_and_dampers() {
    // Held still, the same four-bar's input torque is the potential's
    // slope alone: -dV/dtheta with V the energy at rest.
    let m = load("loads/fourbar_weights");
    let interp = Interpreter::new(plan(&m));
    let mut d = Driver::new(interp.clone(), Options::default());
    let mut v_at = |theta: f64| {
        assert!(d.frame(&[theta]).is_solved());
        // Rates 0: no kinetic energy, no damper loss.
        let jets = interp.rates(d.state(), d.inputs(), &[0.0], &[0.0]).unwrap();
        energy(&m, &jets).0
    };
    let mut d2 = Driver::new(interp.clone(), Options::default());
    let h = 0.01f64;
    for k in 0..12 {
        let theta = 30.0 * k as f64 + 7.0;
        let mut v = |dt: f64| v_at(theta + dt);
        let dv = (-v(2.0 * h) + 8.0 * v(h) - 8.0 * v(-h) + v(-2.0 * h)) / (12.0 * h.to_radians());
        let q = forces_at(&m, &mut d2, theta, None);
        assert!(
            (q - dv).abs() < 1e-8 * dv.abs().max(1.0),
            "{q} against {dv} at {theta}"
        );
    }
}

/// The reactions and the input forces at crank angle `theta`, and the
/// virtual-work input forces there.
fn reactions_at(
    m: &Mechanism,
    driver: &mut Driver<Interpreter>,
    theta: f64,
    moving: Option<Moving>,
) -> (dofplan::forces::planar::Reactions, Vec<f64>) {
    use dofplan::forces::planar::{force_plan, reactions};
    assert_eq!(
        driver.frame(&[theta]),
        FrameStatus::Solved,
        "{} at {theta}",
        m.name
    );
    let actual = moving.map(|mv| {
        (driver.solver())
            .rates(driver.state(), driver.inputs(), mv.rates, mv.accelerations)
            .unwrap()
    });
    let plan = force_plan(m).expect("no primitive constraints");
    let r = reactions(m, &plan, driver.poses(), actual.as_deref()).expect("no primitive constraints");
    let q = input_forces(m, driver.solver(), driver.state(), driver.inputs(), moving).unwrap();
    (r, q)
}

#[test]
fn the_slider_crank_s_reactions_are_its_two_force_rod_s() {
    // The rod is pinned at both ends and carries no load of its own: it
    // pushes along itself. The slider, held against the piston force F,
    // takes from the rod R_C = (-F_x, -F_x tan(beta)) (beta the rod's
    // slope) and from the rail the rest, square to it; the rod passes R_C
    // on to the crank (R_B = R_C) and the crank to the ground (R_O = R_B);
    // the input holds the crank with Q = B x R_B.
    let m = load("loads/slider_crank_press");
    let mut d = Driver::new(Interpreter::new(plan(&m)), Options::default());
    let joint = |n: &str| m.joints.iter().position(|j| j.name == n).unwrap();
    let (o, b, c, s) = (joint("O"), joint("B"), joint("C"), joint("S"));
    for k in 0..24 {
        let theta = 15.0 * k as f64 + 1.0;
        let (r, q) = reactions_at(&m, &mut d, theta, None);
        let phi = (30.0 + theta).to_radians();
        let pb = [phi.cos(), phi.sin()];
        let pc = [pb[0] + (3.5f64.powi(2) - (pb[1] - 0.25).powi(2)).sqrt(), 0.25];
        let tan_beta = (pc[1] - pb[1]) / (pc[0] - pb[0]);
        let rc = [100.0, 100.0 * tan_beta];
        let close = |x: [f64; 2], y: [f64; 2]| (x[0] - y[0]).abs().max((x[1] - y[1]).abs()) < 1e-9;
        assert!(close(r.forces[c], rc), "C {:?} {rc:?} at {theta}", r.forces[c]);
        assert!(
            close(r.forces[b], rc) && close(r.forces[o], rc),
            "B, O at {theta}"
        );
        assert!(
            close(r.forces[s], [0.0, -rc[1]]),
            "S {:?} at {theta}",
            r.forces[s]
        );
        assert!(r.moments[s].abs() < 1e-9, "the rail's moment {}", r.moments[s]);
        let torque = pb[0] * rc[1] - pb[1] * rc[0];
        assert!(
            (r.inputs[0] - torque).abs() < 1e-9 && (q[0] - torque).abs() < 1e-9,
            "{} {q:?} {torque}",
            r.inputs[0]
        );
        assert!(r.indeterminate.is_empty() && r.residual < 1e-10);
    }
}

#[test]
fn reactions_balance_every_body_and_give_the_virtual_work_input_torque() {
    // The four-bar with every kind of load, held and running: every moving
    // body's forces and moments sum to zero (to 1e-10 of the loads), and
    // the input torque from the bodies' equilibrium is virtual work's.
    let m = load("loads/fourbar_weights");
    let interp = Interpreter::new(plan(&m));
    let mut d = Driver::new(interp, Options::default());
    let rates = [2f64.to_degrees()];
    for moving in [
        None,
        Some(Moving {
            rates: &rates,
            accelerations: &[0.0],
        }),
    ] {
        for k in 0..36 {
            let theta = 10.0 * k as f64 + 0.5;
            let (r, q) = reactions_at(&m, &mut d, theta, moving);
            assert!(r.indeterminate.is_empty(), "{:?}", r.indeterminate);
            assert!(r.residual < 1e-10 * 100.0, "residual {:e} at {theta}", r.residual);
            assert!(
                (r.inputs[0] - q[0]).abs() < 1e-9 * q[0].abs().max(1.0),
                "{} {} at {theta}",
                r.inputs[0],
                q[0]
            );
        }
    }
}

#[test]
fn a_redundant_joint_s_reactions_are_not_unique_and_are_said_to_be() {
    // vlink: the V pinned to the coupler at two holes, joint W redundant.
    // A load on the V: the V's two pins share it in any proportion (the
    // least-norm share is given); the input torque is still unique.
    let text = std::fs::read_to_string(mechanisms_dir().join("vlink.toml")).unwrap()
        + "\n[loads.tip]\nkind = \"force\"\nmarker = \"vee.T\"\nforce = [5.0, -10.0]\n";
    let m = load_str("vlink_loaded.toml", &text, Format::Toml).unwrap();
    let mut d = Driver::new(Interpreter::new(plan(&m)), Options::default());
    let names = |js: &[usize]| js.iter().map(|&j| m.joints[j].name.clone()).collect::<Vec<_>>();
    for theta in [10.0, 100.0, 250.0] {
        let (r, q) = reactions_at(&m, &mut d, theta, None);
        let loose = names(&r.indeterminate);
        assert!(
            loose.contains(&"U".to_string()) && loose.contains(&"W".to_string()),
            "{loose:?}"
        );
        assert!(!loose.contains(&"A".to_string()), "{loose:?}");
        assert!(r.residual < 1e-9, "{}", r.residual);
        assert!((r.inputs[0] - q[0]).abs() < 1e-9 * q[0].abs().max(1.0));
    }
}

#[test]
fn the_ground_takes_every_outside_load_and_running_the_inertia_too() {
    // Springs, dampers and torsion springs act between the mechanism's own
    // bodies (the ground among them) and cancel; what reaches the ground
    // is the weight, the payload, the brake's torque and, running, minus
    // the bodies' mass times their centres' accelerations.
    let m = load("loads/fourbar_weights");
    let interp = Interpreter::new(plan(&m));
    let mut d = Driver::new(interp.clone(), Options::default());
    let g = m.loads.gravity.unwrap();
    let rates = [2f64.to_degrees()];
    for moving in [
        None,
        Some(Moving {
            rates: &rates,
            accelerations: &[0.0],
        }),
    ] {
        for k in 0..12 {
            let theta = 30.0 * k as f64 + 4.0;
            let (r, _) = reactions_at(&m, &mut d, theta, moving);
            let jets = interp
                .rates(
                    d.state(),
                    d.inputs(),
                    moving.map_or(&[0.0][..], |mv| mv.rates),
                    &[0.0],
                )
                .unwrap();
            let mut expected = [0.0, -20.0, 0.0];
            let p = d.poses()[m.bodies.iter().position(|b| b.name == "coupler").unwrap()].world([3.0, 3.5]);
            expected[2] += p[0] * -20.0 + 3.0;
            for (b, mass) in m.loads.masses.iter().enumerate() {
                let Some(mass) = mass else { continue };
                let c = jets[b].world(mass.centre);
                let f = [mass.mass * (g[0] - c[0].dd), mass.mass * (g[1] - c[1].dd)];
                let alpha = jets[b].rot.c.v * jets[b].rot.s.dd - jets[b].rot.s.v * jets[b].rot.c.dd;
                expected[0] += f[0];
                expected[1] += f[1];
                expected[2] += c[0].v * f[1] - c[1].v * f[0] - mass.inertia * alpha;
            }
            for k in 0..3 {
                assert!(
                    (r.shaking[k] - expected[k]).abs() < 1e-9 * 100.0,
                    "{:?} against {expected:?} at {theta}",
                    r.shaking
                );
            }
            if moving.is_none() {
                assert!(
                    (r.shaking[1] - (-20.0 - 9.81 * 3.5)).abs() < 1e-9,
                    "{:?}",
                    r.shaking
                );
            }
        }
    }
}

#[test]
fn the_slider_crank_s_mechanical_advantage_is_its_closed_form_s() {
    // Per unit crank torque: the slider holds 1 / |dx_C/dphi|, the rod's
    // pin at C (the rod turning against the slider, which does not turn)
    // 1 / |dpsi/dphi| with sin(psi) = (e - r sin(phi)) / l, the crank's tip
    // 1 / r.
    use dofplan::forces::planar::advantage;
    let m = load("loads/slider_crank_press");
    let mut d = Driver::new(Interpreter::new(plan(&m)), Options::default());
    let joint = |n: &str| m.joints.iter().position(|j| j.name == n).unwrap();
    let marker = |n: &str| m.all_markers().position(|id| m.marker_name(id) == n).unwrap();
    let (r, l, e) = (1.0f64, 3.5f64, 0.25f64);
    for k in 0..24 {
        let theta = 15.0 * k as f64 + 2.0;
        assert!(d.frame(&[theta]).is_solved());
        let a = advantage(&m, d.solver(), d.state(), d.inputs()).unwrap().unwrap();
        let phi = (30.0 + theta).to_radians();
        let root = (l * l - (r * phi.sin() - e).powi(2)).sqrt();
        let dx = -r * phi.sin() - (r * phi.sin() - e) * r * phi.cos() / root;
        let psi = ((e - r * phi.sin()) / l).asin();
        let dpsi = -r * phi.cos() / (l * psi.cos());
        let close = |got: Option<f64>, want: f64| (got.unwrap() - want).abs() < 1e-9 * want;
        assert!(close(a.joints[joint("S")], 1.0 / dx.abs()), "S at {theta}");
        assert!(
            close(a.markers[marker("slider.C")], 1.0 / dx.abs()),
            "slider.C at {theta}"
        );
        assert!(
            close(a.joints[joint("C")], 1.0 / dpsi.abs()),
            "C at {theta}: {:?} {}",
            a.joints[joint("C")],
            1.0 / dpsi.abs()
        );
        assert!(close(a.markers[marker("crank.B")], 1.0 / r));
        assert_eq!(a.joints[joint("O")], None, "the driven joint");
        assert_eq!(a.markers[marker("ground.O")], None, "the ground does not move");
    }
}

#[test]
fn the_force_plan_solves_in_blocks_what_least_squares_solves_whole() {
    // Made once from the equations' structure, each body's moment about
    // one of its pins: the four-bar's coupler about its crank pin and its
    // rocker about the ground pin give the coupler-rocker pin C (two
    // equations in its two components), then every other unknown one at a
    // time (B, D, then the crank's A and the input torque); the
    // slider-crank's rod and slider give three (the rod's far pin and the
    // rail's force), then ones. Each block solve gives least squares'
    // answer; the over-constrained V-linkage keeps least squares, which
    // names its redundant pins.
    use dofplan::forces::plan::ForcePlan;
    use dofplan::forces::planar::{force_plan, reactions};
    for (name, sizes) in [
        ("loads/fourbar_weights", vec![2, 1, 1, 1, 1, 1, 1, 1]),
        ("loads/slider_crank_press", vec![3, 1, 1, 1, 1, 1, 1]),
    ] {
        let m = load(name);
        let plan = force_plan(&m).unwrap();
        assert_eq!(plan.block_sizes(), sizes, "{name}");
        let interp = Interpreter::new(dofplan_tests::plan(&m));
        let mut d = Driver::new(interp.clone(), Options::default());
        let whole = ForcePlan::LeastSquares("compared");
        for k in 0..72 {
            assert!(d.frame(&[5.0 * k as f64 + 1.0]).is_solved());
            let rates = [90.0];
            let actual = interp.rates(d.state(), d.inputs(), &rates, &[0.0]).unwrap();
            for motion in [None, Some(&actual[..])] {
                let a = reactions(&m, &plan, d.poses(), motion).unwrap();
                let b = reactions(&m, &whole, d.poses(), motion).unwrap();
                let size = a.forces.iter().flatten().fold(1.0f64, |s, v| s.max(v.abs()));
                let gap = (a.forces.iter().flatten().zip(b.forces.iter().flatten()))
                    .chain(a.inputs.iter().zip(&b.inputs))
                    .chain(a.moments.iter().zip(&b.moments))
                    .chain(a.shaking.iter().zip(&b.shaking))
                    .fold(0.0f64, |g, (x, y)| g.max((x - y).abs()));
                assert!(gap < 1e-11 * size, "{name}: {gap:e}");
                assert!(a.residual < 1e-12 * size && a.indeterminate.is_empty(), "{name}");
            }
        }
    }
    let text = std::fs::read_to_string(mechanisms_dir().join("vlink.toml")).unwrap()
        + "\n[loads.weight]\nkind = \"force\"\nmarker = \"vee.T\"\nforce = [0, -1]\n";
    let m = load_str("vlink.toml", &text, Format::Toml).unwrap();
    assert!(matches!(force_plan(&m), Some(ForcePlan::LeastSquares(_))));
}

#[test]
fn a_chain_s_force_plan_is_small_blocks() {
    // Four four-bar loops in a chain (stress_10): 27 equations, yet no
    // block larger than a loop's middle pin (two unknowns: the moment
    // choice is made body by body here, past 4096 combinations), so each
    // frame's cost grows with the chain's length, not its cube; and the
    // chain's reactions still balance.
    use dofplan::forces::plan::ForcePlan;
    use dofplan::forces::planar::{force_plan, reactions};
    let text = std::fs::read_to_string(mechanisms_dir().join("stress_10.toml")).unwrap()
        + "\n[loads.end]\nkind = \"force\"\nmarker = \"rocker_4.R4\"\nforce = [0, -1]\n";
    let m = load_str("stress_10.toml", &text, Format::Toml).unwrap();
    let forces = force_plan(&m).unwrap();
    let sizes = forces.block_sizes();
    assert_eq!(sizes.iter().sum::<usize>(), 3 * (m.bodies.len() - 1));
    assert!(sizes.iter().all(|&s| s <= 2), "{sizes:?}");
    let mut d = Driver::new(Interpreter::new(plan(&m)), Options::default());
    assert!(d.frame(&[10.0]).is_solved());
    let a = reactions(&m, &forces, d.poses(), None).unwrap();
    let b = reactions(&m, &ForcePlan::LeastSquares("compared"), d.poses(), None).unwrap();
    assert!(a.residual < 1e-12, "{}", a.residual);
    let gap = (a.forces.iter().flatten().zip(b.forces.iter().flatten()))
        .fold(0.0f64, |g, (x, y)| g.max((x - y).abs()));
    assert!(gap < 1e-10, "{gap:e}");
}

#[test]
fn speeding_up_adds_the_generalised_mass_times_the_acceleration() {
    // Q(w, a) - Q(w, 0) = M(theta) a with M = sum m |dc/dtheta|^2 +
    // I (dphi/dtheta)^2, every derivative here a central difference of
    // solved positions (not the plan's rates); springs, gravity and the
    // damper depend on the pose and rate alone and cancel.
    let m = load("loads/fourbar_weights");
    let interp = Interpreter::new(plan(&m));
    let (mut d, mut near) = (
        Driver::new(interp.clone(), Options::default()),
        Driver::new(interp.clone(), Options::default()),
    );
    let (w, a) = (2.0f64, 30.0f64);
    let rates = [w.to_degrees()];
    let accelerations = [a.to_degrees()];
    let h = 1e-4f64;
    let mut largest = 0.0f64;
    for k in 0..24 {
        let theta = 15.0 * k as f64 + 4.0;
        let mut poses = |t: f64| {
            assert!(near.frame(&[t]).is_solved());
            near.poses().to_vec()
        };
        let (ahead, behind) = (poses(theta + h), poses(theta - h));
        let per_radian = 2.0 * h.to_radians();
        let mut mass_of = 0.0;
        for (b, mass) in m.loads.masses.iter().enumerate() {
            let Some(mass) = mass else { continue };
            let (p, q) = (ahead[b].world(mass.centre), behind[b].world(mass.centre));
            let v = [(p[0] - q[0]) / per_radian, (p[1] - q[1]) / per_radian];
            let turn = |pose: &Pose| pose.rot.s.atan2(pose.rot.c);
            let spin = (turn(&ahead[b]) - turn(&behind[b])) / per_radian;
            mass_of += mass.mass * (v[0] * v[0] + v[1] * v[1]) + mass.inertia * spin * spin;
        }
        let steady = forces_at(
            &m,
            &mut d,
            theta,
            Some(Moving {
                rates: &rates,
                accelerations: &[0.0],
            }),
        );
        let speeding = forces_at(
            &m,
            &mut d,
            theta,
            Some(Moving {
                rates: &rates,
                accelerations: &accelerations,
            }),
        );
        let want = mass_of * a;
        largest = largest.max(want.abs());
        assert!(
            (speeding - steady - want).abs() < 1e-6 * want.abs(),
            "theta {theta}: {} against {want}",
            speeding - steady
        );
    }
    assert!(largest > 1.0, "the inertia counts: {largest}");
}
