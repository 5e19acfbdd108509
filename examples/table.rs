//! Prints the move-time table: mechanism, mobile links, joints, plan
//! steps, compiled ns/frame, interpreted ns/frame, ratio.
//!
//! `cargo run --release --example table` (add mechanism names to restrict).
//! Each figure is the median over repeated timed passes of the mechanism's
//! sweep, driven frame by frame through `dofplan_runtime::Driver` exactly as
//! an animation would (warm start, keep-branch, limit policy).

use std::hint::black_box;
use std::time::Instant;

use dofplan::interp::Interpreter;
use dofplan::simulate::sweep_inputs;
use dofplan_runtime::{Driver, Options, Solver};
use dofplan_tests::{bundled, load, plan};

/// Times one pass of `reps` sweeps, in ns per frame.
fn pass<S: Solver>(driver: &mut Driver<S>, inputs: &[Vec<f64>], reps: usize) -> f64 {
    driver.reset();
    let t = Instant::now();
    for _ in 0..reps {
        for i in inputs {
            black_box(driver.frame(black_box(i)));
        }
    }
    t.elapsed().as_secs_f64() * 1e9 / (reps * inputs.len()) as f64
}

/// Sweeps repeated so one pass takes about 5 ms.
fn reps_for<S: Solver>(driver: &mut Driver<S>, inputs: &[Vec<f64>]) -> usize {
    let per_frame = pass(driver, inputs, 1).max(pass(driver, inputs, 1)) * 1e-9;
    ((5e-3 / per_frame) as usize / inputs.len()).max(1)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Median ns per frame of the compiled and the interpreted driver, passes
/// alternating so that both see the same machine (these machines are noisy).
fn compare<S: Solver, T: Solver>(
    compiled: &mut Driver<S>,
    interpreted: &mut Driver<T>,
    inputs: &[Vec<f64>],
    passes: usize,
) -> (f64, f64) {
    let (rc, ri) = (reps_for(compiled, inputs), reps_for(interpreted, inputs));
    let mut c = Vec::new();
    let mut i = Vec::new();
    for _ in 0..passes {
        c.push(pass(compiled, inputs, rc));
        i.push(pass(interpreted, inputs, ri));
    }
    (median(c), median(i))
}

fn main() {
    let filter: Vec<String> = std::env::args().skip(1).collect();
    let names: Vec<String> = bundled()
        .into_iter()
        .filter(|n| filter.is_empty() || filter.contains(n))
        .collect();
    println!("| mechanism | mobile links | joints | plan steps | compiled ns/frame | interpreted ns/frame | ratio |");
    println!("|---|---:|---:|---:|---:|---:|---:|");
    for name in names {
        let m = load(&name);
        let p = plan(&m);
        let inputs = sweep_inputs(&m, None);
        // Figure 30's counts: mobile links exclude the driving link, active
        // joints exclude the driving link's ground joint.
        let mobile = m.bodies.iter().filter(|b| !b.fixed).count() - m.inputs.len();
        let joints = m.joints.len() - m.inputs.len();
        // The compiled plan's own Driver type (monomorphised, no trait object
        // between the loop and the plan), as a user's simulator has it.
        let mut interpreted = Driver::new(Interpreter::new(p.clone()), Options::default());
        let (c, i) = dofplan_generated::with_plan!(name.as_str(), |plan| {
            compare(
                &mut Driver::new(plan, Options::default()),
                &mut interpreted,
                &inputs,
                31,
            )
        })
        .expect("compiled");
        println!(
            "| {name} | {mobile} | {joints} | {} | {c:.1} | {i:.1} | {:.2} |",
            p.steps.len(),
            i / c
        );
    }
}
