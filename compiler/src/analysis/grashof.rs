//! Four-bar loops and their Grashof class.
//!
//! A four-bar loop is a cycle of four bodies joined by four revolute
//! joints (every fixed body counts as one ground). Each link's length is
//! the distance between its two joints of the loop, as drawn. With s the
//! shortest, l the longest and p, q the others, Grashof's condition
//! s + l < p + q says the shortest link turns fully relative to the
//! others; which link is shortest, relative to the loop's frame (the ground
//! when the loop has one, otherwise its first body in file order), names
//! the class: the frame itself → double-crank, a link beside it →
//! crank-rocker, the coupler → double-rocker. s + l > p + q (non-Grashof,
//! a triple rocker) is a double-rocker too, and s + l = p + q a change
//! point (it can fold flat).

use crate::model::{JointKind, MarkerId, Mechanism};

/// A four-bar loop's class.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Class {
    /// The shortest link, beside the frame, turns fully; the other rocks.
    CrankRocker,
    /// The frame is the shortest link: both links beside it turn fully.
    DoubleCrank,
    /// Neither link beside the frame turns fully.
    DoubleRocker,
    /// s + l = p + q: the loop can fold flat.
    ChangePoint,
}

impl Class {
    /// The name reports use.
    pub fn name(self) -> &'static str {
        match self {
            Class::CrankRocker => "crank-rocker",
            Class::DoubleCrank => "double-crank",
            Class::DoubleRocker => "double-rocker",
            Class::ChangePoint => "change point",
        }
    }
}

/// A four-bar loop.
#[derive(Clone, Debug, PartialEq)]
pub struct FourBar {
    /// The bodies around the loop, the frame first (a fixed body when the
    /// loop has one): frame, link, coupler, link.
    pub bodies: [usize; 4],
    /// The joints, `joints[k]` between `bodies[k]` and `bodies[k + 1]`.
    pub joints: [usize; 4],
    /// Each body's link length in the loop.
    pub lengths: [f64; 4],
    /// Its class.
    pub class: Class,
    /// Whether s + l < p + q.
    pub grashof: bool,
    /// s + l and p + q.
    pub sums: (f64, f64),
}

/// Every four-bar loop of `m`, in a deterministic order (by their joints'
/// file order).
pub fn four_bars(m: &Mechanism) -> Vec<FourBar> {
    // Every fixed body is the one ground node.
    let ground = m.bodies.iter().position(|b| b.fixed);
    let node = |b: usize| if m.bodies[b].fixed { ground.unwrap_or(b) } else { b };
    let revolute: Vec<(usize, [MarkerId; 2])> = (m.joints.iter().enumerate())
        .filter(|(_, j)| j.kind == JointKind::Revolute)
        .map(|(k, j)| (k, j.markers))
        .collect();
    let mut adjacent: Vec<Vec<(usize, usize)>> = vec![Vec::new(); m.bodies.len()];
    for &(k, [a, b]) in &revolute {
        let (na, nb) = (node(a.body), node(b.body));
        if na != nb {
            adjacent[na].push((nb, k));
            adjacent[nb].push((na, k));
        }
    }
    let size = m.size();
    let mut seen = std::collections::BTreeSet::new();
    let mut out = Vec::new();
    for a in 0..m.bodies.len() {
        for (x, &(b, j1)) in adjacent[a].iter().enumerate() {
            for &(c, j2) in &adjacent[a][x + 1..] {
                if b == c || j1 == j2 {
                    continue;
                }
                for &(d, j3) in &adjacent[b] {
                    if [a, b, c].contains(&d) || j3 == j1 || j3 == j2 {
                        continue;
                    }
                    for &(e, j4) in &adjacent[c] {
                        if e != d || [j1, j2, j3].contains(&j4) {
                            continue;
                        }
                        let mut key = [j1, j2, j3, j4];
                        key.sort_unstable();
                        if !seen.insert(key) {
                            continue;
                        }
                        // Around the loop: a –j1– b –j3– d –j4– c –j2– a.
                        if let Some(f) = loop_of(m, [a, b, d, c], [j1, j3, j4, j2], &node, size) {
                            out.push(f);
                        }
                    }
                }
            }
        }
    }
    out.sort_by_key(|f| {
        let mut k = f.joints;
        k.sort_unstable();
        k
    });
    out
}

/// The four-bar of bodies `b` around joints `j` (`j[k]` between `b[k]` and
/// `b[k + 1]`), turned so its frame comes first; `None` if a link has no
/// length (two joints at one point).
fn loop_of(
    m: &Mechanism,
    b: [usize; 4],
    j: [usize; 4],
    node: &dyn Fn(usize) -> usize,
    size: f64,
) -> Option<FourBar> {
    // The frame: a fixed body, else the first in file order.
    let first = (0..4)
        .find(|&k| m.bodies[b[k]].fixed)
        .unwrap_or_else(|| (0..4).min_by_key(|&k| b[k]).expect("four bodies"));
    let bodies: [usize; 4] = std::array::from_fn(|k| b[(first + k) % 4]);
    let joints: [usize; 4] = std::array::from_fn(|k| j[(first + k) % 4]);
    // Where joint `k` is on the body `on` (its marker there).
    let at = |k: usize, on: usize| {
        let [x, y] = m.joints[k].markers;
        let id = if node(x.body) == on { x } else { y };
        m.marker(id).at
    };
    let lengths: [f64; 4] = std::array::from_fn(|k| {
        let (p, q) = (at(joints[(k + 3) % 4], bodies[k]), at(joints[k], bodies[k]));
        (p[0] - q[0]).hypot(p[1] - q[1])
    });
    if lengths.iter().any(|l| *l <= 1e-9 * size) {
        return None;
    }
    let mut sorted = lengths;
    sorted.sort_by(f64::total_cmp);
    let (s_l, p_q) = (sorted[0] + sorted[3], sorted[1] + sorted[2]);
    let shortest = (0..4)
        .min_by(|&x, &y| lengths[x].total_cmp(&lengths[y]))
        .expect("four links");
    let grashof = s_l < p_q;
    let class = if (s_l - p_q).abs() <= 1e-9 * p_q {
        Class::ChangePoint
    } else if !grashof {
        Class::DoubleRocker
    } else {
        match shortest {
            0 => Class::DoubleCrank,
            1 | 3 => Class::CrankRocker,
            _ => Class::DoubleRocker,
        }
    };
    Some(FourBar {
        bodies,
        joints,
        lengths,
        class,
        grashof,
        sums: (s_l, p_q),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{load_str, Format};

    fn classes(text: &str) -> Vec<(Vec<String>, &'static str)> {
        let m = load_str("m.toml", text, Format::Toml).unwrap();
        four_bars(&m)
            .into_iter()
            .map(|f| {
                (
                    f.bodies.iter().map(|&b| m.bodies[b].name.clone()).collect(),
                    f.class.name(),
                )
            })
            .collect()
    }

    #[test]
    fn the_bundled_four_bars_are_what_their_headers_say() {
        // fourbar: s + l = √2 + 4 < p + q, the crank shortest.
        let c = classes(include_str!("../../../mechanisms/fourbar.toml"));
        assert_eq!(c.len(), 1);
        assert_eq!(c[0].1, "crank-rocker");
        assert_eq!(c[0].0[0], "ground");
        // rocker_rocker: s + l = 7 > p + q = 5.5.
        let c = classes(include_str!("../../../mechanisms/rocker_rocker.toml"));
        assert_eq!(
            c,
            [(
                vec!["ground".into(), "input".into(), "coupler".into(), "output".into()],
                "double-rocker"
            )]
        );
        // parallelogram: s + l = p + q.
        let c = classes(include_str!("../../../mechanisms/parallelogram.toml"));
        assert!(c.iter().any(|(_, k)| *k == "change point"), "{c:?}");
    }

    #[test]
    fn a_short_ground_makes_a_double_crank() {
        let text =
            "name = \"drag_link\"\n[bodies.ground]\nfixed = true\nmarkers = { A = [0, 0], D = [1, 0] }\n\
            [bodies.a]\nmarkers = { A = [0, 0], B = [0, 3] }\n\
            [bodies.b]\nmarkers = { B = [0, 3], C = [3.4, 2.2] }\n\
            [bodies.c]\nmarkers = { C = [3.4, 2.2], D = [1, 0] }\n\
            [joints.A]\nkind = \"revolute\"\nmarkers = [\"ground.A\", \"a.A\"]\n\
            [joints.B]\nkind = \"revolute\"\nmarkers = [\"a.B\", \"b.B\"]\n\
            [joints.C]\nkind = \"revolute\"\nmarkers = [\"b.C\", \"c.C\"]\n\
            [joints.D]\nkind = \"revolute\"\nmarkers = [\"c.D\", \"ground.D\"]\n";
        let m = load_str("m.toml", text, Format::Toml).unwrap();
        let f = four_bars(&m);
        assert_eq!(f.len(), 1);
        // Lengths computed here: ground 1, a 3, b |(3.4, −0.8)|, c |(2.4, 2.2)|.
        let want = [1.0, 3.0, 3.4f64.hypot(0.8), 2.4f64.hypot(2.2)];
        for (l, w) in f[0].lengths.iter().zip(want) {
            assert!((l - w).abs() < 1e-12);
        }
        assert_eq!(f[0].class, Class::DoubleCrank);
    }
}
