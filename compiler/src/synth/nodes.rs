//! The points a design's parameters move, for either dimension: markers
//! tied by joints (and by constraints that hold them on one point, line or
//! plane) move together, each kept at its drawn offset.

use nalgebra::DMatrix;

use crate::model::MarkerId;
use crate::synth::SynthError;

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

/// A design's parameters, for either dimension: its nodes, each marker's
/// node and the parameters' names (`N` coordinates a node).
#[derive(Clone, Debug)]
pub struct Parameters<const N: usize> {
    nodes: Vec<Node<N>>,
    node_of: Vec<Vec<usize>>,
    names: Vec<String>,
}

impl<const N: usize> Parameters<N> {
    /// The parameters of the nodes [`group`] made.
    pub fn new(nodes: Vec<Node<N>>, node_of: Vec<Vec<usize>>) -> Parameters<N> {
        let names = names(&nodes);
        Parameters {
            nodes,
            node_of,
            names,
        }
    }

    /// The nodes, in parameter order (node `n` is parameters `N·n` to
    /// `N·n + N − 1`).
    pub fn nodes(&self) -> &[Node<N>] {
        &self.nodes
    }

    /// The parameters' names, in order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The index of a parameter by name.
    pub fn index(&self, name: &str) -> Result<usize, SynthError> {
        self.names
            .iter()
            .position(|n| n == name)
            .ok_or_else(|| SynthError::UnknownParameter {
                name: name.to_string(),
                known: self.names.clone(),
            })
    }

    /// The node a marker moves with.
    pub fn node_of(&self, id: MarkerId) -> usize {
        self.node_of[id.body][id.marker]
    }

    /// Every marker's node, body by body.
    pub fn node_table(&self) -> &[Vec<usize>] {
        &self.node_of
    }

    /// The parameters' drawn values.
    pub fn drawn(&self) -> Vec<f64> {
        self.nodes.iter().flat_map(|n| n.at).collect()
    }

    /// Checks `values` (one per parameter, finite) and writes each
    /// marker's position for them through `set(id, k, v)`.
    pub fn place(
        &self,
        values: &[f64],
        drawn: impl Fn(MarkerId) -> [f64; N],
        set: impl FnMut(MarkerId, usize, f64),
    ) -> Result<(), SynthError> {
        if values.len() != self.names.len() {
            return Err(SynthError::WrongLength {
                given: values.len(),
                expected: self.names.len(),
            });
        }
        if let Some(k) = values.iter().position(|v| !v.is_finite()) {
            return Err(SynthError::NotFinite {
                name: self.names[k].clone(),
            });
        }
        place(&self.nodes, values, drawn, set);
        Ok(())
    }
}

/// What [`implicit`] found.
#[derive(Clone, Debug)]
pub struct Implicit {
    /// `dq/dp`, one column per parameter (the minimum-norm one where
    /// freedoms are idle).
    pub dq: DMatrix<f64>,
    /// Smallest over largest singular value of `Φ_q`, the idle freedoms'
    /// left out.
    pub conditioning: f64,
    /// Per parameter, the share of `Φ_p` the poses cannot follow
    /// (relative to the size).
    pub misfit: Vec<f64>,
    /// The idle freedoms: a basis of `Φ_q`'s null space, one column each
    /// (no columns when the equations fix the poses).
    pub idle: DMatrix<f64>,
}

/// The implicit function theorem on a frame's equations, for either
/// dimension: `dq/dp = −Φ_q⁺ Φ_p` with `Φ_q` the equations' Jacobian in
/// the poses (turns scaled by `size`) and `Φ_p` in the parameters.
///
/// Where the equations leave freedoms open, the poses are not functions of
/// the dimensions: an error, unless `idle` allows them — a spatial
/// spherical–spherical link spins about its own axis without moving
/// anything else, and what does not move with such a spin (see
/// [`Implicit::idle`]) still has exact derivatives. `Φ_q` singular
/// otherwise (a dead point) is an error.
pub fn implicit(
    phi_q: &DMatrix<f64>,
    phi_p: &DMatrix<f64>,
    size: f64,
    idle: bool,
) -> Result<Implicit, SynthError> {
    let (rows, unknowns) = (phi_q.nrows(), phi_q.ncols());
    if unknowns == 0 {
        return Ok(Implicit {
            dq: DMatrix::zeros(0, phi_p.ncols()),
            conditioning: 1.0,
            misfit: vec![0.0; phi_p.ncols()],
            idle: DMatrix::zeros(0, 0),
        });
    }
    if rows < unknowns && !idle {
        return Err(SynthError::Underconstrained {
            unknowns,
            equations: rows,
        });
    }
    // Square or tall, so that the SVD's V spans every unknown.
    let mut a = phi_q.clone();
    if rows < unknowns {
        a = a.insert_rows(rows, unknowns - rows, 0.0);
    }
    let svd = a.svd(true, true);
    let hi = svd.singular_values.iter().fold(0.0f64, |m, &s| m.max(s));
    let tol = 1e-9 * hi;
    let open: Vec<usize> = (0..svd.singular_values.len())
        .filter(|&k| svd.singular_values[k] <= tol)
        .collect();
    if !open.is_empty() && !idle {
        return Err(SynthError::Underconstrained {
            unknowns,
            equations: unknowns - open.len(),
        });
    }
    let lo = (svd.singular_values.iter())
        .filter(|&&s| s > tol)
        .fold(f64::INFINITY, |m, &s| m.min(s));
    let conditioning = if hi > 0.0 && lo.is_finite() { lo / hi } else { 0.0 };
    if conditioning < 1e-12 {
        return Err(SynthError::Singular { ratio: conditioning });
    }
    let mut p = phi_p.clone();
    if rows < unknowns {
        p = p.insert_rows(rows, unknowns - rows, 0.0);
    }
    let dq = svd
        .solve(&(-&p), tol)
        .map_err(|_| SynthError::Singular { ratio: conditioning })?;
    let left = phi_q * &dq + phi_p;
    let misfit = (0..phi_p.ncols())
        .map(|k| left.column(k).norm() / size.max(f64::MIN_POSITIVE))
        .collect();
    let v_t = svd.v_t.as_ref().expect("asked for V");
    let mut basis = DMatrix::zeros(unknowns, open.len());
    for (c, &k) in open.iter().enumerate() {
        for j in 0..unknowns {
            basis[(j, c)] = v_t[(k, j)];
        }
    }
    Ok(Implicit {
        dq,
        conditioning,
        misfit,
        idle: basis,
    })
}

/// [`implicit`] for a search's inner loop, which uses `dq` only: a square
/// `Φ_q` well away from singular (its LU's pivots, with full pivoting,
/// within [`CLEAR_OF_SINGULAR`] of each other) is solved by that LU, a
/// tenth of an SVD's work on a four-bar; anything else — a tall or wide
/// `Φ_q`, or pivots that leave any doubt — by [`implicit`] itself, which
/// says exactly how singular it is. `conditioning` is then the pivots'
/// ratio, an estimate of the singular values' (not to be reported).
pub fn implicit_fast(phi_q: &DMatrix<f64>, phi_p: &DMatrix<f64>, size: f64) -> Result<Implicit, SynthError> {
    let unknowns = phi_q.ncols();
    if unknowns == 0 || phi_q.nrows() != unknowns {
        return implicit(phi_q, phi_p, size, false);
    }
    let lu = phi_q.clone().full_piv_lu();
    let pivots = lu.u().diagonal().map(f64::abs);
    let (lo, hi) = (pivots.min(), pivots.max());
    if !(hi > 0.0 && lo >= CLEAR_OF_SINGULAR * hi) {
        return implicit(phi_q, phi_p, size, false);
    }
    let Some(dq) = lu.solve(&(-phi_p)) else {
        return implicit(phi_q, phi_p, size, false);
    };
    let left = phi_q * &dq + phi_p;
    let misfit = (0..phi_p.ncols())
        .map(|k| left.column(k).norm() / size.max(f64::MIN_POSITIVE))
        .collect();
    Ok(Implicit {
        dq,
        conditioning: lo / hi,
        misfit,
        idle: DMatrix::zeros(unknowns, 0),
    })
}

/// The smallest pivot over the largest at which [`implicit_fast`] trusts
/// its LU: far above [`implicit`]'s 1e-12 on singular values, so that a
/// frame anywhere near a dead point is judged by the SVD.
pub const CLEAR_OF_SINGULAR: f64 = 1e-6;
