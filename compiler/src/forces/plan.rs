//! The plan for the force unknowns, made once from the structure of a
//! mechanism's equilibrium equations: which joint components and input
//! forces each body's equations involve never changes from frame to
//! frame, only the numbers do. A perfect matching of equations to
//! unknowns and the strongly connected components of what each matched
//! equation needs (the block triangular form) give small blocks solved in
//! order, each a dense solve of its own size, each passing its unknowns
//! on to the later ones: the force counterpart of contracting a linkage
//! dyad by dyad (a four-bar: the coupler and rocker's six equations in
//! the three joints they share, then the crank's three). A mechanism whose
//! equations are not square and regular as drawn (redundant joints, a
//! freedom no input holds) keeps the least-squares solve of every frame
//! (`least_norm`), which is what names the joints whose share is
//! not fixed.

use nalgebra::{DMatrix, DVector};

use super::Solved;

/// Equilibrium equations in sparse columns: one column per unknown (a
/// joint's reaction component, an input's force), its entries the
/// moving-body rows it enters; `ground` the same unknowns' share on the
/// fixed bodies (rows 0.. of the force and the moment there).
#[derive(Clone, Debug, Default)]
pub(crate) struct System {
    /// Equations (3 per moving body in the plane, 6 in space).
    pub rows: usize,
    /// Per unknown: (row, coefficient).
    pub columns: Vec<Vec<(usize, f64)>>,
    /// Per unknown: (ground row, coefficient).
    pub ground: Vec<Vec<(usize, f64)>>,
}

impl System {
    /// A system of `rows` equations and `cols` unknowns, no entries yet.
    pub fn new(rows: usize, cols: usize) -> System {
        System {
            rows,
            columns: vec![Vec::new(); cols],
            ground: vec![Vec::new(); cols],
        }
    }

    /// The equations as a dense matrix.
    fn dense(&self) -> DMatrix<f64> {
        let mut a = DMatrix::zeros(self.rows, self.columns.len());
        for (c, column) in self.columns.iter().enumerate() {
            for &(r, v) in column {
                a[(r, c)] += v;
            }
        }
        a
    }

    /// `sum over unknowns of ground column × x`: what they put on the
    /// ground, `n` components.
    pub fn on_ground(&self, x: &[f64], n: usize) -> Vec<f64> {
        let mut out = vec![0.0; n];
        for (column, xc) in self.ground.iter().zip(x) {
            for &(r, v) in column {
                out[r] += v * xc;
            }
        }
        out
    }
}

/// One block of the plan: equations and the unknowns they fix together.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Block {
    /// The equations (rows).
    pub rows: Vec<usize>,
    /// The unknowns (columns), as many.
    pub cols: Vec<usize>,
}

/// How a mechanism's force unknowns are solved each frame.
#[derive(Clone, Debug, PartialEq)]
pub enum ForcePlan {
    /// Square and regular as drawn: these blocks, in order, with (planar)
    /// each body's moment equation taken about `about[body]`, a local
    /// point (empty: about the world origin).
    Blocks {
        /// The blocks, in order.
        blocks: Vec<Block>,
        /// Per body, the local point its moment equation is about.
        about: Vec<[f64; 2]>,
    },
    /// Not square, or singular as drawn: least squares each frame, and
    /// why.
    LeastSquares(&'static str),
}

impl ForcePlan {
    /// The plan for `system`, the equations at the drawn pose.
    pub(crate) fn new(system: &System) -> ForcePlan {
        let (rows, cols) = (system.rows, system.columns.len());
        if rows < cols {
            return ForcePlan::LeastSquares("more reaction unknowns than equations: redundant joints");
        }
        if rows > cols {
            return ForcePlan::LeastSquares("more equations than unknowns: a freedom no input holds");
        }
        let Some(matched) = matching(system) else {
            return ForcePlan::LeastSquares("no equation for some unknown: redundant joints");
        };
        let blocks = blocks(system, &matched);
        let plan = ForcePlan::Blocks {
            blocks,
            about: Vec::new(),
        };
        // Structure is not enough: the drawn numbers must be regular too
        // (two pins on one line, a joint's share no equation fixes).
        let probe = vec![1.0; rows];
        match plan.by_blocks(system, &probe) {
            Some(_) => plan,
            None => ForcePlan::LeastSquares("singular as drawn: redundant joints"),
        }
    }

    /// The sizes of `system`'s blocks from its structure alone (no look
    /// at its numbers), in the order they would be solved; `None` where
    /// it is not square or some unknown has no equation.
    pub(crate) fn structural_sizes(system: &System) -> Option<Vec<usize>> {
        if system.rows != system.columns.len() {
            return None;
        }
        let matched = matching(system)?;
        Some(blocks(system, &matched).iter().map(|b| b.cols.len()).collect())
    }

    /// The plan with each body's moment equation about `about[body]` (a
    /// local point), as the system it was made from takes them.
    pub(crate) fn with_about(self, about: Vec<[f64; 2]>) -> ForcePlan {
        match self {
            ForcePlan::Blocks { blocks, .. } => ForcePlan::Blocks { blocks, about },
            other => other,
        }
    }

    /// Per body, the local point its moment equation is about (empty:
    /// the world origin; and for least squares).
    pub fn about(&self) -> &[[f64; 2]] {
        match self {
            ForcePlan::Blocks { about, .. } => about,
            ForcePlan::LeastSquares(_) => &[],
        }
    }

    /// The sizes of the blocks, in the order they are solved (empty for
    /// least squares).
    pub fn block_sizes(&self) -> Vec<usize> {
        self.blocks().iter().map(|b| b.cols.len()).collect()
    }

    /// The blocks, in the order they are solved (none for least squares).
    pub fn blocks(&self) -> &[Block] {
        match self {
            ForcePlan::Blocks { blocks, .. } => blocks,
            ForcePlan::LeastSquares(_) => &[],
        }
    }

    /// Solves `system x = -w`: block by block where the plan has blocks
    /// and every block is regular at this frame, else by least squares.
    pub(crate) fn solve(&self, system: &System, w: &[f64]) -> Solved {
        ForcePlan::solved(system, w, self.by_blocks(system, w))
    }

    /// The solution of `system x = -w`: `by_blocks` where the blocks gave
    /// one (how well it holds measured), else least squares.
    pub(crate) fn solved(system: &System, w: &[f64], by_blocks: Option<Vec<f64>>) -> Solved {
        if let Some(x) = by_blocks {
            let residual = residual(system, &x, w);
            return Solved {
                fixed: vec![true; x.len()],
                x: DVector::from_vec(x),
                residual,
            };
        }
        super::least_norm(&system.dense(), &DVector::from_column_slice(w))
    }

    /// The block solve; `None` where a block is singular at this frame (a
    /// dead point, a toggle) or the plan has no blocks.
    fn by_blocks(&self, system: &System, w: &[f64]) -> Option<Vec<f64>> {
        let ForcePlan::Blocks { blocks, .. } = self else {
            return None;
        };
        let mut rhs: Vec<f64> = w.iter().map(|v| -v).collect();
        let mut x = vec![0.0; system.columns.len()];
        let mut local = vec![usize::MAX; system.rows];
        for block in blocks {
            let k = block.rows.len();
            for (i, &r) in block.rows.iter().enumerate() {
                local[r] = i;
            }
            let mut a = DMatrix::<f64>::zeros(k, k);
            for (j, &c) in block.cols.iter().enumerate() {
                for &(r, v) in &system.columns[c] {
                    if local[r] != usize::MAX {
                        a[(local[r], j)] += v;
                    }
                }
            }
            let b = DVector::from_iterator(k, block.rows.iter().map(|&r| rhs[r]));
            for &r in &block.rows {
                local[r] = usize::MAX;
            }
            let y = regular_solve(a, b)?;
            for (j, &c) in block.cols.iter().enumerate() {
                x[c] = y[j];
                for &(r, v) in &system.columns[c] {
                    rhs[r] -= v * y[j];
                }
            }
        }
        Some(x)
    }
}

/// `a y = b` by the runtime's LU (the one compiled `solve_forces` uses);
/// `None` where `a` is singular to round-off.
fn regular_solve(a: DMatrix<f64>, b: DVector<f64>) -> Option<DVector<f64>> {
    let k = b.len();
    // Row-major, as the runtime takes it.
    let mut flat: Vec<f64> = (0..k * k).map(|i| a[(i / k, i % k)]).collect();
    let mut y: Vec<f64> = b.iter().copied().collect();
    dofplan_runtime::numeric::lu_solve(&mut flat, &mut y, k).then(|| DVector::from_vec(y))
}

/// The largest component of `system x + w`.
fn residual(system: &System, x: &[f64], w: &[f64]) -> f64 {
    let mut r = w.to_vec();
    for (column, xc) in system.columns.iter().zip(x) {
        for &(row, v) in column {
            r[row] += v * xc;
        }
    }
    r.iter().fold(0.0f64, |m, v| m.max(v.abs()))
}

/// A perfect matching of rows to columns by augmenting paths (breadth
/// first, no recursion: a long chain has thousands of rows), as `row ->
/// column`; `None` if some column has no row left.
fn matching(system: &System) -> Option<Vec<usize>> {
    let (rows, cols) = (system.rows, system.columns.len());
    let mut row_of = vec![usize::MAX; cols];
    let mut col_of = vec![usize::MAX; rows];
    let mut parent = vec![usize::MAX; rows];
    let mut seen = vec![usize::MAX; rows];
    for start in 0..cols {
        let mut queue = std::collections::VecDeque::from([start]);
        let mut end = None;
        'search: while let Some(c) = queue.pop_front() {
            for &(r, _) in &system.columns[c] {
                if seen[r] == start {
                    continue;
                }
                seen[r] = start;
                parent[r] = c;
                if col_of[r] == usize::MAX {
                    end = Some(r);
                    break 'search;
                }
                queue.push_back(col_of[r]);
            }
        }
        // Flip the path: each row takes the column that reached it.
        let mut r = end?;
        loop {
            let c = parent[r];
            let previous = row_of[c];
            row_of[c] = r;
            col_of[r] = c;
            if c == start {
                break;
            }
            r = previous;
        }
    }
    Some(col_of)
}

/// The blocks of the block triangular form, in solve order: Tarjan's
/// strongly connected components (iterative) of "unknown c's matched
/// equation involves unknown d", which it emits dependencies first.
fn blocks(system: &System, col_of: &[usize]) -> Vec<Block> {
    let cols = system.columns.len();
    let mut row_of = vec![0; cols];
    for (r, &c) in col_of.iter().enumerate() {
        row_of[c] = r;
    }
    // Per row, the columns in it.
    let mut in_row: Vec<Vec<usize>> = vec![Vec::new(); system.rows];
    for (c, column) in system.columns.iter().enumerate() {
        for &(r, _) in column {
            if in_row[r].last() != Some(&c) {
                in_row[r].push(c);
            }
        }
    }
    let needs = |c: usize| &in_row[row_of[c]];
    let (mut index, mut low, mut on_stack) = (vec![usize::MAX; cols], vec![0; cols], vec![false; cols]);
    let (mut stack, mut out, mut next) = (Vec::new(), Vec::new(), 0);
    for root in 0..cols {
        if index[root] != usize::MAX {
            continue;
        }
        // (node, position in its list of needs)
        let mut calls = vec![(root, 0usize)];
        index[root] = next;
        low[root] = next;
        next += 1;
        stack.push(root);
        on_stack[root] = true;
        while let Some(&mut (v, ref mut k)) = calls.last_mut() {
            if let Some(&w) = needs(v).get(*k) {
                *k += 1;
                if index[w] == usize::MAX {
                    index[w] = next;
                    low[w] = next;
                    next += 1;
                    stack.push(w);
                    on_stack[w] = true;
                    calls.push((w, 0));
                } else if on_stack[w] {
                    low[v] = low[v].min(index[w]);
                }
                continue;
            }
            calls.pop();
            if let Some(&(parent, _)) = calls.last() {
                low[parent] = low[parent].min(low[v]);
            }
            if low[v] == index[v] {
                let mut component = Vec::new();
                while let Some(w) = stack.pop() {
                    on_stack[w] = false;
                    component.push(w);
                    if w == v {
                        break;
                    }
                }
                component.sort_unstable();
                out.push(Block {
                    rows: component.iter().map(|&c| row_of[c]).collect(),
                    cols: component,
                });
            }
        }
    }
    out
}
