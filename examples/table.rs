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

/// Median ns per frame of driving `driver` through `inputs`, over `passes`
/// passes each long enough to take a few milliseconds.
fn ns_per_frame<S: Solver>(driver: &mut Driver<S>, inputs: &[Vec<f64>], passes: usize) -> f64 {
    // Warm up and size each pass to ~5 ms.
    let start = Instant::now();
    let mut frames = 0usize;
    while start.elapsed().as_millis() < 20 {
        for i in inputs {
            black_box(driver.frame(black_box(i)));
        }
        frames += inputs.len();
    }
    let per = start.elapsed().as_secs_f64() / frames as f64;
    let reps = ((5e-3 / per) as usize / inputs.len()).max(1);
    let mut samples: Vec<f64> = (0..passes)
        .map(|_| {
            driver.reset();
            let t = Instant::now();
            for _ in 0..reps {
                for i in inputs {
                    black_box(driver.frame(black_box(i)));
                }
            }
            t.elapsed().as_secs_f64() * 1e9 / (reps * inputs.len()) as f64
        })
        .collect();
    samples.sort_by(f64::total_cmp);
    samples[samples.len() / 2]
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
        let c = dofplan_generated::with_plan!(name.as_str(), |plan| {
            ns_per_frame(&mut Driver::new(plan, Options::default()), &inputs, 21)
        })
        .expect("compiled");
        let mut interpreted = Driver::new(Interpreter::new(p.clone()), Options::default());
        let i = ns_per_frame(&mut interpreted, &inputs, 21);
        println!(
            "| {name} | {mobile} | {joints} | {} | {c:.1} | {i:.1} | {:.2} |",
            p.steps.len(),
            i / c
        );
    }
}
