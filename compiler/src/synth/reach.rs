//! Running a candidate to its targets' input values, for either
//! dimension: up from its drawing (input 0) to the positive values and
//! down to the negative ones, in steps no larger than a given one, so that
//! every target is reached on the drawing's own circuit.

use dofplan_runtime::{Driver, Options, Solver};

/// The frames (poses and state) of `solver` at every value of `at`, in
/// `at`'s order, or `None` if one is not reached; `request(v)` makes the
/// inputs for the driving input's value `v`.
#[allow(clippy::type_complexity)]
pub fn reach<S: Solver>(
    solver: &S,
    at: &[f64],
    step: f64,
    request: impl Fn(f64) -> Vec<f64>,
) -> Option<Vec<(Vec<S::Pose>, S::State)>> {
    let mut order: Vec<usize> = (0..at.len()).collect();
    order.sort_by(|&a, &b| at[a].total_cmp(&at[b]));
    let mut out: Vec<Option<(Vec<S::Pose>, S::State)>> = vec![None; at.len()];
    let (down, up): (Vec<usize>, Vec<usize>) = order.into_iter().partition(|&i| at[i] < 0.0);
    for side in [up, down.into_iter().rev().collect::<Vec<_>>()] {
        // A borrowed plan: the candidate's plan is not copied per side.
        let mut driver = Driver::new(solver, Options::default());
        let mut now = 0.0f64;
        for i in side {
            let n = ((at[i] - now).abs() / step).ceil().max(1.0) as usize;
            for s in 1..=n {
                if !driver
                    .frame(&request(now + (at[i] - now) * s as f64 / n as f64))
                    .is_solved()
                {
                    return None;
                }
            }
            now = at[i];
            out[i] = Some((driver.poses().to_vec(), driver.state().clone()));
        }
    }
    out.into_iter().collect()
}
