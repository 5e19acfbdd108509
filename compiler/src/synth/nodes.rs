//! The points a design's parameters move, for either dimension: markers
//! tied by joints (and by constraints that hold them on one point, line or
//! plane) move together, each kept at its drawn offset.

use crate::model::MarkerId;

/// Markers that move together when a parameter changes, each kept at its
/// drawn offset from the node's position — zero for a revolute joint's
/// markers, the drawn offset along the slide for a prismatic joint's.
#[derive(Clone, Debug, PartialEq)]
pub struct Node<const N: usize> {
    /// The joint that names it, or "body.marker" for a free marker.
    pub name: String,
    /// Its drawn position (its first marker's).
    pub at: [f64; N],
    /// Its markers and their drawn offsets from `at`.
    pub markers: Vec<(MarkerId, [f64; N])>,
}

/// The nodes of a mechanism whose markers are drawn at `drawn(id)` (every
/// marker in `markers`, named by `name(id)`), tied by `ties` (a name and
/// two markers, in file order): nodes in order of their first tie, then
/// the free markers. Returns the nodes and each marker's node (body by
/// body, `sizes[b]` markers on body `b`).
pub fn group<const N: usize>(
    sizes: &[usize],
    markers: &[MarkerId],
    drawn: impl Fn(MarkerId) -> [f64; N],
    name: impl Fn(MarkerId) -> String,
    ties: impl Iterator<Item = (String, [MarkerId; 2])>,
) -> (Vec<Node<N>>, Vec<Vec<usize>>) {
    let mut node_of: Vec<Vec<usize>> = sizes.iter().map(|&n| vec![usize::MAX; n]).collect();
    let mut nodes: Vec<Node<N>> = Vec::new();
    let offset = |id: MarkerId, base: [f64; N]| {
        let at = drawn(id);
        std::array::from_fn(|k| at[k] - base[k])
    };
    for (tie, [a, b]) in ties {
        let keep = match (node_of[a.body][a.marker], node_of[b.body][b.marker]) {
            (usize::MAX, usize::MAX) => {
                nodes.push(Node {
                    name: tie,
                    at: drawn(a),
                    markers: Vec::new(),
                });
                nodes.len() - 1
            }
            (usize::MAX, n) | (n, usize::MAX) => n,
            (x, y) => x.min(y),
        };
        for id in [a, b] {
            let old = node_of[id.body][id.marker];
            if old == keep {
                continue;
            }
            // Merging two nodes: every marker of the later one moves over.
            let members: Vec<MarkerId> = if old == usize::MAX {
                vec![id]
            } else {
                std::mem::take(&mut nodes[old].markers)
                    .into_iter()
                    .map(|(k, _)| k)
                    .collect()
            };
            for k in members {
                node_of[k.body][k.marker] = keep;
                let base = nodes[keep].at;
                nodes[keep].markers.push((k, offset(k, base)));
            }
        }
    }
    for &id in markers {
        if node_of[id.body][id.marker] == usize::MAX {
            node_of[id.body][id.marker] = nodes.len();
            nodes.push(Node {
                name: name(id),
                at: drawn(id),
                markers: vec![(id, [0.0; N])],
            });
        }
    }
    // Nodes emptied by merges are dropped, the indices renumbered.
    let mut renumber = vec![usize::MAX; nodes.len()];
    let mut kept = Vec::new();
    for (i, n) in nodes.into_iter().enumerate() {
        if !n.markers.is_empty() {
            renumber[i] = kept.len();
            kept.push(n);
        }
    }
    for row in &mut node_of {
        for n in row.iter_mut() {
            *n = renumber[*n];
        }
    }
    (kept, node_of)
}

/// The parameters' names: `NAME.x`, `NAME.y` (and `NAME.z`) per node.
pub fn names<const N: usize>(nodes: &[Node<N>]) -> Vec<String> {
    let axes = ["x", "y", "z"];
    nodes
        .iter()
        .flat_map(|n| (0..N).map(move |k| format!("{}.{}", n.name, axes[k])))
        .collect()
}

/// Each marker's position for parameter `values` (`N` per node): a
/// coordinate left as drawn keeps the drawn marker exactly (node + offset
/// may differ from it in the last bit). `set(id, k, v)` writes one.
pub fn place<const N: usize>(
    nodes: &[Node<N>],
    values: &[f64],
    drawn: impl Fn(MarkerId) -> [f64; N],
    mut set: impl FnMut(MarkerId, usize, f64),
) {
    for (n, node) in nodes.iter().enumerate() {
        for (id, off) in &node.markers {
            let was = drawn(*id);
            for k in 0..N {
                let v = values[N * n + k];
                set(*id, k, if v != node.at[k] { v + off[k] } else { was[k] });
            }
        }
    }
}
