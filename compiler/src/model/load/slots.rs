//! Validating pins in slots (`kind = "slot"` entries of `[joints]`): two
//! markers, the first carrying the slot's direction, the slot's ends,
//! between which the pin must be drawn, and for a circular slot its
//! radius, which must be the drawn distance from its centre to the pin.

use super::*;
use crate::model::planar::slots::{Shape, Slot};

impl Validator {
    /// The slots among `entries` (each a `[joints]` entry of kind `slot`).
    pub(super) fn slots<'n>(
        &mut self,
        entries: &[&'n (Key<'n>, Node<'n>)],
        bodies: &[Body],
    ) -> Vec<(Slot, &'n Node<'n>)> {
        let mut out = Vec::new();
        for (key, entry) in entries.iter().map(|e| (&e.0, &e.1)) {
            let path = join("joints", &key.name);
            let owner = format!("joint `{}`", key.name);
            self.check_name(key, &path, "joint");
            let Some(fields) = self.table(entry, &path) else {
                continue;
            };
            self.check_keys(fields, &["kind", "markers", "ends", "radius"], &path);
            let pair = self.pair(
                fields,
                entry,
                &path,
                bodies,
                (&owner, "a slot's pin is a marker of another body than the slot's"),
            );
            let shape = self.shape(fields, &path);
            let ends = self.ends(fields, entry, &path, shape);
            let (Some(markers), Some(ends), Some(shape)) = (pair, ends, shape) else {
                continue;
            };
            let drawn_ok = match shape {
                Shape::Straight => self.check_in_line(markers, bodies, entry, &path, &owner, "slot"),
                Shape::Arc { .. } => self.check_arc_dir(markers[0], bodies, entry, &path, &owner),
            };
            if !drawn_ok {
                continue;
            }
            let slot = Slot {
                name: key.name.to_string(),
                markers,
                shape,
                ends,
                line: None,
            };
            if self.check_pin_drawn(&slot, bodies, (fields, entry), &path, &owner) {
                out.push((slot, entry));
            }
        }
        out
    }

    /// Straight without `radius`; an arc with `radius = r` (r > 0).
    /// `None` after an error.
    fn shape(&mut self, fields: &[(Key, Node)], path: &str) -> Option<Shape> {
        let Some(node) = Self::get(fields, "radius") else {
            return Some(Shape::Straight);
        };
        let rpath = join(path, "radius");
        let radius = self.number(node, &rpath)?;
        if radius > 0.0 && radius.is_finite() {
            return Some(Shape::Arc { radius });
        }
        let loc = self.loc(node, &rpath);
        self.error(
            loc,
            format!("`{rpath}` is {radius}: an arc slot's radius must be positive"),
            Some("give the distance from the slot's marker (its centre) to the pin".into()),
        );
        None
    }

    /// `ends = [lo, hi]`, lo below hi (for an arc, less than a turn
    /// apart). Checked against the shape when it is known.
    fn ends(
        &mut self,
        fields: &[(Key, Node)],
        entry: &Node,
        path: &str,
        shape: Option<Shape>,
    ) -> Option<[f64; 2]> {
        let node = self.required(fields, "ends", entry, path)?;
        let epath = join(path, "ends");
        let e = self.point(node, &epath)?;
        let arc = matches!(shape, Some(Shape::Arc { .. }));
        let problem = if e[0] >= e[1] {
            "the first end must lie below the second"
        } else if arc && e[1] - e[0] > 360.0 {
            "an arc's ends lie at most a turn (360°) apart"
        } else {
            return Some(e);
        };
        let loc = self.loc(node, &epath);
        let help = if arc {
            "give the ends as angles in degrees about the slot's centre, counter-clockwise from its marker's dir, low then high"
        } else {
            "give the ends as positions along the slot's dir, low then high"
        };
        self.error(
            loc,
            format!("`{epath}` is [{}, {}]: {problem}", e[0], e[1]),
            Some(help.into()),
        );
        None
    }

    /// Whether an arc slot's centre marker has the `dir` its ends' angles
    /// count from; reports where not.
    fn check_arc_dir(
        &mut self,
        centre: MarkerId,
        bodies: &[Body],
        node: &Node,
        path: &str,
        owner: &str,
    ) -> bool {
        if bodies[centre.body].markers[centre.marker].unit_dir().is_some() {
            return true;
        }
        let needs = "the first marker of an arc slot is its centre, whose dir the ends' angles count from";
        self.no_direction(centre, bodies, node, path, owner, needs);
        false
    }

    /// Whether the pin is drawn on the slot (an arc's radius from its
    /// centre) and between its ends; reports where not.
    fn check_pin_drawn(
        &mut self,
        slot: &Slot,
        bodies: &[Body],
        (fields, entry): (&[(Key, Node)], &Node),
        path: &str,
        owner: &str,
    ) -> bool {
        let [s, p] = slot.markers;
        let (at, pin) = (
            &bodies[s.body].markers[s.marker],
            &bodies[p.body].markers[p.marker],
        );
        let names = (
            format!("{}.{}", bodies[p.body].name, pin.name),
            format!("{}.{}", bodies[s.body].name, at.name),
        );
        let dir = at.unit_dir().expect("checked: the slot's marker has a dir");
        let v = [pin.at[0] - at.at[0], pin.at[1] - at.at[1]];
        let (where_, inside, help) = match slot.shape {
            Shape::Straight => {
                let along = v[0] * dir[0] + v[1] * dir[1];
                (
                    format!("{along} along the slot"),
                    along >= slot.ends[0] && along <= slot.ends[1],
                    "the ends are positions along the slot's dir from its marker: draw the pin between them",
                )
            }
            Shape::Arc { radius } => {
                let drawn = v[0].hypot(v[1]);
                if (drawn - radius).abs() > DRAWN_TOLERANCE * self.size(bodies) {
                    let node = Self::get(fields, "radius").unwrap_or(entry);
                    let loc = self.loc(node, &join(path, "radius"));
                    self.error(
                        loc,
                        format!(
                            "{owner}: the pin {} is drawn {drawn} from the slot's centre {}, not its radius {radius}",
                            names.0, names.1
                        ),
                        Some("draw the pin on the arc, or give the drawn distance as the radius".into()),
                    );
                    return false;
                }
                let angle = (dir[0] * v[1] - dir[1] * v[0])
                    .atan2(dir[0] * v[0] + dir[1] * v[1])
                    .to_degrees();
                (
                    format!("at {angle}° about the slot's centre"),
                    (angle - slot.ends[0]).rem_euclid(360.0) <= slot.ends[1] - slot.ends[0],
                    "the ends are angles in degrees about the slot's marker, from its dir: draw the pin between them",
                )
            }
        };
        if !inside {
            let loc = self.loc(Self::get(fields, "ends").unwrap_or(entry), &join(path, "ends"));
            self.error(
                loc,
                format!(
                    "{owner}: the pin {} is drawn {where_} from {}, outside its ends [{}, {}]",
                    names.0, names.1, slot.ends[0], slot.ends[1]
                ),
                Some(help.into()),
            );
        }
        inside
    }
}
