//! Names for what an edit creates: the first the file does not use yet, in
//! a deterministic order, so the same edits on the same file name the same
//! things.

use crate::model::Mechanism;

/// `prefix1`, `prefix2`, … : the first `taken` refuses.
fn numbered(prefix: &str, taken: impl Fn(&str) -> bool) -> String {
    (1..)
        .map(|i| format!("{prefix}{i}"))
        .find(|n| !taken(n))
        .expect("some number is free")
}

/// A new body's name: `link1`, `link2`, …
pub fn body(m: &Mechanism) -> String {
    numbered("link", |n| m.bodies.iter().any(|b| b.name == n))
}

/// Whether `name` is a joint's, a constraint's, a gear pair's or a slot's
/// (they share one namespace).
pub fn joint_taken(m: &Mechanism, name: &str) -> bool {
    m.joints.iter().any(|j| j.name == name)
        || m.constraints.iter().any(|c| c.name == name)
        || m.gears.iter().any(|g| g.name == name)
        || m.slots.iter().any(|s| s.name == name)
}

/// A new joint's name, unique among joints, constraints, gear pairs and
/// slots: `J1`, `J2`, …
pub fn joint(m: &Mechanism) -> String {
    numbered("J", |n| joint_taken(m, n))
}

/// A new input's name: `theta`, `theta2`, … for an angle, `s`, `s2`, … for a
/// slide.
pub fn input(m: &Mechanism, angle: bool) -> String {
    let base = if angle { "theta" } else { "s" };
    let taken = |n: &str| m.inputs.iter().any(|i| i.name == n);
    if !taken(base) {
        return base.to_string();
    }
    (2..)
        .map(|i| format!("{base}{i}"))
        .find(|n| !taken(n))
        .expect("some number is free")
}

/// New marker names on a body that has `taken`: `A` … `Z` first, then
/// `M1`, `M2`, …, `count` of them.
pub fn markers(taken: &[String], count: usize) -> Vec<String> {
    let letters = (b'A'..=b'Z').map(|c| (c as char).to_string());
    let numbered = (1..).map(|i| format!("M{i}"));
    letters
        .chain(numbered)
        .filter(|n| !taken.contains(n))
        .take(count)
        .collect()
}
