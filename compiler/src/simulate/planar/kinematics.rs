//! What a designer reads off a frame beyond positions: every marker's
//! velocity and acceleration, every body's angular velocity and
//! acceleration (from [`Interpreter::rates`](crate::interp::Interpreter::rates),
//! exact), and each four-bar loop's transmission angle.

use dofplan_runtime::planar::{Point, Pose};
use dofplan_runtime::real::Jet2;

use crate::analysis::planar::grashof::FourBar;
use crate::model::Mechanism;

/// One frame's rates.
#[derive(Clone, Debug, PartialEq)]
pub struct Motion {
    /// Every marker's velocity, in [`Mechanism::all_markers`] order.
    pub velocity: Vec<Point>,
    /// Every marker's acceleration, in the same order.
    pub acceleration: Vec<Point>,
    /// Every body's angular velocity (rad per unit of time).
    pub omega: Vec<f64>,
    /// Every body's angular acceleration.
    pub alpha: Vec<f64>,
}

/// The rates of `m`'s markers and bodies from the bodies' jets.
pub fn motion(m: &Mechanism, jets: &[Pose<Jet2>]) -> Motion {
    let (mut velocity, mut acceleration) = (Vec::new(), Vec::new());
    for id in m.all_markers() {
        let local = m.marker(id).at;
        let p = jets[id.body].world(local);
        velocity.push([p[0].d, p[1].d]);
        acceleration.push([p[0].dd, p[1].dd]);
    }
    // For a unit (c, s): ω = c·ṡ − s·ċ, α = c·s̈ − s·c̈.
    let omega = jets
        .iter()
        .map(|p| p.rot.c.v * p.rot.s.d - p.rot.s.v * p.rot.c.d)
        .collect();
    let alpha = jets
        .iter()
        .map(|p| p.rot.c.v * p.rot.s.dd - p.rot.s.v * p.rot.c.dd)
        .collect();
    Motion {
        velocity,
        acceleration,
        omega,
        alpha,
    }
}

/// The transmission angle of a four-bar loop at `poses`, in degrees
/// (0..180): the angle between the coupler and the output link at their
/// joint. The output is the link beside the frame that no input drives
/// (the second, unless an input drives the joint of the second to the
/// frame).
pub fn transmission_angle(m: &Mechanism, f: &FourBar, poses: &[Pose]) -> f64 {
    transmission_cos(m, f, poses).acos().to_degrees()
}

/// The cosine of [`transmission_angle`] (in -1..1): what a search that
/// only compares angles needs, without an arc cosine per frame.
pub fn transmission_cos(m: &Mechanism, f: &FourBar, poses: &[Pose]) -> f64 {
    let driven_last = m.inputs.iter().any(|i| i.joint == f.joints[3]);
    // (coupler's far joint, the shared joint, the output's far joint)
    let (far_c, at, far_o, coupler, output) = if driven_last {
        (f.joints[2], f.joints[1], f.joints[0], f.bodies[2], f.bodies[1])
    } else {
        (f.joints[1], f.joints[2], f.joints[3], f.bodies[2], f.bodies[3])
    };
    let point = |joint: usize, body: usize| {
        let [a, b] = m.joints[joint].markers;
        let id = if a.body == body { a } else { b };
        poses[body].world(m.marker(id).at)
    };
    let j = point(at, coupler);
    let u = sub(point(far_c, coupler), j);
    let v = sub(point(far_o, output), j);
    let cos =
        (u[0] * v[0] + u[1] * v[1]) / ((u[0] * u[0] + u[1] * u[1]) * (v[0] * v[0] + v[1] * v[1])).sqrt();
    cos.clamp(-1.0, 1.0)
}

fn sub(a: Point, b: Point) -> Point {
    [a[0] - b[0], a[1] - b[1]]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::planar::grashof::four_bars;
    use crate::conflict::load_str;
    use crate::model::Format;

    /// fourbar as drawn: C = (4.5, 2.5), B = (1, 1), D = (4, 0):
    /// μ = angle between C→B = (−3.5, −1.5) and C→D = (−0.5, −2.5), worked
    /// out here.
    #[test]
    fn the_drawn_fourbar_transmits_at_the_angle_of_its_coupler_and_rocker() {
        let m = load_str(
            "f.toml",
            include_str!("../../../../mechanisms/fourbar.toml"),
            Format::Toml,
        )
        .unwrap();
        let f = &four_bars(&m)[0];
        let poses = vec![Pose::IDENTITY; m.bodies.len()];
        let (u, v) = ([-3.5_f64, -1.5_f64], [-0.5_f64, -2.5_f64]);
        let want = ((u[0] * v[0] + u[1] * v[1]) / (u[0].hypot(u[1]) * v[0].hypot(v[1])))
            .acos()
            .to_degrees();
        assert!((transmission_angle(&m, f, &poses) - want).abs() < 1e-12);
    }

    /// The rate of a sweep's input is the rate asked for, even over a span
    /// near the largest f64 (the span's difference would overflow).
    #[test]
    fn input_rates_survive_huge_spans() {
        let m = load_str(
            "f.toml",
            include_str!("../../../../mechanisms/fourbar.toml"),
            Format::Toml,
        )
        .unwrap();
        for (from, to) in [(0.0, 360.0), (0.0, 1e308), (-1e308, 1e308), (1e308, -1e308)] {
            let sweep = crate::model::Sweep::single(0, from, to, 3, Vec::new());
            let rates = crate::simulate::input_rates(&m.inputs, &sweep, 1.0);
            let want = if to > from { 1.0_f64 } else { -1.0 }.to_degrees();
            assert!((rates[0] - want).abs() < 1e-12, "{from}..{to}: {rates:?}");
        }
    }
}
