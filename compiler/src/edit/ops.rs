//! The edits, made on the `toml_edit` document: only the keys an edit is
//! about change, so comments, key order and layout elsewhere are kept.

use dofplan_runtime::planar::Pose;
use serde::Deserialize;
use toml_edit::{Array, DocumentMut, InlineTable, Item, Table, TableLike, Value};

use super::{names, EditError};
use crate::model::{InputKind, JointKind, MarkerId, Mechanism};
use dofplan_runtime::Point;

/// One edit of a planar mechanism file. Markers are named `"body.M"`,
/// points are `[x, y]` in the file's units. As JSON (what the editor's page
/// sends): `{"op": "add_body", "markers": [[0, 0], [1, 1]]}`.
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(tag = "op", rename_all = "snake_case", deny_unknown_fields)]
pub enum Edit {
    /// A new body (a link) with two or more markers, named `A`, `B`, …;
    /// `name` defaults to `link1`, `link2`, …
    AddBody {
        /// Its name.
        #[serde(default)]
        name: Option<String>,
        /// Its markers' positions.
        markers: Vec<Point>,
    },
    /// A new marker on a body.
    AddMarker {
        /// The body.
        body: String,
        /// Its name (default: the first free of `A` … `Z`, `M1`, …).
        #[serde(default)]
        name: Option<String>,
        /// Where it is.
        at: Point,
    },
    /// Moves a marker: a change of its body's geometry, or of the ground.
    /// Markers joined to it by revolute joints or coincident constraints
    /// move with it, so those joints stay closed.
    MoveMarker {
        /// The marker.
        marker: String,
        /// Where it goes.
        to: Point,
    },
    /// A revolute joint between markers of two bodies; with `snap`, the
    /// second marker (and what is joined to it) is first moved onto the
    /// first — dropping one marker onto another.
    Join {
        /// The first marker.
        a: String,
        /// The second marker.
        b: String,
        /// The joint's name (default `J1`, `J2`, …).
        #[serde(default)]
        name: Option<String>,
        /// Move `b` onto `a` first.
        #[serde(default)]
        snap: bool,
    },
    /// A revolute joint becomes prismatic, sliding along the line of the
    /// two bodies' markers as drawn (the first marker's direction; editable
    /// with `set_dir`), or a prismatic joint becomes revolute. An input on
    /// it changes kind with it (angle ↔ slide).
    Toggle {
        /// The joint.
        joint: String,
    },
    /// Sets a marker's direction (a prismatic joint's line).
    SetDir {
        /// The marker.
        marker: String,
        /// The direction (any length but zero).
        dir: Point,
    },
    /// Drives a joint: an angle input on a revolute joint, a slide on a
    /// prismatic one; `name` defaults to `theta`/`s` (`theta2`, … if taken).
    AddInput {
        /// The joint.
        joint: String,
        /// The input's name.
        #[serde(default)]
        name: Option<String>,
    },
    /// Deletes an input (and the sweep's use of it).
    DeleteInput {
        /// The input.
        input: String,
    },
    /// Deletes a body with its joints and constraints, the inputs on them
    /// and its markers' traces.
    DeleteBody {
        /// The body.
        body: String,
    },
    /// Deletes a marker with the joints and constraints on it, the inputs
    /// on those and its trace.
    DeleteMarker {
        /// The marker.
        marker: String,
    },
    /// Deletes a joint or a constraint, with the inputs on it.
    DeleteJoint {
        /// The joint.
        joint: String,
    },
    /// Renames the mechanism (the file's top-level `name`).
    Rename {
        /// The new name.
        name: String,
    },
    /// Sets the sweep: `input` moved from `from` to `to` in `steps` frames
    /// (both ends included). A sweep the file has keeps its traced markers
    /// and its comments; one that moves several inputs together
    /// (`sweep.inputs`) is refused, not silently narrowed to one.
    SetSweep {
        /// The input swept.
        input: String,
        /// Its first value (degrees for an angle).
        from: f64,
        /// Its last value.
        to: f64,
        /// Frames, both ends included.
        steps: u64,
    },
    /// Deletes the sweep (with its traced markers).
    DeleteSweep,
    /// Traces a marker over the sweep (`on`), or stops tracing it.
    Trace {
        /// The marker.
        marker: String,
        /// Traced or not.
        on: bool,
    },
}

fn refused(why: String) -> EditError {
    EditError::Refused(why)
}

/// Makes `edit` on `doc`, which `m` was loaded from; returns the summary.
pub(super) fn apply(doc: &mut DocumentMut, m: &Mechanism, edit: &Edit) -> Result<String, EditError> {
    match edit {
        Edit::AddBody { name, markers } => add_body(doc, m, name.as_deref(), markers),
        Edit::AddMarker { body, name, at } => add_marker(doc, m, body, name.as_deref(), *at),
        Edit::MoveMarker { marker, to } => {
            let id = marker_id(m, marker)?;
            let moved = move_group(doc, m, id, *to)?;
            Ok(format!("moved {} to {}", moved.join(", "), show(*to)))
        }
        Edit::Join { a, b, name, snap } => join(doc, m, a, b, name.as_deref(), *snap),
        Edit::Toggle { joint } => toggle(doc, m, joint),
        Edit::SetDir { marker, dir } => {
            let id = marker_id(m, marker)?;
            set_dir(doc, m, id, *dir)?;
            Ok(format!("{marker} now points along {}", show(*dir)))
        }
        Edit::AddInput { joint, name } => add_input(doc, m, joint, name.as_deref()),
        Edit::DeleteInput { input } => {
            if !m.inputs.iter().any(|i| &i.name == input) {
                return Err(refused(format!("there is no input named {input}")));
            }
            let mut removed = Vec::new();
            delete_input(doc, input, &mut removed);
            Ok(summary_of_deletion(&format!("input {input}"), &removed))
        }
        Edit::DeleteJoint { joint } => {
            let known = m.joints.iter().any(|j| &j.name == joint)
                || m.constraints.iter().any(|c| &c.name == joint)
                || m.gears.iter().any(|g| &g.name == joint)
                || m.slots.iter().any(|s| &s.name == joint);
            if !known {
                return Err(refused(format!("there is no joint or constraint named {joint}")));
            }
            let mut removed = Vec::new();
            delete_joint(doc, m, joint, &mut removed);
            Ok(summary_of_deletion(&format!("joint {joint}"), &removed))
        }
        Edit::DeleteMarker { marker } => delete_marker(doc, m, marker),
        Edit::Rename { name } => {
            if name.trim().is_empty() {
                return Err(refused("a mechanism's name cannot be empty".into()));
            }
            doc.insert("name", toml_edit::value(name.as_str()));
            Ok(format!("renamed the mechanism {name}"))
        }
        Edit::SetSweep { .. } => set_sweep(doc, m, edit),
        Edit::DeleteSweep => {
            if doc.remove("sweep").is_none() {
                return Err(refused("the file has no sweep".into()));
            }
            Ok("deleted the sweep".into())
        }
        Edit::Trace { marker, on } => trace(doc, m, marker, *on),
        Edit::DeleteBody { body } => delete_body(doc, m, body),
    }
}

/// [`Edit::AddBody`]: a new `[bodies]` table whose markers are named `A`,
/// `B`, … in the order given.
fn add_body(
    doc: &mut DocumentMut,
    m: &Mechanism,
    name: Option<&str>,
    markers: &[Point],
) -> Result<String, EditError> {
    if markers.len() < 2 {
        return Err(refused(format!(
            "a body needs two or more markers to be a link, {} given: click at least twice",
            markers.len()
        )));
    }
    let name = name.map_or_else(|| names::body(m), str::to_string);
    if m.bodies.iter().any(|b| b.name == name) {
        return Err(refused(format!("there is already a body named {name}")));
    }
    let mnames = names::markers(&[], markers.len());
    let mut table = InlineTable::new();
    for (n, p) in mnames.iter().zip(markers) {
        table.insert(n, point(*p));
    }
    let mut body = Table::new();
    body.insert("markers", Item::Value(Value::InlineTable(table)));
    section(doc, "bodies")?.insert(&name, Item::Table(body));
    Ok(format!("added body {name} with markers {}", mnames.join(", ")))
}

/// [`Edit::AddMarker`]: a new key in the body's `markers`.
fn add_marker(
    doc: &mut DocumentMut,
    m: &Mechanism,
    body: &str,
    name: Option<&str>,
    at: Point,
) -> Result<String, EditError> {
    let b = body_index(m, body)?;
    let taken: Vec<String> = m.bodies[b].markers.iter().map(|k| k.name.clone()).collect();
    let name = match name {
        Some(n) if taken.iter().any(|t| t == n) => {
            return Err(refused(format!("{body} already has a marker {n}")))
        }
        Some(n) => n.to_string(),
        None => names::markers(&taken, 1).remove(0),
    };
    markers_of(doc, body)?.insert(&name, Item::Value(point(at)));
    Ok(format!("added marker {body}.{name} at {}", show(at)))
}

/// [`Edit::Join`]: a new revolute joint, after moving `b` (and what is
/// joined to it) onto `a` when `snap` asks for it.
fn join(
    doc: &mut DocumentMut,
    m: &Mechanism,
    a: &str,
    b: &str,
    name: Option<&str>,
    snap: bool,
) -> Result<String, EditError> {
    let (ia, ib) = (marker_id(m, a)?, marker_id(m, b)?);
    if ia.body == ib.body {
        return Err(refused(format!(
            "{a} and {b} are on the same body: a joint joins two bodies"
        )));
    }
    let name = name.map_or_else(|| names::joint(m), str::to_string);
    if names::joint_taken(m, &name) {
        return Err(refused(format!(
            "there is already a joint or constraint named {name}"
        )));
    }
    let mut moved = String::new();
    if snap {
        let to = m.marker(ia).at;
        moved = format!("; moved {} onto {a}", move_group(doc, m, ib, to)?.join(", "));
    }
    let mut joint = Table::new();
    joint.insert("kind", toml_edit::value("revolute"));
    let mut pair = Array::new();
    pair.push(a);
    pair.push(b);
    joint.insert("markers", toml_edit::value(pair));
    section(doc, "joints")?.insert(&name, Item::Table(joint));
    Ok(format!("joined {a} and {b} by revolute joint {name}{moved}"))
}

/// [`Edit::AddInput`]: an angle input on a revolute joint, a slide on a
/// prismatic one.
fn add_input(
    doc: &mut DocumentMut,
    m: &Mechanism,
    joint: &str,
    name: Option<&str>,
) -> Result<String, EditError> {
    let j = joint_index(m, joint)?;
    let angle = m.joints[j].kind == JointKind::Revolute;
    let name = name.map_or_else(|| names::input(m, angle), str::to_string);
    if m.inputs.iter().any(|i| i.name == name) {
        return Err(refused(format!("there is already an input named {name}")));
    }
    let kind = if angle { "angle" } else { "slide" };
    let mut input = Table::new();
    input.insert("kind", toml_edit::value(kind));
    input.insert("joint", toml_edit::value(joint));
    section(doc, "inputs")?.insert(&name, Item::Table(input));
    Ok(format!("joint {joint} is driven by {kind} input {name}"))
}

/// [`Edit::DeleteMarker`]: the marker, with the joints, constraints and
/// inputs on it; a body's last marker is refused (delete the body).
fn delete_marker(doc: &mut DocumentMut, m: &Mechanism, marker: &str) -> Result<String, EditError> {
    let id = marker_id(m, marker)?;
    let mut removed = Vec::new();
    delete_uses(doc, m, id, &mut removed);
    let body = &m.bodies[id.body];
    if body.markers.len() == 1 {
        return Err(refused(format!(
            "{marker} is {}'s only marker: delete the body instead",
            body.name
        )));
    }
    markers_of(doc, &body.name)?.remove(&body.markers[id.marker].name);
    Ok(summary_of_deletion(&format!("marker {marker}"), &removed))
}

/// [`Edit::DeleteBody`]: the body with what uses its markers; the last
/// fixed body is refused (a mechanism needs a ground).
fn delete_body(doc: &mut DocumentMut, m: &Mechanism, body: &str) -> Result<String, EditError> {
    let b = body_index(m, body)?;
    if m.bodies[b].fixed && m.bodies.iter().filter(|x| x.fixed).count() == 1 {
        return Err(refused(format!(
            "{body} is the only fixed body: every mechanism needs a ground"
        )));
    }
    let mut removed = Vec::new();
    for k in 0..m.bodies[b].markers.len() {
        delete_uses(doc, m, MarkerId { body: b, marker: k }, &mut removed);
    }
    section(doc, "bodies")?.remove(body);
    Ok(summary_of_deletion(&format!("body {body}"), &removed))
}

/// The sweep's table, if the file has one.
fn sweep_of(doc: &mut DocumentMut) -> Option<&mut dyn TableLike> {
    doc.get_mut("sweep").and_then(Item::as_table_like_mut)
}

fn set_sweep(doc: &mut DocumentMut, m: &Mechanism, edit: &Edit) -> Result<String, EditError> {
    let Edit::SetSweep {
        input,
        from,
        to,
        steps,
    } = edit
    else {
        unreachable!("set_sweep is given a SetSweep")
    };
    if !m.inputs.iter().any(|i| &i.name == input) {
        return Err(refused(format!("there is no input named {input}")));
    }
    if ![from, to].iter().all(|v| v.is_finite()) {
        return Err(refused(format!(
            "the sweep's range {from} to {to} is not two numbers"
        )));
    }
    let steps = i64::try_from(*steps).unwrap_or(i64::MAX);
    let fresh = doc.get("sweep").is_none();
    let sweep = match sweep_of(doc) {
        Some(s) => s,
        None => {
            doc.insert("sweep", Item::Table(Table::new()));
            sweep_of(doc).ok_or_else(|| refused("`sweep` in the file is not a table".into()))?
        }
    };
    if sweep.contains_key("inputs") {
        return Err(refused(
            "the sweep moves several inputs together (sweep.inputs): edit it in the File tab".into(),
        ));
    }
    sweep.insert("input", toml_edit::value(input.as_str()));
    sweep.insert("from", toml_edit::value(*from));
    sweep.insert("to", toml_edit::value(*to));
    sweep.insert("steps", toml_edit::value(steps));
    Ok(format!(
        "{} the sweep: {input} from {} to {} in {steps} steps",
        if fresh { "added" } else { "set" },
        crate::plan::num(*from),
        crate::plan::num(*to)
    ))
}

fn trace(doc: &mut DocumentMut, m: &Mechanism, marker: &str, on: bool) -> Result<String, EditError> {
    let id = marker_id(m, marker)?;
    let name = m.marker_name(id);
    let Some(sweep) = sweep_of(doc) else {
        return Err(refused(format!(
            "the file has no sweep to trace {name} over: set one first"
        )));
    };
    if !sweep.contains_key("trace") {
        sweep.insert("trace", toml_edit::value(Array::new()));
    }
    let list = sweep
        .get_mut("trace")
        .and_then(Item::as_array_mut)
        .ok_or_else(|| refused("`sweep.trace` in the file is not an array".into()))?;
    let has = list.iter().any(|v| v.as_str() == Some(name.as_str()));
    match (on, has) {
        (true, true) => Err(refused(format!("{name} is traced already"))),
        (false, false) => Err(refused(format!("{name} is not traced"))),
        (true, false) => {
            list.push(name.as_str());
            Ok(format!("tracing {name} over the sweep"))
        }
        (false, true) => {
            list.retain(|v| v.as_str() != Some(name.as_str()));
            Ok(format!("no longer tracing {name}"))
        }
    }
}

/// Every marker and direction redrawn where `poses` put them.
pub(super) fn redraw(doc: &mut DocumentMut, m: &Mechanism, poses: &[Pose]) -> Result<String, EditError> {
    if poses.len() != m.bodies.len() {
        return Err(refused(format!(
            "{} poses for {} bodies",
            poses.len(),
            m.bodies.len()
        )));
    }
    let mut moved = 0;
    for (b, (body, pose)) in m.bodies.iter().zip(poses).enumerate() {
        if body.fixed || *pose == Pose::IDENTITY {
            continue;
        }
        for (k, marker) in body.markers.iter().enumerate() {
            let id = MarkerId { body: b, marker: k };
            set_at(doc, m, id, pose.world(marker.at))?;
            if let Some(d) = marker.dir {
                set_dir(doc, m, id, pose.world_dir(d))?;
            }
            moved += 1;
        }
    }
    Ok(format!("redrawn at the pose shown ({moved} markers moved)"))
}

/// A revolute joint made prismatic or back.
fn toggle(doc: &mut DocumentMut, m: &Mechanism, joint: &str) -> Result<String, EditError> {
    let j = joint_index(m, joint)?;
    let [first, second] = m.joints[j].markers;
    let (kind, input_kind, what) = match m.joints[j].kind {
        JointKind::Revolute => {
            let dir = match m.marker(first).dir {
                Some(d) => d,
                None => {
                    let d = slide_line(m, first, second);
                    set_dir(doc, m, first, d)?;
                    d
                }
            };
            ("prismatic", "slide", format!("prismatic along {}", show(dir)))
        }
        JointKind::Prismatic => ("revolute", "angle", "revolute".to_string()),
    };
    let table = section(doc, "joints")?
        .get_mut(joint)
        .and_then(Item::as_table_like_mut)
        .ok_or_else(|| refused(format!("joint {joint} is not a table in the file")))?;
    table.insert("kind", toml_edit::value(kind));
    let mut also = Vec::new();
    for input in m.inputs.iter().filter(|i| i.joint == j) {
        if let Some(t) = section(doc, "inputs")?
            .get_mut(&input.name)
            .and_then(Item::as_table_like_mut)
        {
            t.insert("kind", toml_edit::value(input_kind));
            let was = match input.kind {
                InputKind::Angle => "degrees",
                InputKind::Slide => "length units",
            };
            also.push(format!(
                "; input {} is now a {input_kind} (a sweep range over it was in {was}: check it)",
                input.name
            ));
        }
    }
    Ok(format!("joint {joint} is now {what}{}", also.concat()))
}

/// The prismatic line of a joint drawn as revolute: toward the second
/// body's nearest other marker, else the first body's, else along x.
fn slide_line(m: &Mechanism, first: MarkerId, second: MarkerId) -> Point {
    let at = m.marker(first).at;
    for id in [second, first] {
        let nearest = m.bodies[id.body]
            .markers
            .iter()
            .enumerate()
            .filter(|(k, _)| *k != id.marker)
            .map(|(_, mk)| [mk.at[0] - at[0], mk.at[1] - at[1]])
            .map(|d| (d[0].hypot(d[1]), d))
            .filter(|(len, _)| *len > 1e-9 * m.size().max(1.0))
            .min_by(|a, b| a.0.total_cmp(&b.0));
        if let Some((len, d)) = nearest {
            return [d[0] / len, d[1] / len];
        }
    }
    [1.0, 0.0]
}

/// Moves `id` and every marker joined to it by a revolute joint or a
/// coincident constraint to `to`; their names.
fn move_group(
    doc: &mut DocumentMut,
    m: &Mechanism,
    id: MarkerId,
    to: Point,
) -> Result<Vec<String>, EditError> {
    let mut group = vec![id];
    let mut i = 0;
    while i < group.len() {
        let at = group[i];
        for [a, b] in m.coincident_pairs() {
            for (x, y) in [(a, b), (b, a)] {
                if x == at && !group.contains(&y) {
                    group.push(y);
                }
            }
        }
        i += 1;
    }
    for &g in &group {
        set_at(doc, m, g, to)?;
    }
    Ok(group.iter().map(|&g| m.marker_name(g)).collect())
}

/// Deletes the joints, slots and constraints on `id` (with their inputs)
/// and its trace: a slot goes with its slot's marker and with its pin.
fn delete_uses(doc: &mut DocumentMut, m: &Mechanism, id: MarkerId, removed: &mut Vec<String>) {
    let names: Vec<String> = m
        .joints
        .iter()
        .filter(|j| j.markers.contains(&id))
        .map(|j| j.name.clone())
        .chain(
            m.slots
                .iter()
                .filter(|s| s.markers.contains(&id))
                .map(|s| s.name.clone()),
        )
        .chain(
            m.constraints
                .iter()
                .filter(|c| c.markers.contains(&id))
                .map(|c| c.name.clone()),
        )
        .collect();
    for n in names {
        if !removed.contains(&format!("joint {n}")) {
            removed.push(format!("joint {n}"));
            delete_joint(doc, m, &n, removed);
        }
    }
    let name = m.marker_name(id);
    if let Some(trace) = doc
        .get_mut("sweep")
        .and_then(|s| s.get_mut("trace"))
        .and_then(Item::as_array_mut)
    {
        let before = trace.len();
        trace.retain(|v| v.as_str() != Some(name.as_str()));
        if trace.len() != before {
            removed.push(format!("the trace of {name}"));
        }
    }
}

/// Deletes a joint, constraint, slot or gear pair, the inputs on it, and the
/// gear pairs that turn on it (a pair meshes two bodies each turning or
/// sliding in a joint with their carrier).
fn delete_joint(doc: &mut DocumentMut, m: &Mechanism, name: &str, removed: &mut Vec<String>) {
    for key in ["joints", "constraints"] {
        remove_entry(doc, key, name);
    }
    if let Some(j) = m.joints.iter().position(|j| j.name == name) {
        for input in m.inputs.iter().filter(|i| i.joint == j) {
            removed.push(format!("input {}", input.name));
            delete_input(doc, &input.name, removed);
        }
        for g in m.gears.iter().filter(|g| g.pivots.contains(&j)) {
            let gear = format!("joint {}", g.name);
            if !removed.contains(&gear) {
                removed.push(gear);
                remove_entry(doc, "joints", &g.name);
            }
        }
    }
}

/// Deletes an input and the sweep's use of it (the whole sweep when it
/// moved no other input).
fn delete_input(doc: &mut DocumentMut, name: &str, removed: &mut Vec<String>) {
    remove_entry(doc, "inputs", name);
    let Some(sweep) = doc.get_mut("sweep").and_then(Item::as_table_like_mut) else {
        return;
    };
    let single = sweep.get("input").and_then(Item::as_str) == Some(name);
    let mut empty = single;
    if let Some(inputs) = sweep.get_mut("inputs").and_then(Item::as_table_like_mut) {
        inputs.remove(name);
        empty = inputs.is_empty();
    }
    if empty {
        doc.remove("sweep");
        removed.push("the sweep".to_string());
    }
}

/// Removes `[key.name]`, and `[key]` once it is empty.
fn remove_entry(doc: &mut DocumentMut, key: &str, name: &str) {
    if let Some(t) = doc.get_mut(key).and_then(Item::as_table_like_mut) {
        t.remove(name);
        if t.is_empty() {
            doc.remove(key);
        }
    }
}

fn summary_of_deletion(what: &str, removed: &[String]) -> String {
    let also: Vec<&String> = removed.iter().filter(|r| r.as_str() != what).collect();
    if also.is_empty() {
        format!("deleted {what}")
    } else {
        let also: Vec<&str> = also.iter().map(|s| s.as_str()).collect();
        format!("deleted {what}; also removed {}", also.join(", "))
    }
}

/// `[x, y]` as the file writes it.
fn point(p: Point) -> Value {
    let mut a = Array::new();
    a.push(p[0]);
    a.push(p[1]);
    Value::Array(a)
}

/// `(x, y)` in a summary.
fn show(p: Point) -> String {
    format!("({}, {})", crate::plan::num(p[0]), crate::plan::num(p[1]))
}

/// The top-level table `key` (created when missing).
fn section<'d>(doc: &'d mut DocumentMut, key: &str) -> Result<&'d mut dyn TableLike, EditError> {
    if doc.get(key).is_none() {
        let mut t = Table::new();
        t.set_implicit(true);
        doc.insert(key, Item::Table(t));
    }
    doc.get_mut(key)
        .and_then(Item::as_table_like_mut)
        .ok_or_else(|| refused(format!("`{key}` in the file is not a table")))
}

/// A body's `markers` table.
fn markers_of<'d>(doc: &'d mut DocumentMut, body: &str) -> Result<&'d mut dyn TableLike, EditError> {
    section(doc, "bodies")?
        .get_mut(body)
        .and_then(|b| b.get_mut("markers"))
        .and_then(Item::as_table_like_mut)
        .ok_or_else(|| refused(format!("body {body} has no markers table in the file")))
}

/// Sets a marker's position, in whichever form the file writes it
/// (`[x, y]` or `{ at = [x, y], dir = [..] }`).
fn set_at(doc: &mut DocumentMut, m: &Mechanism, id: MarkerId, p: Point) -> Result<(), EditError> {
    let (body, marker) = (
        &m.bodies[id.body].name,
        &m.bodies[id.body].markers[id.marker].name,
    );
    let item = markers_of(doc, body)?
        .get_mut(marker)
        .ok_or_else(|| refused(format!("{body}.{marker} is not in the file")))?;
    match item.as_table_like_mut() {
        Some(t) => {
            t.insert("at", Item::Value(point(p)));
        }
        None => *item = Item::Value(point(p)),
    }
    Ok(())
}

/// Sets a marker's direction, writing the marker as `{ at, dir }` if it was
/// a bare point.
fn set_dir(doc: &mut DocumentMut, m: &Mechanism, id: MarkerId, d: Point) -> Result<(), EditError> {
    let mk = &m.bodies[id.body].markers[id.marker];
    let body = &m.bodies[id.body].name;
    let item = markers_of(doc, body)?
        .get_mut(&mk.name)
        .ok_or_else(|| refused(format!("{body}.{} is not in the file", mk.name)))?;
    match item.as_table_like_mut() {
        Some(t) => {
            t.insert("dir", Item::Value(point(d)));
        }
        None => {
            let mut t = InlineTable::new();
            t.insert("at", point(mk.at));
            t.insert("dir", point(d));
            *item = Item::Value(Value::InlineTable(t));
        }
    }
    Ok(())
}

fn body_index(m: &Mechanism, name: &str) -> Result<usize, EditError> {
    m.bodies
        .iter()
        .position(|b| b.name == name)
        .ok_or_else(|| refused(format!("there is no body named {name}")))
}

fn joint_index(m: &Mechanism, name: &str) -> Result<usize, EditError> {
    m.joints
        .iter()
        .position(|j| j.name == name)
        .ok_or_else(|| refused(format!("there is no joint named {name}")))
}

fn marker_id(m: &Mechanism, name: &str) -> Result<MarkerId, EditError> {
    let (body, marker) = name
        .split_once('.')
        .ok_or_else(|| refused(format!("`{name}` is not a marker: write it as body.marker")))?;
    let b = body_index(m, body)?;
    let k = m.bodies[b]
        .markers
        .iter()
        .position(|mk| mk.name == marker)
        .ok_or_else(|| refused(format!("body {body} has no marker {marker}")))?;
    Ok(MarkerId { body: b, marker: k })
}
