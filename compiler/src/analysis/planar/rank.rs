//! Mobility by the rank of the constraint Jacobian at the drawn pose, and
//! what it says that Grübler's count cannot: which equations are redundant
//! (Brunkhart §2.1.3–2.1.4: non-generic mechanisms) and which bodies can
//! move on their own (idle degrees of freedom).
//!
//! The Jacobian is sparse — each equation's rows touch the three columns of
//! at most two bodies — so its rank is found by Gaussian elimination on
//! sparse rows taken in file order (`Echelon`): a row that the rows
//! before it already span is dependent, which is exactly "redundant =
//! dependent on the joints before them in the file", and each row costs
//! only the eliminations its own columns call for. On a chain of loops that
//! is a bounded number per row, so the whole rank is linear in the
//! mechanism's size (a dense SVD of every prefix of the Jacobian was
//! quartic). An idle body's freedom is the rank of its own three columns,
//! from the few rows that touch it.

use dofplan_runtime::numeric::{rank, Equations};
use dofplan_runtime::planar::cluster::{Param, System};
use dofplan_runtime::planar::Pose;
use nalgebra::{DMatrix, DVector};

use super::Progress;
use crate::model::planar::equations::equations;
use crate::model::planar::gears::{Gear, GearKind};
use crate::model::Mechanism;
use crate::plan::ClusterRow;

/// Relative cut-off for ranks at the drawn pose: a row is dependent when
/// what is left of it after elimination is below this share of the
/// Jacobian's largest entry (as singular values below this share of the
/// largest one are zero for the SVD of a body's columns).
const RANK_CUTOFF: f64 = 1e-9;

/// Mobility from the Jacobian.
#[derive(Clone, Debug, PartialEq)]
pub struct RankMobility {
    /// Unknowns: three per mobile body.
    pub unknowns: usize,
    /// Scalar equations of joints and constraints (inputs left out).
    pub equations: usize,
    /// Rank of their Jacobian at the drawn pose.
    pub rank: usize,
    /// Degrees of freedom: unknowns − rank.
    pub dof: i64,
    /// Equations that add no rank, by origin, with how many of their rows
    /// are dependent on the ones before them (file order).
    pub redundant: Vec<(String, usize)>,
    /// The same rows by (origin, primitive, rows), an entry per primitive.
    pub redundant_rows: Vec<(String, String, usize)>,
    /// Bodies that can move while every other body stays put, with how
    /// many freedoms they have on their own.
    pub idle: Vec<(String, usize)>,
    /// Row eliminations the rank took (its work: linear in the size of a
    /// chain of loops).
    pub eliminations: usize,
}

/// One row of the Jacobian: (column, value) of its nonzero entries.
pub(crate) type SparseRow = Vec<(usize, f64)>;

/// Mobility of the mechanism with its inputs released, by Jacobian rank.
pub fn rank_mobility(m: &Mechanism) -> RankMobility {
    rank_mobility_with(m, &mut |_| {})
}

/// [`rank_mobility`], reporting how far it is to `progress` (rows
/// eliminated out of all rows).
pub fn rank_mobility_with(m: &Mechanism, progress: &mut dyn FnMut(Progress)) -> RankMobility {
    let mut free = m.clone();
    free.inputs.clear();
    rank_of(&free, progress)
}

/// The freedoms no input drives: unknowns − the Jacobian's rank with the
/// inputs' equations added (an idle body's, or a chain's left free).
pub fn idle_freedoms(m: &Mechanism) -> i64 {
    rank_of(m, &mut |_| {}).dof
}

/// The rank analysis of `free`'s equations as they are (inputs included if
/// it has any).
fn rank_of(free: &Mechanism, progress: &mut dyn FnMut(Progress)) -> RankMobility {
    let size = free.size();
    // Three columns per mobile body, in body order (pure Newton's columns).
    let mut column = vec![None; free.bodies.len()];
    let mut unknowns = 0;
    for (b, body) in free.bodies.iter().enumerate() {
        if !body.fixed {
            column[b] = Some(unknowns);
            unknowns += 3;
        }
    }
    // Every equation on a mobile body (one between fixed bodies constrains
    // nothing), in file order, with its rows.
    // Inputs at 0: the drawn pose (their values do not enter the rows'
    // derivatives, only the residuals).
    let zeros = vec![0.0; free.inputs.len()];
    let groups: Vec<(String, &'static str, Vec<SparseRow>)> = equations(free)
        .into_iter()
        .filter(|s| s.eq.bodies().iter().any(|&b| column[b].is_some()))
        .map(|s| {
            (
                s.origin,
                s.eq.kind_name(),
                jacobian_rows(&s.eq.row(), &column, size, &zeros),
            )
        })
        .collect();
    let mut groups = groups;
    groups.extend(free.gears.iter().map(|g| {
        (
            format!("joint {}", g.name),
            g.kind.name(),
            vec![gear_row(g, &column, size)],
        )
    }));
    let total: usize = groups.iter().map(|(_, _, rows)| rows.len()).sum();
    let largest = groups
        .iter()
        .flat_map(|(_, _, rows)| rows.iter().flatten())
        .map(|&(_, v)| v.abs())
        .fold(0.0, f64::max);

    // Greedy in file order: a group whose rows do not all raise the rank of
    // the rows before it has dependent rows.
    let mut echelon = Echelon::new(unknowns, RANK_CUTOFF * largest);
    let mut redundant: Vec<(String, usize)> = Vec::new();
    let mut redundant_rows: Vec<(String, String, usize)> = Vec::new();
    let mut done = 0;
    for (origin, kind, rows) in &groups {
        let dependent = rows.iter().filter(|row| !echelon.add(row)).count();
        if dependent > 0 {
            redundant.push((origin.clone(), dependent));
            redundant_rows.push((origin.clone(), kind.to_string(), dependent));
        }
        done += rows.len();
        progress(Progress {
            stage: "rank",
            done,
            total,
        });
    }

    // Each body's own columns, from the rows that touch it.
    let mut own: Vec<Vec<[f64; 3]>> = vec![Vec::new(); free.bodies.len()];
    for row in groups.iter().flat_map(|(_, _, rows)| rows) {
        let mut touched: Vec<usize> = row.iter().map(|&(c, _)| c / 3).collect();
        touched.dedup();
        for k in touched {
            let mut entries = [0.0; 3];
            for &(c, v) in row.iter().filter(|&&(c, _)| c / 3 == k) {
                entries[c % 3] += v;
            }
            own[k].push(entries);
        }
    }
    let idle = free
        .bodies
        .iter()
        .zip(&column)
        .filter_map(|(body, c)| {
            let k = (*c)? / 3;
            let rows = &own[k];
            let block = DMatrix::from_fn(rows.len(), 3, |i, j| rows[i][j]);
            let alone = 3 - rank(&block, RANK_CUTOFF);
            (alone > 0).then(|| (body.name.clone(), alone))
        })
        .collect();
    RankMobility {
        unknowns,
        equations: total,
        rank: echelon.rank(),
        dof: unknowns as i64 - echelon.rank() as i64,
        redundant,
        redundant_rows,
        idle,
        eliminations: echelon.eliminations,
    }
}

/// The Jacobian rows of one equation at the drawn pose (every body at the
/// identity: markers are drawn in world coordinates), with respect to the
/// free unknowns of its mobile bodies (`column`: each body's first
/// column). Evaluated by the runtime's cluster system, so the derivatives
/// are the ones pure Newton and the numeric clusters use.
fn jacobian_rows(row: &ClusterRow, column: &[Option<usize>], size: f64, inputs: &[f64]) -> Vec<SparseRow> {
    // The equation on a system of its own two bodies: local 0 and 1.
    let (a, b) = match *row {
        ClusterRow::Coincident { a, b, .. }
        | ClusterRow::InLine { a, b, .. }
        | ClusterRow::OnCircle { a, b, .. }
        | ClusterRow::Parallel { a, b, .. } => (a, b),
    };
    let bodies: Vec<usize> = if a == b { vec![a] } else { vec![a, b] };
    let local = |g: usize| usize::from(g != a);
    let local_row = match *row {
        ClusterRow::Coincident { a, la, slide, b, lb } => ClusterRow::Coincident {
            a: local(a),
            la,
            slide,
            b: local(b),
            lb,
        },
        ClusterRow::InLine { a, la, dir, b, lb } => ClusterRow::InLine {
            a: local(a),
            la,
            dir,
            b: local(b),
            lb,
        },
        ClusterRow::OnCircle { a, la, r, b, lb } => ClusterRow::OnCircle {
            a: local(a),
            la,
            r,
            b: local(b),
            lb,
        },
        ClusterRow::Parallel { a, b, input } => ClusterRow::Parallel {
            a: local(a),
            b: local(b),
            input,
        },
    };
    let params: Vec<Param> = (0..bodies.len())
        .filter(|&k| column[bodies[k]].is_some())
        .map(|body| Param::Free { body })
        .collect();
    let mut poses = vec![Pose::IDENTITY; bodies.len()];
    let rows = [local_row];
    let (mut system, x) = System::new(&mut poses, &params, &rows, inputs, size);
    let (n, count) = (system.unknowns(), system.equations());
    let mut r = DVector::zeros(count);
    let mut j = DMatrix::zeros(count, n);
    system.eval(&x, &mut r, Some(&mut j));
    (0..count)
        .map(|i| {
            params
                .iter()
                .enumerate()
                .flat_map(|(q, p)| {
                    let first = column[bodies[p.body()]].expect("a mobile body");
                    (0..3).map(move |k| (first + k, 3 * q + k))
                })
                .map(|(c, local)| (c, j[(i, local)]))
                .filter(|&(_, v)| v != 0.0)
                .collect()
        })
        .collect()
}

/// The Jacobian row of a gear pair or rack at the drawn pose, in the
/// columns of pure Newton (x, y, size·angle per mobile body): for gears
/// `θb − θc − ratio·(θa − θc)`, for a rack the slide of its marker along
/// the carrier's direction less `ratio·(θpinion − θc)`, both scaled as
/// the cluster rows are (lengths).
fn gear_row(g: &Gear, column: &[Option<usize>], size: f64) -> SparseRow {
    let mut row = SparseRow::new();
    let mut put = |body: Option<usize>, k: usize, v: f64| {
        if let Some(first) = body.and_then(|b| column[b]) {
            if v != 0.0 {
                row.push((first + k, v));
            }
        }
    };
    let [a, b] = g.bodies;
    let ratio = g.ratio();
    match g.kind {
        GearKind::Gear { .. } => {
            put(Some(b), 2, 1.0);
            put(Some(a), 2, -ratio);
            put(g.carrier, 2, ratio - 1.0);
        }
        GearKind::RackPinion { dir, .. } => {
            // The rack's marker against the carrier's point under it; a
            // body's point P moves by δθ·perp(P) when it turns at the
            // identity pose.
            let p = g.centres[1];
            let turn = (dir[1] * p[0] - dir[0] * p[1]) / size;
            put(Some(b), 0, dir[0]);
            put(Some(b), 1, dir[1]);
            put(Some(b), 2, turn);
            put(g.carrier, 0, -dir[0]);
            put(g.carrier, 1, -dir[1]);
            put(g.carrier, 2, -turn + ratio / size);
            put(Some(a), 2, -ratio / size);
        }
    }
    row.sort_by_key(|e| e.0);
    row
}

/// Rows in row echelon form, added one at a time: Gaussian elimination on
/// sparse rows.
///
/// Each kept row has a pivot column (its largest entry, so eliminating with
/// it never more than doubles an entry) and is zero in the pivot columns of
/// the rows kept before it. A new row is reduced by the kept rows whose
/// pivot columns it has, oldest first (a kept row only brings in pivot
/// columns of younger rows, so a heap of row numbers orders the work); what
/// is left is either a new kept row or, below the tolerance, a dependent
/// row.
pub(crate) struct Echelon {
    /// Kept rows (pivot entry included).
    rows: Vec<SparseRow>,
    /// Each kept row's pivot column and value.
    pivots: Vec<(usize, f64)>,
    /// Per column: the kept row pivoting on it.
    pivot_row: Vec<Option<usize>>,
    /// The row being reduced, dense, and its nonzero columns.
    work: Vec<f64>,
    pattern: Vec<usize>,
    in_pattern: Vec<bool>,
    /// Kept rows still to eliminate with, smallest first.
    queue: std::collections::BinaryHeap<std::cmp::Reverse<usize>>,
    queued: Vec<bool>,
    tolerance: f64,
    eliminations: usize,
}

impl Echelon {
    pub(crate) fn new(columns: usize, tolerance: f64) -> Echelon {
        Echelon {
            rows: Vec::new(),
            pivots: Vec::new(),
            pivot_row: vec![None; columns],
            work: vec![0.0; columns],
            pattern: Vec::new(),
            in_pattern: vec![false; columns],
            queue: Default::default(),
            queued: Vec::new(),
            tolerance,
            eliminations: 0,
        }
    }

    pub(crate) fn rank(&self) -> usize {
        self.rows.len()
    }

    /// Brings column `c` into the pattern of the row being reduced, and its
    /// kept row into the queue.
    fn touch(&mut self, c: usize) {
        if !self.in_pattern[c] {
            self.in_pattern[c] = true;
            self.pattern.push(c);
            if let Some(k) = self.pivot_row[c] {
                if !self.queued[k] {
                    self.queued[k] = true;
                    self.queue.push(std::cmp::Reverse(k));
                }
            }
        }
    }

    /// Adds a row: true if it raises the rank, false if the rows before it
    /// span it (to the tolerance).
    pub(crate) fn add(&mut self, row: &SparseRow) -> bool {
        for &(c, v) in row {
            self.touch(c);
            self.work[c] += v;
        }
        while let Some(std::cmp::Reverse(k)) = self.queue.pop() {
            self.queued[k] = false;
            let (pivot, value) = self.pivots[k];
            let factor = self.work[pivot] / value;
            if factor != 0.0 {
                for i in 0..self.rows[k].len() {
                    let (c, v) = self.rows[k][i];
                    self.touch(c);
                    self.work[c] -= factor * v;
                }
                self.eliminations += 1;
            }
            // Exactly zero, as the kept rows after it assume.
            self.work[pivot] = 0.0;
        }
        let mut best: Option<(usize, f64)> = None;
        for &c in &self.pattern {
            let v = self.work[c].abs();
            if v > self.tolerance && best.is_none_or(|(_, b)| v > b) {
                best = Some((c, v));
            }
        }
        let kept = best.map(|(pivot, _)| {
            let row: SparseRow = self
                .pattern
                .iter()
                .map(|&c| (c, self.work[c]))
                .filter(|&(_, v)| v != 0.0)
                .collect();
            self.pivot_row[pivot] = Some(self.rows.len());
            self.pivots.push((pivot, self.work[pivot]));
            self.rows.push(row);
            self.queued.push(false);
        });
        for &c in &self.pattern {
            self.work[c] = 0.0;
            self.in_pattern[c] = false;
        }
        self.pattern.clear();
        kept.is_some()
    }
}
