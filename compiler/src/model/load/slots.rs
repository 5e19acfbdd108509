//! Validating pins in slots (`kind = "slot"` entries of `[joints]`): two
//! markers, the first carrying the slot's direction, and the slot's ends,
//! between which the pin must be drawn.

use super::*;
use crate::model::planar::slots::Slot;

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
            self.check_keys(fields, &["kind", "markers", "ends"], &path);
            let pair = self.pair(
                fields,
                entry,
                &path,
                bodies,
                (&owner, "a slot's pin is a marker of another body than the slot's"),
            );
            let ends = self.ends(fields, entry, &path);
            let (Some(markers), Some(ends)) = (pair, ends) else {
                continue;
            };
            if !self.check_in_line(markers, bodies, entry, &path, &owner, "slot") {
                continue;
            }
            // Where the pin is drawn along the slot: between the ends.
            let (slot, pin) = (
                &bodies[markers[0].body].markers[markers[0].marker],
                &bodies[markers[1].body].markers[markers[1].marker],
            );
            let dir = slot.unit_dir().expect("checked: the slot's marker has a dir");
            let along = (pin.at[0] - slot.at[0]) * dir[0] + (pin.at[1] - slot.at[1]) * dir[1];
            if along < ends[0] || along > ends[1] {
                let loc = self.loc(Self::get(fields, "ends").unwrap_or(entry), &join(&path, "ends"));
                self.error(
                    loc,
                    format!(
                        "{owner}: the pin {}.{} is drawn {along} along the slot from {}.{}, outside its ends [{}, {}]",
                        bodies[markers[1].body].name, pin.name, bodies[markers[0].body].name, slot.name, ends[0], ends[1]
                    ),
                    Some("the ends are positions along the slot's dir from its marker: draw the pin between them".into()),
                );
                continue;
            }
            out.push((
                Slot {
                    name: key.name.to_string(),
                    markers,
                    ends,
                    line: None,
                },
                entry,
            ));
        }
        out
    }

    /// `ends = [lo, hi]`, lo below hi.
    fn ends(&mut self, fields: &[(Key, Node)], entry: &Node, path: &str) -> Option<[f64; 2]> {
        let node = self.required(fields, "ends", entry, path)?;
        let epath = join(path, "ends");
        let e = self.point(node, &epath)?;
        if e[0] >= e[1] {
            let loc = self.loc(node, &epath);
            self.error(
                loc,
                format!(
                    "`{epath}` is [{}, {}]: the first end must lie below the second",
                    e[0], e[1]
                ),
                Some("give the ends as positions along the slot's dir, low then high".into()),
            );
            return None;
        }
        Some(e)
    }
}
