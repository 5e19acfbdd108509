//! Pins in slots in the editor: what the page is sent to draw them (each
//! slot's segment in its body's drawn coordinates, between the ends the
//! pin runs between) and the points they reach at a pose (the view frames
//! them).
//!
//! A slot is a marker's line (its `dir`) and two ends along it, so a
//! mechanism redrawn at a pose moves it with its marker: the marker's
//! position and direction are turned with the slotted body, and the ends,
//! measured along the unit direction from it, hold (see
//! [`super::session`]'s `redrawn`).

use dofplan_runtime::planar::{Point, Pose};
use serde_json::{json, Value};

use crate::model::planar::slots::Slot;
use crate::model::Mechanism;

/// A slot's ends as points of the slotted body's drawing: `at + lo·dir`
/// and `at + hi·dir` (its marker's position `at`, unit direction `dir`).
fn segment(m: &Mechanism, s: &Slot) -> [Point; 2] {
    let marker = m.marker(s.markers[0]);
    let dir = marker
        .unit_dir()
        .expect("validated: a slot's marker carries a dir");
    s.ends
        .map(|t| [marker.at[0] + t * dir[0], marker.at[1] + t * dir[1]])
}

/// The `slots` of a `document` message: per slot its name, the slotted
/// `body` by name, the slot's `marker` and the `pin` ("body.M"), the unit
/// `dir` of the slot and its `ends` along it (as the file gives them), and
/// the `segment` between which the pin runs: the two end points in the
/// slotted body's drawn coordinates, low end first.
pub(super) fn describe(m: &Mechanism) -> Vec<Value> {
    m.slots
        .iter()
        .map(|s| {
            json!({
                "name": s.name,
                "body": m.bodies[s.markers[0].body].name,
                "marker": m.marker_name(s.markers[0]),
                "pin": m.marker_name(s.markers[1]),
                "dir": m.marker(s.markers[0]).unit_dir(),
                "ends": s.ends,
                "segment": segment(m, s),
            })
        })
        .collect()
}

/// The points the slots reach at `poses`: each slot's end points (to frame
/// the view with; a slot may reach past its body's markers).
pub(super) fn reach(m: &Mechanism, poses: &[Pose]) -> Vec<Point> {
    (m.slots.iter())
        .flat_map(|s| segment(m, s).map(|p| poses[s.markers[0].body].world(p)))
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
