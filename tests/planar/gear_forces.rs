//! Forces through a gear pair (`mechanisms/gears/geared_hoist.toml`: a
//! motor's pinion driving a drum gear that winds a rope) against
//! computations written here:
//! - the motor torque that holds the hoist, from the drum's load moment
//!   and the gear ratio (virtual work by hand: the drum turns −θ/3);
//! - the tooth force: its moment about the drum's axle balances the
//!   drum's loads, it leans exactly the pressure angle off the common
//!   tangent and its radial part always pushes the gears apart, whichever
//!   way the teeth drive (both ways occur over a drum turn);
//! - every body's force and moment equilibrium;
//! - running with the bodies' inertia, the input power against the rate
//!   of the kinetic and potential energy.

use dofplan::forces::planar::{force_plan, input_forces, reactions, Moving, Reactions};
use dofplan::interp::Interpreter;
use dofplan::model::Mechanism;
use dofplan_runtime::{Driver, FrameStatus, Options};
use dofplan_tests::{load, plan};

/// The hoist's drawing, read from the loaded file: the axles, the rope's
/// marker, the pitch radii (from the axles' distance and the pinion's
/// tooth marker), the drum's mass and centre, gravity and the rope's load.
struct Hoist {
    m: Mechanism,
    axle_a: [f64; 2],
    axle_b: [f64; 2],
    rope_at: [f64; 2],
    rope: [f64; 2],
    drum_mass: f64,
    drum_centre: [f64; 2],
    pinion_mass: f64,
    g: [f64; 2],
    /// The drum's pitch radius.
    rb: f64,
    /// The drum's turn per turn of the pinion.
    ratio: f64,
}

impl Hoist {
    fn new() -> Hoist {
        let m = load("gears/geared_hoist");
        let at = |n: &str| m.marker(m.find_marker(n).unwrap()).at;
        let (axle_a, axle_b, tooth) = (at("frame.A"), at("frame.B"), at("pinion.T"));
        // The pinion's pitch circle reaches its tooth marker; the drum's
        // is the rest of the centre distance (an external mesh).
        let ra = (tooth[0] - axle_a[0]).hypot(tooth[1] - axle_a[1]);
        let rb = (axle_b[0] - axle_a[0]).hypot(axle_b[1] - axle_a[1]) - ra;
        let body = |n: &str| m.bodies.iter().position(|b| b.name == n).unwrap();
        let drum = *m.loads.mass(body("drum")).unwrap();
        let pinion = *m.loads.mass(body("pinion")).unwrap();
        let dofplan::model::planar::loads::LoadKind::Force { force, .. } = m.loads.applied[0].kind else {
            panic!("the rope is a force")
        };
        Hoist {
            axle_a,
            axle_b,
            rope_at: at("drum.R"),
            rope: force,
            drum_mass: drum.mass,
            drum_centre: drum.centre,
            pinion_mass: pinion.mass,
            g: m.loads.gravity.unwrap(),
            rb,
            ratio: -ra / rb,
            m,
        }
    }

    /// The drum's load moment about its axle at drum angle `phi`
    /// (radians): the rope's and its weight's.
    fn drum_moment(&self, phi: f64) -> f64 {
        let turn = |p: [f64; 2]| {
            let d = [p[0] - self.axle_b[0], p[1] - self.axle_b[1]];
            [
                phi.cos() * d[0] - phi.sin() * d[1],
                phi.sin() * d[0] + phi.cos() * d[1],
            ]
        };
        let cross = |a: [f64; 2], b: [f64; 2]| a[0] * b[1] - a[1] * b[0];
        let weight = [self.drum_mass * self.g[0], self.drum_mass * self.g[1]];
        cross(turn(self.rope_at), self.rope) + cross(turn(self.drum_centre), weight)
    }
}

fn reactions_at(
    h: &Hoist,
    d: &mut Driver<Interpreter>,
    theta: f64,
    moving: Option<Moving>,
) -> (Reactions, f64) {
    assert_eq!(d.frame(&[theta]), FrameStatus::Solved, "motor at {theta}");
    let actual = moving.map(|mv| {
        (d.solver())
            .rates(d.state(), d.inputs(), mv.rates, mv.accelerations)
            .unwrap()
    });
    let fp = force_plan(&h.m).expect("a force plan");
    let r = reactions(&h.m, &fp, d.poses(), actual.as_deref()).expect("reactions");
    let q = input_forces(&h.m, d.solver(), d.state(), d.inputs(), moving).unwrap();
    (r, q[0])
}

#[test]
fn the_motor_holds_the_drum_s_moment_through_the_gear_ratio() {
    let h = Hoist::new();
    let mut d = Driver::new(Interpreter::new(plan(&h.m)), Options::default());
    let lean = 20f64.to_radians().tan();
    let (mut driving, mut braking) = (0, 0);
    for k in 0..=72 {
        let theta = 15.0 * k as f64 + 0.5;
        let (r, q) = reactions_at(&h, &mut d, theta, None);
        // Virtual work by hand: the drum turns ratio·θ, so the motor holds
        // −ratio × the drum's load moment.
        let phi = (h.ratio * theta).to_radians();
        let held = -h.ratio * h.drum_moment(phi);
        let scale = held.abs().max(1.0);
        assert!(
            (q - held).abs() < 1e-9 * scale,
            "virtual work {q} vs {held} at {theta}"
        );
        assert!(
            (r.inputs[0] - held).abs() < 1e-9 * scale,
            "reactions {} vs {held} at {theta}",
            r.inputs[0]
        );

        // The tooth force on the drum: its moment about the axle balances
        // the drum's loads; it leans the pressure angle off the tangent
        // (the pitch point lies on the line of centres, so only the
        // tangential part turns the drum), and pushes the drum away.
        let tooth = r.teeth[0];
        let nu = {
            let d = [h.axle_b[0] - h.axle_a[0], h.axle_b[1] - h.axle_a[1]];
            let n = d[0].hypot(d[1]);
            [d[0] / n, d[1] / n]
        };
        let tangential = -nu[1] * tooth[0] + nu[0] * tooth[1];
        let radial = nu[0] * tooth[0] + nu[1] * tooth[1];
        assert!(
            (-h.rb * tangential + h.drum_moment(phi)).abs() < 1e-9 * h.drum_moment(phi).abs().max(1.0),
            "the drum's moments at {theta}: tooth {tooth:?}"
        );
        assert!(
            (radial - lean * tangential.abs()).abs() < 1e-9 * tangential.abs().max(1.0),
            "the tooth force leans 20°, outward: {tooth:?} at {theta}"
        );
        if tangential > 0.0 {
            driving += 1;
        } else {
            braking += 1;
        }
        // The pinion: its pivot, the tooth force back and its weight.
        let pin = r.forces[0];
        let w = [h.pinion_mass * h.g[0], h.pinion_mass * h.g[1]];
        let sum = [pin[0] - tooth[0] + w[0], pin[1] - tooth[1] + w[1]];
        assert!(
            sum[0].abs().max(sum[1].abs()) < 1e-9 * scale,
            "pinion forces {sum:?} at {theta}"
        );
        assert!(r.residual < 1e-9 * scale, "residual {} at {theta}", r.residual);
    }
    assert!(driving > 5 && braking > 5, "both ways: {driving} {braking}");
}

#[test]
fn a_running_hoist_s_input_power_is_its_energy_s_rate() {
    // At a constant 2 rad/s of the motor: Q·ω = dE/dt, E the kinetic and
    // potential energy (the rope's weight included), dE/dθ by a
    // fourth-order central difference.
    let h = Hoist::new();
    let interp = Interpreter::new(plan(&h.m));
    let w = 2.0f64;
    let rates = [w.to_degrees()];
    let moving = Moving {
        rates: &rates,
        accelerations: &[0.0],
    };
    let mut d = Driver::new(interp.clone(), Options::default());
    let mut e_at = |theta: f64| {
        assert!(d.frame(&[theta]).is_solved());
        let jets = interp.rates(d.state(), d.inputs(), &rates, &[0.0]).unwrap();
        super::forces::energy(&h.m, &jets).0
    };
    let mut d2 = Driver::new(Interpreter::new(plan(&h.m)), Options::default());
    let step = 0.01f64;
    let (mut largest, mut worst) = (0.0f64, 0.0f64);
    for k in 0..36 {
        let theta = 30.0 * k as f64 + 3.0;
        let mut e = |dt: f64| e_at(theta + dt);
        let de =
            (-e(2.0 * step) + 8.0 * e(step) - 8.0 * e(-step) + e(-2.0 * step)) / (12.0 * step.to_radians());
        let (r, q) = reactions_at(&h, &mut d2, theta, Some(moving));
        assert!(
            (r.inputs[0] - q).abs() < 1e-9 * q.abs().max(1.0),
            "{} {q}",
            r.inputs[0]
        );
        largest = largest.max((q * w).abs());
        worst = worst.max((q * w - de * w).abs());
    }
    assert!(largest > 10.0, "the loads do work: {largest}");
    assert!(worst < 1e-8 * largest, "worst {worst:e} of {largest}");
}
