//! Dragging a point of a mechanism whose freedoms are all driven by its
//! inputs, through its plan: the inputs move so that the point comes as
//! close to the pointer as the mechanism reaches.
//!
//! Pinning a point of a one-DOF linkage is one equation too many, so a
//! general drag ([`super::drag`]) relaxes the pin with a task-priority
//! Newton solve over every body's pose: exact, but it costs a dense solve
//! over all the mechanism's unknowns per pointer move (147 for a 50-loop
//! chain). When the plan already places every body from the inputs, the
//! same least-squares problem has only the inputs as unknowns: minimise
//! |P(u) − target|² over u, each evaluation a run of the plan (so every
//! pose tried has its joints closed by construction). A one-DOF linkage
//! then follows its coupler curve to the point nearest the pointer, and a
//! two-DOF one pins the point exactly wherever it reaches.
//!
//! Gauss–Newton with Levenberg damping; the Jacobian of the point with
//! respect to the inputs comes from forward differences of plan runs (the
//! plan is straight-line code, a run costs microseconds). Each accepted
//! step is a frame of the driver, no longer than a few degrees or a few
//! hundredths of the mechanism's size, so branches are followed as in an
//! animation and never flip.

use dofplan_runtime::planar::{Point, Pose};
use dofplan_runtime::{Ctx, Driver, FrameStatus, Solver};

use crate::model::InputKind;

/// The most an input moves in one frame: degrees for angles, a fraction of
/// the mechanism's size for slides.
const MAX_DEGREES: f64 = 5.0;
const MAX_SLIDE: f64 = 0.02;

/// Gauss–Newton iterations a pointer move may take.
const ITERATIONS: usize = 60;

/// What one drag toward a target did.
#[derive(Clone, Debug, PartialEq)]
pub struct InputDragReport {
    /// The last frame's status (`Solved` unless the inputs ran into an
    /// assembly limit: then `Limited` with the step that broke).
    pub status: FrameStatus,
    /// How far the point ends from the target.
    pub distance: f64,
    /// Frames committed.
    pub frames: usize,
    /// Plan runs, frames and probes together.
    pub runs: usize,
}

/// Moves `driver`'s inputs so that the point `local` of body `body` comes
/// as close to `target` as the plan reaches, from where the driver is.
/// `kinds` are the inputs' kinds and `size` the mechanism's size (they set
/// the step limits and the difference steps).
pub fn drag_inputs<S: Solver<Pose = Pose>>(
    driver: &mut Driver<S>,
    body: usize,
    local: Point,
    target: Point,
    kinds: &[InputKind],
    size: f64,
) -> InputDragReport {
    let size = size.max(f64::MIN_POSITIVE);
    let k = kinds.len();
    let cap: Vec<f64> = kinds
        .iter()
        .map(|kind| match kind {
            InputKind::Angle => MAX_DEGREES,
            InputKind::Slide => MAX_SLIDE * size,
        })
        .collect();
    let h: Vec<f64> = cap.iter().map(|c| c * 1e-7).collect();
    let point = |poses: &[Pose]| poses[body].world(local);
    let gap = |p: Point| [p[0] - target[0], p[1] - target[1]];
    let mut report = InputDragReport {
        status: FrameStatus::Solved,
        distance: 0.0,
        frames: 0,
        runs: 0,
    };
    let mut lambda = 1e-6;
    for _ in 0..ITERATIONS {
        let u: Vec<f64> = driver.inputs().to_vec();
        let p = point(driver.poses());
        let r = gap(p);
        let f = r[0] * r[0] + r[1] * r[1];
        report.distance = f.sqrt();
        if report.distance <= 1e-12 * size || k == 0 {
            break;
        }
        // J: d point / d input, by forward differences of plan runs.
        let mut jac = vec![[0.0; 2]; k];
        for i in 0..k {
            let mut v = u.clone();
            v[i] += h[i];
            report.runs += 1;
            match probe(driver, &v, &point) {
                Some(q) => jac[i] = [(q[0] - p[0]) / h[i], (q[1] - p[1]) / h[i]],
                None => {
                    // At an assembly limit: difference backwards.
                    v[i] = u[i] - h[i];
                    report.runs += 1;
                    if let Some(q) = probe(driver, &v, &point) {
                        jac[i] = [(p[0] - q[0]) / h[i], (p[1] - q[1]) / h[i]];
                    }
                }
            }
        }
        // Gradient of ½|r|² and the Gauss–Newton matrix, scaled so every
        // input's step cap is 1 (angles and slides weigh alike).
        let g: Vec<f64> = (0..k)
            .map(|i| cap[i] * (jac[i][0] * r[0] + jac[i][1] * r[1]))
            .collect();
        let gn = g.iter().map(|x| x * x).sum::<f64>().sqrt();
        if gn <= 1e-13 * size * size {
            break; // the closest point the mechanism reaches
        }
        let a: Vec<Vec<f64>> = (0..k)
            .map(|i| {
                (0..k)
                    .map(|j| cap[i] * cap[j] * (jac[i][0] * jac[j][0] + jac[i][1] * jac[j][1]))
                    .collect()
            })
            .collect();
        let mut improved = false;
        for _ in 0..30 {
            let Some(step) = damped_step(&a, &g, lambda) else {
                lambda *= 10.0;
                continue;
            };
            // In units of the caps; at most one cap per frame.
            let longest = step.iter().fold(0.0_f64, |m, s| m.max(s.abs()));
            let shrink = if longest > 1.0 { 1.0 / longest } else { 1.0 };
            let v: Vec<f64> = (0..k).map(|i| u[i] + step[i] * shrink * cap[i]).collect();
            report.runs += 1;
            if let Some(q) = probe(driver, &v, &point) {
                let rq = gap(q);
                let fq = rq[0] * rq[0] + rq[1] * rq[1];
                if fq < f {
                    report.status = driver.frame(&v);
                    report.frames += 1;
                    report.runs += 1;
                    lambda = (lambda * 0.1).max(1e-12);
                    // Gains below a millionth of a pixel's worth: the
                    // closest approach (slow near a stretched-out pose).
                    improved = f - fq > 1e-18 * size * size;
                    break;
                }
            }
            lambda *= 10.0;
            if lambda > 1e12 {
                break;
            }
        }
        if !improved {
            // No step brings the point (noticeably) closer: it is at the closest
            // approach, or against an assembly limit.
            if let Some(v) = limit_toward(driver, &u, &g, &cap, &point, &gap, f) {
                report.status = driver.frame(&v);
                report.frames += 1;
            }
            break;
        }
    }
    report.distance = {
        let r = gap(point(driver.poses()));
        r[0].hypot(r[1])
    };
    report
}

/// The plan run at `inputs` from the driver's state, not committed; `None`
/// if it breaks there.
fn probe<S: Solver<Pose = Pose>>(
    driver: &Driver<S>,
    inputs: &[f64],
    point: &dyn Fn(&[Pose]) -> Point,
) -> Option<Point> {
    let mut state = driver.state().clone();
    let mut ctx = Ctx::new(driver.options().branch, false);
    driver.solver().solve(&mut state, inputs, &mut ctx).ok()?;
    Some(point(S::poses(&state)))
}

/// `(A + λ·diag(A) + λ·I)·s = −g`, by Gaussian elimination with partial
/// pivoting (a handful of inputs); `None` if singular.
fn damped_step(a: &[Vec<f64>], g: &[f64], lambda: f64) -> Option<Vec<f64>> {
    let n = g.len();
    let mut m: Vec<Vec<f64>> = (0..n)
        .map(|i| {
            let mut row = a[i].clone();
            row[i] += lambda * (a[i][i] + 1.0);
            row.push(-g[i]);
            row
        })
        .collect();
    for c in 0..n {
        let p = (c..n).max_by(|&x, &y| m[x][c].abs().total_cmp(&m[y][c].abs()))?;
        if m[p][c].abs() < 1e-300 {
            return None;
        }
        m.swap(c, p);
        let (top, below) = m.split_at_mut(c + 1);
        let pivot = &top[c];
        for row in below {
            let f = row[c] / pivot[c];
            for (x, p) in row[c..].iter_mut().zip(&pivot[c..]) {
                *x -= f * p;
            }
        }
    }
    let mut s = vec![0.0; n];
    for i in (0..n).rev() {
        let tail: f64 = (i + 1..n).map(|j| m[i][j] * s[j]).sum();
        s[i] = (m[i][n] - tail) / m[i][i];
    }
    s.iter().all(|x| x.is_finite()).then_some(s)
}

/// Against an assembly limit: the inputs as far along the descent
/// direction as the plan still assembles (bisection to 1e-9 of a cap), if
/// that brings the point closer.
fn limit_toward<S: Solver<Pose = Pose>>(
    driver: &Driver<S>,
    u: &[f64],
    g: &[f64],
    cap: &[f64],
    point: &dyn Fn(&[Pose]) -> Point,
    gap: &dyn Fn(Point) -> [f64; 2],
    f: f64,
) -> Option<Vec<f64>> {
    let gn = g.iter().map(|x| x * x).sum::<f64>().sqrt();
    if gn == 0.0 {
        return None;
    }
    let at = |t: f64| -> Vec<f64> { (0..u.len()).map(|i| u[i] - t * g[i] / gn * cap[i]).collect() };
    if probe(driver, &at(1.0), point).is_some() {
        return None; // not a limit: the descent simply stopped
    }
    let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
    while hi - lo > 1e-9 {
        let mid = 0.5 * (lo + hi);
        if probe(driver, &at(mid), point).is_some() {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let v = at(lo);
    let q = probe(driver, &v, point)?;
    let r = gap(q);
    (lo > 0.0 && r[0] * r[0] + r[1] * r[1] < f).then_some(v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::analyse;
    use crate::conflict::load_str;
    use crate::interp::Interpreter;
    use crate::model::Format;
    use dofplan_runtime::Options;

    const FOURBAR: &str = include_str!("../../../../mechanisms/fourbar.toml");

    /// The coupler point's curve sampled finely by the plan itself is the
    /// reference: the drag must end within a hair of the curve's point
    /// nearest the target (a brute-force minimum over 36,000 crank angles,
    /// continuous from the start), never farther.
    #[test]
    fn a_fourbar_dragged_by_its_coupler_point_stops_at_the_nearest_point_of_its_curve() {
        let m = load_str("fourbar.toml", FOURBAR, Format::Toml).unwrap();
        let plan = analyse(&m).plan.unwrap();
        let coupler = m.bodies.iter().position(|b| b.name == "coupler").unwrap();
        let p_local = [3.0, 3.5];
        let mut curve = Driver::new(Interpreter::new(plan.clone()), Options::default());
        let samples: Vec<Point> = (0..36_000)
            .map(|i| {
                curve.frame(&[i as f64 * 0.01]);
                curve.poses()[coupler].world(p_local)
            })
            .collect();
        let mut d = Driver::new(Interpreter::new(plan), Options::default());
        for target in [[3.5, 3.8], [2.0, 4.5], [6.0, 1.0], [-1.0, -3.0], [3.0, 3.5]] {
            let rep = drag_inputs(&mut d, coupler, p_local, target, &[InputKind::Angle], m.size());
            let nearest = samples
                .iter()
                .map(|q| (q[0] - target[0]).hypot(q[1] - target[1]))
                .fold(f64::INFINITY, f64::min);
            assert!(
                rep.distance <= nearest + 1e-6,
                "target {target:?}: ended {} away, the curve comes within {nearest}",
                rep.distance
            );
            // Every joint closed at the pose reached.
            for j in &m.joints {
                let [a, b] = j.markers.map(|id| d.poses()[id.body].world(m.marker(id).at));
                assert!((a[0] - b[0]).hypot(a[1] - b[1]) < 1e-9);
            }
        }
    }

    #[test]
    fn a_two_input_mechanism_pins_the_point_exactly() {
        // A two-link arm, both joints driven: any point of the annulus is
        // reached exactly.
        let text = "name = \"arm\"\n[bodies.ground]\nfixed = true\nmarkers = { O = [0, 0] }\n\
            [bodies.upper]\nmarkers = { O = [0, 0], E = [2, 0] }\n\
            [bodies.fore]\nmarkers = { E = [2, 0], H = [3.5, 0] }\n\
            [joints.S]\nkind = \"revolute\"\nmarkers = [\"ground.O\", \"upper.O\"]\n\
            [joints.E]\nkind = \"revolute\"\nmarkers = [\"upper.E\", \"fore.E\"]\n\
            [inputs.a]\nkind = \"angle\"\njoint = \"S\"\n\
            [inputs.b]\nkind = \"angle\"\njoint = \"E\"\n";
        let m = load_str("arm.toml", text, Format::Toml).unwrap();
        let plan = analyse(&m).plan.unwrap();
        let mut d = Driver::new(Interpreter::new(plan), Options::default());
        let kinds = [InputKind::Angle, InputKind::Angle];
        for target in [[1.0, 2.0], [-2.5, 0.5], [0.8, -1.2]] {
            let rep = drag_inputs(&mut d, 2, [3.5, 0.0], target, &kinds, m.size());
            assert!(rep.distance < 1e-9, "{target:?}: {rep:?}");
        }
        // Out of reach (|target| > 3.5): the arm stretches toward it.
        let rep = drag_inputs(&mut d, 2, [3.5, 0.0], [6.0, 0.0], &kinds, m.size());
        assert!((rep.distance - 2.5).abs() < 1e-5, "{rep:?}");
    }
}
