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

use crate::model::{JointKind, Mechanism};

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

impl FourBar {
    /// The same loop (bodies and joints) measured in `m`, a drawing of the
    /// same mechanism with other dimensions (a synthesis candidate); `None`
    /// if a link has no length there.
    pub fn in_drawing(&self, m: &Mechanism) -> Option<FourBar> {
        let ground = m.bodies.iter().position(|b| b.fixed);
        let node = |b: usize| if m.bodies[b].fixed { ground.unwrap_or(b) } else { b };
        loop_of(m, self.bodies, self.joints, &node, m.size())
    }

    /// How far link `link` (1 or 3, a link beside the frame) is from
    /// turning fully, by the lengths alone: the smaller of p + q − (s + l)
    /// and the slack by which it or the frame is the shortest link.
    /// Negative when it cannot turn fully, however finely it is sampled
    /// (just past a change point its stops are a fraction of a degree
    /// apart).
    pub fn turning_margin(&self, link: usize) -> f64 {
        let l = self.lengths;
        let slack = |k: usize| {
            (0..4)
                .filter(|&j| j != k)
                .map(|j| l[j])
                .fold(f64::INFINITY, f64::min)
                - l[k]
        };
        (self.sums.1 - self.sums.0).min(slack(link).max(slack(0)))
    }
}

/// Every four-bar loop of `m`, in a deterministic order (by their joints'
/// file order).
pub fn four_bars(m: &Mechanism) -> Vec<FourBar> {
    four_bars_counted(m).0
}

/// [`four_bars`] and the work its search did: the paths of two joints it
/// walked plus the pairs of them it compared. On a mechanism whose bodies
/// each carry a bounded number of joints, except for the ground (a chain,
/// a tree of loops), that work grows linearly with the joints; the tests
/// count it.
///
/// Each loop is found once, from its highest body in an order by number of
/// joints (then by file order): from that body `v`, every path v–u–w
/// through two lower bodies is filed under its end `w`, and two paths to
/// one `w` through different bodies `u` close a loop. A body with many
/// joints (the ground) is highest, so the paths never fan out from it
/// twice: the search is the classic degree-ordered one for 4-cycles
/// (Chiba and Nishizeki 1985), O(J·a) for J joints and a graph of
/// arboricity a, where pairing every two neighbours of the ground was
/// quadratic in a long chain.
pub fn four_bars_counted(m: &Mechanism) -> (Vec<FourBar>, usize) {
    // Every fixed body is the one ground node.
    let ground = m.bodies.iter().position(|b| b.fixed);
    let node = |b: usize| if m.bodies[b].fixed { ground.unwrap_or(b) } else { b };
    let n = m.bodies.len();
    let mut adjacent: Vec<Vec<(usize, usize)>> = vec![Vec::new(); n];
    for (k, j) in m.joints.iter().enumerate() {
        if j.kind != JointKind::Revolute {
            continue;
        }
        let [a, b] = j.markers;
        let (na, nb) = (node(a.body), node(b.body));
        if na != nb {
            adjacent[na].push((nb, k));
            adjacent[nb].push((na, k));
        }
    }
    // rank[b]: b's place in the order by (number of joints, file order).
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by_key(|&b| (adjacent[b].len(), b));
    let mut rank = vec![0; n];
    for (r, &b) in order.iter().enumerate() {
        rank[b] = r;
    }
    let size = m.size();
    let mut work = 0;
    let mut out = Vec::new();
    // paths[w]: the paths v –j1– u –j2– w from the current v, as (u, j1, j2).
    let mut paths: Vec<Vec<(usize, usize, usize)>> = vec![Vec::new(); n];
    let mut ends = Vec::new();
    for v in 0..n {
        for &(u, j1) in &adjacent[v] {
            if rank[u] >= rank[v] {
                continue;
            }
            for &(w, j2) in &adjacent[u] {
                // w == v only by a second joint between u and v: rank[v]
                // is not below itself.
                if rank[w] >= rank[v] {
                    continue;
                }
                work += 1;
                if paths[w].is_empty() {
                    ends.push(w);
                }
                paths[w].push((u, j1, j2));
            }
        }
        for w in ends.drain(..) {
            let through = std::mem::take(&mut paths[w]);
            for (x, &(u1, ja, jb)) in through.iter().enumerate() {
                for &(u2, jd, jc) in &through[x + 1..] {
                    work += 1;
                    if u1 == u2 {
                        continue;
                    }
                    // Around the loop: v –ja– u1 –jb– w –jc– u2 –jd– v,
                    // four bodies and four joints, all different.
                    let (b, j) = canonical([v, u1, w, u2], [ja, jb, jc, jd]);
                    if let Some(f) = loop_of(m, b, j, &node, size) {
                        out.push(f);
                    }
                }
            }
            // Keep the allocation for the next v.
            paths[w] = through;
            paths[w].clear();
        }
    }
    out.sort_by_key(|f| {
        let mut k = f.joints;
        k.sort_unstable();
        k
    });
    (out, work)
}

/// The loop of bodies `b` and joints `j` (`j[k]` between `b[k]` and
/// `b[k + 1]`) walked from its first body in file order, leaving it by the
/// earlier of its two joints: one way of writing each loop, so that which
/// link [`loop_of`] lists after the frame does not depend on how the search
/// met the loop.
fn canonical(b: [usize; 4], j: [usize; 4]) -> ([usize; 4], [usize; 4]) {
    let first = (0..4).min_by_key(|&k| b[k]).expect("four bodies");
    // The two joints at b[first]: j[first] forward, j[first - 1] back.
    let back = (first + 3) % 4;
    if j[first] < j[back] {
        (
            std::array::from_fn(|k| b[(first + k) % 4]),
            std::array::from_fn(|k| j[(first + k) % 4]),
        )
    } else {
        // Walk backward: bodies first, first−1, …; joints back, back−1, ….
        (
            std::array::from_fn(|k| b[(first + 4 - k) % 4]),
            std::array::from_fn(|k| j[(back + 4 - k) % 4]),
        )
    }
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
    use crate::conflict::load_str;
    use crate::model::Format;

    /// The bundled four-bar with its four joints moved to `a`, `b`, `c`,
    /// `d` (A and D on the ground).
    fn fourbar_at(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> Mechanism {
        let text = include_str!("../../../../mechanisms/fourbar.toml");
        let p = |v: [f64; 2]| format!("[{:?}, {:?}]", v[0], v[1]);
        let text = text
            .replace(
                "{ A = [0, 0], D = [4, 0] }",
                &format!("{{ A = {}, D = {} }}", p(a), p(d)),
            )
            .replace(
                "{ A = [0, 0], B = [1, 1] }",
                &format!("{{ A = {}, B = {} }}", p(a), p(b)),
            )
            .replace(
                "B = [1, 1], C = [4.5, 2.5]",
                &format!("B = {}, C = {}", p(b), p(c)),
            )
            .replace(
                "{ C = [4.5, 2.5], D = [4, 0] }",
                &format!("{{ C = {}, D = {} }}", p(c), p(d)),
            );
        load_str("m.toml", &text, Format::Toml).unwrap()
    }

    /// The turning margin against the lengths computed here: Grashof's
    /// slack where the crank is the shortest, the frame's where the frame
    /// is, and negative both just past a change point and where the
    /// coupler is the shortest link.
    #[test]
    fn the_turning_margin_says_whether_the_crank_turns() {
        let d = |u: [f64; 2], v: [f64; 2]| (u[0] - v[0]).hypot(u[1] - v[1]);
        let margin = |a, b, c, dd| {
            let m = fourbar_at(a, b, c, dd);
            let f = four_bars(&m).remove(0);
            assert_eq!(f.joints[0], 0, "joint A, the input's, starts the loop");
            (f.turning_margin(1), [d(a, dd), d(a, b), d(b, c), d(c, dd)])
        };
        // The bundled crank-rocker: p + q − (s + l).
        let (m, [g, a, b, c]) = margin([0.0, 0.0], [1.0, 1.0], [4.5, 2.5], [4.0, 0.0]);
        assert!(
            (m - ((b + c) - (a + g)).min(b.min(c).min(g) - a)).abs() < 1e-12,
            "{m}"
        );
        assert!(m > 0.0);
        // 6.6e-6 past its change point (a synthesised mkh_18 linkage).
        let (m, [g, a, b, c]) = margin(
            [0.88798882428, 0.12965620756],
            [1.83279395081, 0.76590906965],
            [1.82529464191, 1.98817236498],
            [-0.20150880004, 1.75524107588],
        );
        assert!(
            (m - ((g + b) - (a + c))).abs() < 1e-12 && m < 0.0 && m > -1e-5,
            "{m}"
        );
        // A double-crank: the frame (1) is the shortest.
        let (m, _) = margin([0.0, 0.0], [0.0, 3.0], [3.3223, 1.8991], [1.0, 0.0]);
        assert!(m > 0.0, "{m}");
        // Grashof, but the coupler (1) is the shortest: a double-rocker.
        let (m, _) = margin([0.0, 0.0], [1.5, 2.0], [2.5, 2.0], [4.0, 0.0]);
        assert!(m < 0.0, "{m}");
    }

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

    /// The search this module used to make, kept as the reference: every
    /// two joints of a body `a` to bodies b and c, then every body d
    /// joined to both. Quadratic in the joints of the busiest body, and
    /// obviously complete.
    fn four_bars_by_pairs(m: &Mechanism) -> Vec<FourBar> {
        let ground = m.bodies.iter().position(|b| b.fixed);
        let node = |b: usize| if m.bodies[b].fixed { ground.unwrap_or(b) } else { b };
        let mut adjacent: Vec<Vec<(usize, usize)>> = vec![Vec::new(); m.bodies.len()];
        for (k, j) in m.joints.iter().enumerate() {
            let [a, b] = j.markers;
            let (na, nb) = (node(a.body), node(b.body));
            if j.kind == JointKind::Revolute && na != nb {
                adjacent[na].push((nb, k));
                adjacent[nb].push((na, k));
            }
        }
        let mut seen = std::collections::BTreeSet::new();
        let mut out = Vec::new();
        for a in 0..m.bodies.len() {
            for (x, &(b, j1)) in adjacent[a].iter().enumerate() {
                for &(c, j2) in &adjacent[a][x + 1..] {
                    if b == c {
                        continue;
                    }
                    for &(d, j3) in &adjacent[b] {
                        if [a, b, c].contains(&d) {
                            continue;
                        }
                        for &(e, j4) in &adjacent[c] {
                            let mut key = [j1, j2, j3, j4];
                            key.sort_unstable();
                            if e != d || !seen.insert(key) {
                                continue;
                            }
                            let f = loop_of(m, [a, b, d, c], [j1, j3, j4, j2], &node, m.size());
                            out.extend(f);
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

    #[test]
    fn every_bundled_mechanism_has_the_loops_of_the_pairwise_search() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../mechanisms");
        let mut files = 0;
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "toml") {
                let text = std::fs::read_to_string(&path).unwrap();
                let Ok(m) = load_str("m.toml", &text, Format::Toml) else {
                    continue;
                };
                assert_eq!(four_bars(&m), four_bars_by_pairs(&m), "{}", path.display());
                files += 1;
            }
        }
        assert!(files >= 20, "{files} bundled planar files read");
    }

    /// Random multigraphs: bodies (some fixed), revolute joints between
    /// random pairs (some doubled, some on two fixed bodies), drawn open
    /// (the search does not look at whether joints hold).
    #[test]
    fn random_graphs_have_the_loops_of_the_pairwise_search() {
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = |n: u64| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed % n
        };
        let mut loops = 0;
        for case in 0..60 {
            let bodies = 4 + next(9) as usize;
            let joints = bodies + next(2 * bodies as u64) as usize;
            let mut markers = vec![vec!["M = [0.5, 0.25]".to_string()]; bodies];
            let mut text = format!("name = \"g{case}\"\n");
            let mut joint_text = String::new();
            for k in 0..joints {
                let a = next(bodies as u64) as usize;
                let b = (a + 1 + next(bodies as u64 - 1) as usize) % bodies;
                for (body, d) in [(a, 0), (b, 1)] {
                    let (x, y) = (next(1000) as f64 / 100.0, next(1000) as f64 / 100.0 + d as f64);
                    markers[body].push(format!("J{k} = [{x:?}, {y:?}]"));
                }
                joint_text += &format!(
                    "[joints.J{k}]\nkind = \"revolute\"\nmarkers = [\"b{a}.J{k}\", \"b{b}.J{k}\"]\n"
                );
            }
            for (b, list) in markers.iter().enumerate() {
                let fixed = b == 0 || (b == 3 && case % 3 == 0);
                text += &format!(
                    "[bodies.b{b}]\nfixed = {fixed}\nmarkers = {{ {} }}\n",
                    list.join(", ")
                );
            }
            text += &joint_text;
            let m = crate::model::load_str_drawn("g.toml", &text, Format::Toml)
                .unwrap_or_else(|e| panic!("{e}\n{text}"))
                .mechanism;
            let want = four_bars_by_pairs(&m);
            loops += want.len();
            assert_eq!(four_bars(&m), want, "{text}");
        }
        assert!(loops > 100, "{loops} loops over the cases");
    }

    #[test]
    fn the_bundled_four_bars_are_what_their_headers_say() {
        // fourbar: s + l = √2 + 4 < p + q, the crank shortest.
        let c = classes(include_str!("../../../../mechanisms/fourbar.toml"));
        assert_eq!(c.len(), 1);
        assert_eq!(c[0].1, "crank-rocker");
        assert_eq!(c[0].0[0], "ground");
        // rocker_rocker: s + l = 7 > p + q = 5.5.
        let c = classes(include_str!("../../../../mechanisms/rocker_rocker.toml"));
        assert_eq!(
            c,
            [(
                vec!["ground".into(), "input".into(), "coupler".into(), "output".into()],
                "double-rocker"
            )]
        );
        // parallelogram: s + l = p + q.
        let c = classes(include_str!("../../../../mechanisms/parallelogram.toml"));
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
