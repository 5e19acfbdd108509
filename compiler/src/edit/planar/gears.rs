//! Gear pairs and racks in the editor: what the page is sent to draw them
//! (each pitch circle in its body's drawn coordinates, a rack's pitch line
//! in the rack's), the points they reach at a pose (the view frames them),
//! and the pairs redrawn at the pose on screen (so a plan from there meshes
//! where the gears are now).

use dofplan_runtime::planar::{Point, Pose};
use serde_json::{json, Value};

use crate::model::planar::gears::{Gear, GearKind, PitchLine};
use crate::model::Mechanism;

/// Tick marks along a rack's pitch line per turn of its pinion (one per
/// 30°, as `dofplan simulate --svg` draws them).
const RACK_TICKS_PER_TURN: f64 = 12.0;

fn unit(v: Point) -> Point {
    let n = v[0].hypot(v[1]);
    if n > 0.0 {
        [v[0] / n, v[1] / n]
    } else {
        [1.0, 0.0]
    }
}

/// `p + s·d`.
fn along(p: Point, s: f64, d: Point) -> Point {
    [p[0] + s * d[0], p[1] + s * d[1]]
}

/// Where the pitch circles touch as drawn (each circle's tick points
/// there): the mesh's pitch point.
fn pitch_point(g: &Gear) -> Point {
    g.mesh().at
}

/// A rack's pitch line (`None` for a gear pair), reaching over the rack's
/// markers.
fn line(m: &Mechanism, g: &Gear) -> Option<PitchLine> {
    g.pitch_line(m.bodies[g.bodies[1]].markers.iter().map(|k| k.at))
}

/// The `gears` of a `document` message: per pair its name, kind, bodies
/// (and carrier) by name, pitch radii (a rack's pinion's `radius`), each
/// body's pivot as drawn (`centres`: the pitch circles' centres in their
/// bodies' coordinates, which are the drawing's; a rack's is its slide
/// marker), the `pitch` point where they touch as drawn (each circle's
/// tick points there), and for a rack its pitch `line` in its own
/// coordinates: the pitch point `at`, the slide direction `dir`, its ends
/// `from`/`to` along it, the `normal` from the pinion toward the rack and
/// the `step` between its tick marks.
pub(super) fn describe(m: &Mechanism) -> Vec<Value> {
    m.gears
        .iter()
        .map(|g| {
            let name = |b: usize| m.bodies[b].name.as_str();
            let mut v = json!({
                "name": g.name,
                "kind": g.kind.name(),
                "bodies": [name(g.bodies[0]), name(g.bodies[1])],
                "carrier": g.carrier.map(name),
                "centres": g.centres,
                "pitch": pitch_point(g),
                "ratio": g.ratio(),
            });
            match g.kind {
                GearKind::Gear { radii, internal, .. } => {
                    v["radii"] = json!(radii);
                    v["internal"] = json!(internal);
                }
                GearKind::RackPinion { radius, .. } => {
                    let l = line(m, g).expect("a rack has a pitch line");
                    v["radius"] = json!(radius);
                    v["line"] = json!({
                        "at": l.at,
                        "dir": l.dir,
                        "from": l.from,
                        "to": l.to,
                        "normal": l.normal,
                        "step": std::f64::consts::TAU * radius / RACK_TICKS_PER_TURN,
                    });
                }
            }
            v
        })
        .collect()
}

/// The points the gear pairs reach at `poses`: each pitch circle's box
/// corners and each rack line's ends (to frame the view with).
pub(super) fn reach(m: &Mechanism, poses: &[Pose]) -> Vec<Point> {
    let mut out = Vec::new();
    for g in &m.gears {
        for c in g.pitch_circles() {
            let [x, y] = poses[c.body].world(c.centre);
            out.extend([[x - c.radius, y - c.radius], [x + c.radius, y + c.radius]]);
        }
        if let Some(l) = line(m, g) {
            let rack = &poses[g.bodies[1]];
            out.extend([l.from, l.to].map(|s| rack.world(along(l.at, s, l.dir))));
        }
    }
    out
}

/// The pairs of a mechanism redrawn at `poses` (every marker moved where
/// its body's pose puts it): each pivot where its body is now, and a
/// rack's slide direction turned with its carrier (the pitch circles and
/// the rack's side move rigidly with the bodies, so radii and sides hold).
pub(super) fn redraw(gears: &mut [Gear], poses: &[Pose]) {
    for g in gears {
        for (centre, &body) in g.centres.iter_mut().zip(&g.bodies) {
            *centre = poses[body].world(*centre);
        }
        if let (GearKind::RackPinion { dir, .. }, Some(carrier)) = (&mut g.kind, g.carrier) {
            *dir = unit(poses[carrier].world_dir(*dir));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::conflict::load_any;
    use crate::model::Model;

    fn load(name: &str) -> Mechanism {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../mechanisms/{name}.toml"));
        match load_any(&path) {
            Ok(Model::Planar(m)) => m,
            _ => panic!("{name} is a planar file"),
        }
    }

    fn close(a: Point, b: Point) -> bool {
        (a[0] - b[0]).hypot(a[1] - b[1]) < 1e-12
    }

    #[test]
    fn the_pitch_circles_touch_where_drawn() {
        // epicyclic: sun (r 2) and ring (r 4) about O, planet (r 1) at
        // (3, 0): sun and planet touch at (2, 0), planet and ring at (4, 0).
        let m = load("gears/epicyclic");
        let d = describe(&m);
        assert_eq!(d.len(), 2);
        assert_eq!(d[0]["name"], "sp");
        assert_eq!(d[0]["kind"], "gear");
        assert_eq!(d[0]["bodies"], json!(["sun", "planet"]));
        assert_eq!(d[0]["carrier"], "arm");
        assert_eq!(d[0]["radii"], json!([2.0, 1.0]));
        assert_eq!(d[0]["centres"], json!([[0.0, 0.0], [3.0, 0.0]]));
        assert_eq!(d[0]["pitch"], json!([2.0, 0.0]));
        assert_eq!(d[1]["name"], "pr");
        assert_eq!(d[1]["internal"], true);
        assert_eq!(d[1]["pitch"], json!([4.0, 0.0]));
        // Every circle is its radius from the pitch point.
        for g in &m.gears {
            let p = pitch_point(g);
            for c in g.pitch_circles() {
                let d = (p[0] - c.centre[0]).hypot(p[1] - c.centre[1]);
                assert!(
                    (d - c.radius).abs() < 1e-12,
                    "{}: {d} against {}",
                    g.name,
                    c.radius
                );
            }
        }
    }

    #[test]
    fn a_racks_pitch_line_is_tangent_to_its_pinion() {
        // rack_pinion: pinion r 1 at O, the rack below it sliding along x.
        let m = load("gears/rack_pinion");
        let d = &describe(&m)[0];
        assert_eq!(d["kind"], "rack-pinion");
        assert_eq!(d["bodies"], json!(["pinion", "rack"]));
        assert_eq!(d["carrier"], Value::Null);
        assert_eq!(d["radius"], 1.0);
        assert_eq!(d["pitch"], json!([0.0, -1.0]));
        let l = &d["line"];
        assert_eq!(
            (l["at"].clone(), l["dir"].clone()),
            (json!([0.0, -1.0]), json!([1.0, 0.0]))
        );
        assert_eq!(l["normal"], json!([-0.0, -1.0]));
        // The rack's markers T (0, -1) and E (2, -1), half a radius beyond.
        assert_eq!((l["from"].as_f64(), l["to"].as_f64()), (Some(-1.5), Some(2.5)));
    }

    #[test]
    fn redrawn_pairs_move_with_their_bodies() {
        let mut m = load("gears/epicyclic");
        let turned = Pose {
            at: [0.0, 0.0],
            rot: dofplan_runtime::planar::Rot::from_degrees(90.0),
        };
        // Everything but the frame turned a quarter about O.
        let poses: Vec<Pose> = (m.bodies.iter())
            .map(|b| if b.fixed { Pose::IDENTITY } else { turned })
            .collect();
        let before = reach(&m, &poses);
        redraw(&mut m.gears, &poses);
        assert!(
            close(m.gears[0].centres[1], [0.0, 3.0]),
            "{:?}",
            m.gears[0].centres
        );
        assert!(close(pitch_point(&m.gears[1]), [0.0, 4.0]));
        // Drawn at the identity now, they reach where they reached at the
        // poses before.
        let identity = vec![Pose::IDENTITY; m.bodies.len()];
        for (a, b) in before.iter().zip(reach(&m, &identity)) {
            assert!(close(*a, b), "{a:?} against {b:?}");
        }
    }
}
