//! The mechanism file's text, and the sweep it runs.

use std::fmt::Write as _;

use super::layout::{Layout, Marker};
use super::Expression;
use crate::analysis::ranges::{assembly_ranges, InputRanges};
use crate::format::{number, rounded};
use crate::model::Mechanism;

/// The `[sweep]` to write.
pub(super) struct Sweep {
    pub input: String,
    pub from: f64,
    pub to: f64,
    pub steps: usize,
    /// Why this range, for a comment.
    pub why: String,
}

/// Frames of an angle sweep (one a degree over a full turn) and of a slide.
const ANGLE_STEPS: usize = 361;
const SLIDE_STEPS: usize = 201;

/// The file: a header saying where it came from and how names map, then
/// the mechanism.
pub(super) fn toml(
    expr: &Expression,
    l: &Layout,
    name: &str,
    sweep: Option<&Sweep>,
    notes: &[String],
) -> String {
    let mut s = header(expr, l, notes);
    // Writing into a String cannot fail.
    let _ = writeln!(s, "name = {}\n", quote(name));
    for body in &l.bodies {
        let _ = writeln!(s, "[bodies.{}]", body.name);
        if body.fixed {
            s.push_str("fixed = true\n");
        }
        let markers: Vec<String> = body.markers.iter().map(marker).collect();
        let _ = writeln!(s, "markers = {{ {} }}\n", markers.join(", "));
    }
    for j in &l.joints {
        let kind = if j.prismatic { "prismatic" } else { "revolute" };
        let [a, b] = j.ends.map(|e| format!("\"{}.P{}\"", l.bodies[e].name, j.point));
        let _ = writeln!(
            s,
            "[joints.{}]\nkind = \"{kind}\"\nmarkers = [{a}, {b}]\n",
            j.name
        );
    }
    for o in &l.offsets {
        let [a, b] = o.ends.map(|e| format!("\"{}.P{}\"", l.bodies[e].name, o.point));
        let _ = writeln!(
            s,
            "[constraints.{}]\nkind = \"offset\"\nmarkers = [{a}, {b}]\n",
            o.name
        );
    }
    for i in &l.inputs {
        let kind = if i.slide { "slide" } else { "angle" };
        let joint = &l.joints[i.joint].name;
        let _ = writeln!(s, "[inputs.{}]\nkind = \"{kind}\"\njoint = \"{joint}\"\n", i.name);
    }
    if let Some(w) = sweep {
        let _ = writeln!(s, "# {}", w.why);
        let _ = writeln!(
            s,
            "[sweep]\ninput = \"{}\"\nfrom = {}\nto = {}\nsteps = {}",
            w.input,
            number(w.from),
            number(w.to),
            w.steps
        );
        let trace: Vec<String> = (l.trace.iter())
            .map(|&(body, point)| format!("\"{}.P{point}\"", l.bodies[body].name))
            .collect();
        if !trace.is_empty() {
            let _ = writeln!(s, "trace = [{}]", trace.join(", "));
        }
    }
    s
}

/// `P3 = [x, y]`, or with its direction `P3 = { at = [x, y], dir = [dx, dy] }`.
fn marker(m: &Marker) -> String {
    let at = format!("[{}, {}]", number(m.at[0]), number(m.at[1]));
    match m.dir {
        None => format!("P{} = {at}", m.point),
        Some(d) => format!(
            "P{} = {{ at = {at}, dir = [{}, {}] }}",
            m.point,
            number(d[0]),
            number(d[1])
        ),
    }
}

/// A TOML basic string.
fn quote(text: &str) -> String {
    toml::Value::String(text.to_string()).to_string()
}

/// The text of a comment line: one line, whatever the file name holds.
fn comment(text: &str) -> String {
    text.replace(['\n', '\r'], " ")
}

/// Where the file came from, each point's type, position and links and
/// what it became, and each input pair's input.
fn header(expr: &Expression, l: &Layout, notes: &[String]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# Imported by `dofplan import` from the Pyslvs (PMKS) expression in {}.",
        comment(&expr.file.name)
    );
    s.push_str(
        "# Each point Pk is a marker Pk on every link it lists (`ground` is the fixed\n\
         # body, every other link a body of the same name); its joints are named\n\
         # after it: Pk on two links, Pk_LINK for each further link.\n#\n",
    );
    for (p, role) in expr.points.iter().zip(&l.roles) {
        let kind = match p.angle {
            Some(a) => format!("{} A[{}]", p.kind.name(), rounded(a, 6)),
            None => p.kind.name().to_string(),
        };
        let links: Vec<&str> = p.links.iter().map(|(n, _)| n.as_str()).collect();
        let _ = writeln!(
            s,
            "# {} {kind} at ({}, {}) on {}: {role}",
            p.name(),
            number(p.at[0]),
            number(p.at[1]),
            links.join(", ")
        );
    }
    if !l.inputs.is_empty() {
        s.push_str("#\n# Input pairs (base, drive):\n");
    }
    for i in &l.inputs {
        let _ = writeln!(
            s,
            "# ({}, {}) is input {}: {}",
            i.pair.0, i.pair.1, i.name, i.about
        );
    }
    for note in notes {
        let _ = writeln!(s, "#\n# Note: {}", comment(note));
    }
    s.push('\n');
    s
}

/// The sweep of the first input, and the notes for the user. Its range is
/// the input's assembly range around the drawn pose (a full turn when it
/// turns fully), so every frame of the sweep is a pose the mechanism
/// reaches; without a plan, a full turn or half the mechanism's size each
/// way.
pub(super) fn sweep(m: &Mechanism, l: &Layout) -> (Option<Sweep>, Vec<String>) {
    let Some(first) = l.inputs.first() else {
        let note = "the expression has no input pairs, so the file has no inputs and no sweep: give them after the expression, e.g. `((0, 1),)`, or with `dofplan import --input 0,1`";
        return (None, vec![note.into()]);
    };
    let size = m.size();
    let name = &first.name;
    let sweep = |(from, to): (f64, f64), why: String| Sweep {
        input: name.clone(),
        from,
        to,
        steps: if first.slide { SLIDE_STEPS } else { ANGLE_STEPS },
        why,
    };
    let default = if first.slide {
        (-size / 2.0, size / 2.0)
    } else {
        (0.0, 360.0)
    };
    let default_why = "the sweep is a default range (a full turn, or half the mechanism's size each way)";
    let analysis = crate::analysis::analyse(m);
    let plan = match &analysis.plan {
        Ok(plan) => plan,
        Err(e) => {
            let note = format!(
                "dofplan has no plan for this mechanism ({e}): `dofplan check` on the file says more"
            );
            return (
                Some(sweep(default, format!("No plan: {default_why}."))),
                vec![note],
            );
        }
    };
    let ranges = assembly_ranges(m, plan);
    let range = ranges.iter().find(|r| r.input == 0).and_then(|r| {
        if first.slide {
            slide_range(r, size).map(|r| (r, format!("The sweep runs input {name} over its assembly range (at most the mechanism's size each way).")))
        } else if r.full_turn() {
            Some(((0.0, 360.0), format!("Input {name} turns fully: the sweep is a full turn.")))
        } else {
            angle_range(r).map(|r| (r, format!("Input {name} does not turn fully: the sweep runs over its assembly range, to where the linkage breaks.")))
        }
    });
    match range {
        Some((range, why)) => (Some(sweep(range, why)), Vec::new()),
        None => (
            Some(sweep(default, format!("No assembly range found: {default_why}."))),
            Vec::new(),
        ),
    }
}

/// The assembly interval around the drawn pose, its ends moved inside by
/// at least a thousandth of a degree: a frame exactly at a dead point may
/// miss it by rounding.
fn angle_range(r: &InputRanges) -> Option<(f64, f64)> {
    let ivs = &r.intervals;
    let k = ivs.iter().position(|(a, b)| a.at <= 0.0 && 0.0 <= b.at)?;
    let (mut lo, mut hi) = (ivs[k].0.at, ivs[k].1.at);
    let last = ivs.len() - 1;
    // An interval that reaches −180° or 180° without a break goes on past
    // it: the interval at the other end of the search continues it.
    if k == 0 && k != last && ivs[0].0.brk.is_none() && ivs[last].1.brk.is_none() {
        lo = ivs[last].0.at - 360.0;
    }
    if k == last && k != 0 && ivs[last].1.brk.is_none() && ivs[0].0.brk.is_none() {
        hi = ivs[0].1.at + 360.0;
    }
    Some(inward(lo, hi, 3))
}

/// The slide's assembly interval around the drawn position; an end where
/// nothing breaks (the search goes out to 1,000 sizes) is held to the
/// mechanism's size.
fn slide_range(r: &InputRanges, size: f64) -> Option<(f64, f64)> {
    let (a, b) = r.intervals.iter().find(|(a, b)| a.at <= 0.0 && 0.0 <= b.at)?;
    let lo = if a.brk.is_some() { a.at } else { -size };
    let hi = if b.brk.is_some() { b.at } else { size };
    // Rounded to 1e-4 to 1e-3 of the mechanism's size.
    let decimals = (3 - size.log10().floor() as i64).clamp(0, 12) as usize;
    Some(inward(lo, hi, decimals))
}

/// `lo..hi` rounded inward to `decimals`, strictly inside, when that
/// leaves a range; else `lo..hi` as they are.
fn inward(lo: f64, hi: f64, decimals: usize) -> (f64, f64) {
    let q = 10f64.powi(-(decimals as i32));
    let snap = |x: f64| format!("{x:.decimals$}").parse().unwrap_or(x);
    let from = snap(((lo / q).floor() + 1.0) * q);
    let to = snap(((hi / q).ceil() - 1.0) * q);
    if from < to && from <= 0.0 && 0.0 <= to {
        (from, to)
    } else {
        (lo, hi)
    }
}
