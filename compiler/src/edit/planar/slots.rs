//! Pins in slots in the editor: what the page is sent to draw them (each
//! slot's centre line in its body's drawn coordinates, between the ends
//! the pin runs between) and the points they reach at a pose (the view
//! frames them).
//!
//! A slot is a marker's line (its `dir`) and two ends along it, or the
//! circle about the marker and two ends as angles from its `dir`, so a
//! mechanism redrawn at a pose moves it with its marker: the marker's
//! position and direction are turned with the slotted body, and the ends,
//! measured from it, hold (see [`super::session`]'s `redrawn`).

use dofplan_runtime::planar::{Point, Pose};
use serde_json::{json, Value};

use crate::model::planar::slots::Shape;
use crate::model::Mechanism;

/// The `slots` of a `document` message: per slot its name, the slotted
/// `body` by name, the slot's `marker` and the `pin` ("body.M"), the unit
/// `dir` of the slot and its `ends` (as the file gives them), its `radius`
/// (an arc's; `null` for a straight slot), the `segment` between which
/// the pin runs (the two end points in the slotted body's drawn
/// coordinates, low end first) and the `path` along it (the same two
/// points for a straight slot; an arc's centre line, points at most 3°
/// apart, end to end).
pub(super) fn describe(m: &Mechanism) -> Vec<Value> {
    m.slots
        .iter()
        .map(|s| {
            let path = s.centre_line(m);
            let radius = match s.shape {
                Shape::Straight => None,
                Shape::Arc { radius } => Some(radius),
            };
            json!({
                "name": s.name,
                "body": m.bodies[s.markers[0].body].name,
                "marker": m.marker_name(s.markers[0]),
                "pin": m.marker_name(s.markers[1]),
                "dir": m.marker(s.markers[0]).unit_dir(),
                "ends": s.ends,
                "radius": radius,
                "segment": [path[0], path[path.len() - 1]],
                "path": path,
            })
        })
        .collect()
}

/// The points the slots reach at `poses`: each slot's centre line (to
/// frame the view with; a slot may reach past its body's markers).
pub(super) fn reach(m: &Mechanism, poses: &[Pose]) -> Vec<Point> {
    (m.slots.iter())
        .flat_map(|s| {
            let body = s.markers[0].body;
            s.centre_line(m).into_iter().map(move |p| poses[body].world(p))
        })
        .collect()
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
    fn a_slot_is_described_between_its_ends_along_its_marker() {
        // quick_return: the rocker's slot through O4 = (0, -2) along
        // (1, 2)/√5, from 0.9 to 3.1 out.
        let m = load("slots/quick_return");
        let d = describe(&m);
        assert_eq!(d.len(), 1);
        let s = &d[0];
        assert_eq!(
            (&s["name"], &s["body"], &s["marker"], &s["pin"]),
            (
                &json!("S"),
                &json!("rocker"),
                &json!("rocker.S"),
                &json!("crank.A")
            )
        );
        assert_eq!(s["ends"], json!([0.9, 3.1]));
        let u = [1.0 / 5f64.sqrt(), 2.0 / 5f64.sqrt()];
        let point = |v: &Value| [v[0].as_f64().unwrap(), v[1].as_f64().unwrap()];
        let [lo, hi] = [point(&s["segment"][0]), point(&s["segment"][1])];
        assert!(close(lo, [0.9 * u[0], -2.0 + 0.9 * u[1]]), "{lo:?}");
        assert!(close(hi, [3.1 * u[0], -2.0 + 3.1 * u[1]]), "{hi:?}");
        // The pin as drawn, A = (1, 0), is on the segment, √5 out from O4.
        let t = (5f64.sqrt() - 0.9) / 2.2;
        let on = [lo[0] + t * (hi[0] - lo[0]), lo[1] + t * (hi[1] - lo[1])];
        assert!((on[0] - 1.0).hypot(on[1]) < 1e-12, "{on:?}");
        // The scotch yoke's vertical slot on the yoke.
        let m = load("slots/scotch_yoke");
        let s = &describe(&m)[0];
        assert_eq!((&s["body"], &s["pin"]), (&json!("yoke"), &json!("crank.P")));
        let x = 0.8660254037844387;
        assert_eq!(s["segment"], json!([[x, -1.25], [x, 1.25]]));
    }

    #[test]
    fn an_arc_slot_is_described_along_its_circle_between_its_ends() {
        // curved_lever: the arc of radius 3.5 about lever.C, its ends -40°
        // and 20° from C's dir (drawn pointing at the pin).
        let m = load("slots/curved_lever");
        let s = &describe(&m)[0];
        assert_eq!((&s["marker"], &s["radius"]), (&json!("lever.C"), &json!(3.5)));
        let point = |v: &Value| [v[0].as_f64().unwrap(), v[1].as_f64().unwrap()];
        let c = m.marker(m.find_marker("lever.C").unwrap());
        let d = c.unit_dir().unwrap();
        let path: Vec<Point> = s["path"].as_array().unwrap().iter().map(point).collect();
        assert_eq!(path.len(), 21, "60° in 3° steps");
        for (k, p) in path.iter().enumerate() {
            let a = (-40.0 + 3.0 * k as f64).to_radians();
            let u = [a.cos() * d[0] - a.sin() * d[1], a.sin() * d[0] + a.cos() * d[1]];
            assert!(
                close(*p, [c.at[0] + 3.5 * u[0], c.at[1] + 3.5 * u[1]]),
                "{k}: {p:?}"
            );
        }
        assert!(close(point(&s["segment"][0]), path[0]) && close(point(&s["segment"][1]), path[20]));
        // The pin as drawn, at 0°, is on the arc.
        let pin = at(&m, "crank.P");
        assert!(close(pin, [c.at[0] + 3.5 * d[0], c.at[1] + 3.5 * d[1]]));
        // Straight slots have no radius, and their path is their segment.
        let q = &describe(&load("slots/quick_return"))[0];
        assert!(q["radius"].is_null() && q["path"] == q["segment"]);
    }

    fn at(m: &Mechanism, name: &str) -> Point {
        m.marker(m.find_marker(name).unwrap()).at
    }

    #[test]
    fn a_slot_reaches_its_ends_where_its_body_is() {
        let m = load("slots/scotch_yoke");
        let identity = vec![Pose::IDENTITY; m.bodies.len()];
        let x = 0.8660254037844387;
        assert_eq!(reach(&m, &identity), vec![[x, -1.25], [x, 1.25]]);
        // The yoke moved 0.5 along x and (not that it could) turned a
        // quarter about its origin.
        let yoke = m.bodies.iter().position(|b| b.name == "yoke").unwrap();
        let mut poses = identity;
        poses[yoke] = Pose {
            at: [0.5, 0.0],
            rot: dofplan_runtime::planar::Rot::from_degrees(90.0),
        };
        let r = reach(&m, &poses);
        assert!(
            close(r[0], [0.5 + 1.25, x]) && close(r[1], [0.5 - 1.25, x]),
            "{r:?}"
        );
    }
}
