//! One four-bar candidate on an 18-point given-timing path — prepare, 18
//! frames, the error — through the compiled design module and through the
//! library: the work `cargo bench --bench move_time design` and the
//! table's `design` rows time (shared by both; not a target itself).

/// The four-bar's coupler point at 18 inputs 20° apart: the error of a
/// candidate on a given-timing path is the sum of squared distances to
/// these targets (the drawing's own path, so a candidate's error measures
/// how far it moved).
pub const PATH_INPUTS: [[f64; 1]; 18] = {
    let mut u = [[0.0]; 18];
    let mut i = 0;
    while i < 18 {
        u[i] = [20.0 * i as f64];
        i += 1;
    }
    u
};

/// One candidate through the compiled design module: prepare, 18 frames,
/// the error (infinite when it cannot be prepared or breaks).
pub fn compiled_candidate(values: &[f64; 10], targets: &[[f64; 2]; 18]) -> f64 {
    use dofplan_generated::fourbar::{design, marker};
    use dofplan_runtime::{BranchPolicy, Ctx};
    let Ok(g) = design::prepare(&design::Params(*values)) else {
        return f64::INFINITY;
    };
    let (mut s, p) = (g.state(), g.marker(marker::COUPLER_P));
    let mut ctx = Ctx::new(BranchPolicy::Keep, false);
    let mut e = 0.0;
    for (u, t) in PATH_INPUTS.iter().zip(targets) {
        if design::solve_with(&g, &mut s, u, &mut ctx).is_err() {
            return f64::INFINITY;
        }
        let w = s.marker(p);
        e += (w[0] - t[0]).powi(2) + (w[1] - t[1]).powi(2);
    }
    e
}

/// [`compiled_candidate`] with the 18 frames in lanes
/// (`design::solve_frames_with`: eight frames side by side, each from the
/// candidate's drawn state): the same poses to the bit, so the same error.
pub fn compiled_candidate_in_lanes(values: &[f64; 10], targets: &[[f64; 2]; 18]) -> f64 {
    use dofplan_generated::fourbar::{design, marker, BODIES};
    use dofplan_runtime::planar::Pose;
    const INPUTS: [f64; 18] = {
        let mut u = [0.0; 18];
        let mut i = 0;
        while i < 18 {
            u[i] = PATH_INPUTS[i][0];
            i += 1;
        }
        u
    };
    let Ok(g) = design::prepare(&design::Params(*values)) else {
        return f64::INFINITY;
    };
    let p = g.marker(marker::COUPLER_P);
    let mut poses = [Pose::IDENTITY; 18 * BODIES.len()];
    if design::solve_frames_with(&g, &INPUTS, &mut poses).is_err() {
        return f64::INFINITY;
    }
    let mut e = 0.0;
    for (row, t) in poses.chunks_exact(BODIES.len()).zip(targets) {
        let w = p.world(row);
        e += (w[0] - t[0]).powi(2) + (w[1] - t[1]).powi(2);
    }
    e
}

/// One candidate with its full Jacobian through the compiled design
/// module: prepare, 18 frames with their derivatives with respect to all
/// 10 parameters (`design::gradient`), the error, and the Jacobian of the
/// 36 residuals (x and y of each point) written to `jacobian` — what a
/// Gauss–Newton or Levenberg–Marquardt step needs.
pub fn compiled_candidate_with_jacobian(
    values: &[f64; 10],
    targets: &[[f64; 2]; 18],
    jacobian: &mut [[f64; 10]; 36],
) -> f64 {
    use dofplan_generated::fourbar::{design, marker};
    use dofplan_runtime::{BranchPolicy, Ctx};
    let Ok(g) = design::prepare(&design::Params(*values)) else {
        return f64::INFINITY;
    };
    let t = g.tangents();
    let mut s = g.state();
    let mut ctx = Ctx::new(BranchPolicy::Keep, false);
    let mut e = 0.0;
    for (i, (u, target)) in PATH_INPUTS.iter().zip(targets).enumerate() {
        if design::solve_with(&g, &mut s, u, &mut ctx).is_err() {
            return f64::INFINITY;
        }
        let Ok(poses) = design::gradient(&t, &s, u) else {
            return f64::INFINITY;
        };
        let Some(w) = t.marker(&poses, marker::COUPLER_P) else {
            return f64::INFINITY;
        };
        e += (w[0].v - target[0]).powi(2) + (w[1].v - target[1]).powi(2);
        jacobian[2 * i] = w[0].d;
        jacobian[2 * i + 1] = w[1].d;
    }
    e
}

/// The same candidate through the library: re-planned (`Design::prepare`)
/// and run by the interpreter.
pub fn interpreted_candidate(
    design: &dofplan::synth::planar::Design,
    values: &[f64],
    targets: &[[f64; 2]; 18],
) -> f64 {
    use dofplan_runtime::{BranchPolicy, Ctx, Solver};
    let Ok(c) = design.prepare(values) else {
        return f64::INFINITY;
    };
    let p = c.mechanism.find_marker("coupler.P").expect("bundled");
    let local = c.mechanism.marker(p).at;
    let mut s = c.initial_state();
    let mut ctx = Ctx::new(BranchPolicy::Keep, false);
    let mut e = 0.0;
    for (u, t) in PATH_INPUTS.iter().zip(targets) {
        if c.interpreter.solve(&mut s, u, &mut ctx).is_err() {
            return f64::INFINITY;
        }
        let w = s.poses[p.body].world(local);
        e += (w[0] - t[0]).powi(2) + (w[1] - t[1]).powi(2);
    }
    e
}

/// The targets: the drawn four-bar's coupler point at [`PATH_INPUTS`].
pub fn path_targets() -> [[f64; 2]; 18] {
    use dofplan_generated::fourbar::{self as module, marker};
    use dofplan_runtime::{BranchPolicy, Ctx};
    let mut targets = [[0.0; 2]; 18];
    let mut s = module::State::DRAWN;
    let mut ctx = Ctx::new(BranchPolicy::Keep, false);
    for (u, t) in PATH_INPUTS.iter().zip(&mut targets) {
        module::solve(&mut s, u, &mut ctx).expect("the drawn four-bar turns fully");
        *t = s.marker(marker::COUPLER_P);
    }
    targets
}

/// Two candidates a little off the drawing (every parameter moved), to be
/// alternated so no pass can reuse the last one's work.
pub fn two_candidates() -> [[f64; 10]; 2] {
    use dofplan_generated::fourbar::design::Params;
    let mut a = Params::DRAWN.0;
    let mut b = Params::DRAWN.0;
    for (k, (x, y)) in a.iter_mut().zip(&mut b).enumerate() {
        *x += 0.01 * (k as f64 + 1.0);
        *y -= 0.007 * (k as f64 + 1.0);
    }
    [a, b]
}
