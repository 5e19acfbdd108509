//! How plan time grows with the mechanism: stress chains of 10 to 2,000
//! four-bar loops (`dofplan_tests::stress::stress_chain`), timed through
//! the library calls each CLI command makes, printed as a markdown table.
//!
//! `cargo run --release --example scaling [LOOPS...]`
//!
//! - load: parse and validate the file text;
//! - analyse: Grübler's count, the planner and the branch choice;
//! - rank: the Jacobian-rank cross-check of `check`;
//! - `plan`: load + analyse + the explained plan (what `dofplan plan` does);
//! - ranges: the assembly ranges of `check` (the plan run over each input's
//!   range);
//! - four-bars: the four-bar loops and their Grashof class of `check`;
//! - `check`: load + analyse + rank + ranges + four-bars (the library work
//!   of `dofplan check`);
//! - `emit`: load + analyse + the generated module (`dofplan emit`);
//! - simulate: one interpreted frame of the sweep (warm start,
//!   keep-branch), as `dofplan simulate` runs it;
//! - compiled: one frame of the same sweep by the chain's compiled plan
//!   (`dofplan_generated::chains`, compiled as a user's build.rs compiles
//!   it; other loop counts than the table's have no compiled column).
//!
//! Every figure is a median: of at least 3 runs (more for quick ones, up to
//! 21) for the plan-time columns, of 5 passes over the sweep for the frame.
//! Times are the measuring thread's CPU time: on a shared machine a run of
//! more than a few milliseconds waits for a core, and wall time would count
//! the wait.

use std::hint::black_box;

use dofplan::analysis::analyse;
use dofplan::analysis::planar::grashof::four_bars;
use dofplan::analysis::planar::rank::rank_mobility;
use dofplan::analysis::ranges::assembly_ranges;
use dofplan::emit::emit;
use dofplan::interp::Interpreter;
use dofplan::load_str;
use dofplan::model::{Format, Mechanism};
use dofplan::simulate::sweep_inputs;
use dofplan_runtime::{Animate, Driver, Options};
use dofplan_tests::stress::stress_chain;

/// The sizes of the user guide's table ("Plan time by size" in
/// docs/guide/performance.md).
const LOOPS: [usize; 7] = [10, 50, 100, 200, 500, 1000, 2000];

/// CPU seconds the calling thread has run.
fn cpu() -> f64 {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime writes the timespec it is given, nothing else.
    let ok = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut t) };
    assert_eq!(ok, 0, "the thread CPU clock is readable");
    t.tv_sec as f64 + t.tv_nsec as f64 * 1e-9
}

/// Median CPU seconds of `f`, run until about a second is spent (3 to 21
/// runs).
fn median(mut f: impl FnMut()) -> f64 {
    let mut samples = Vec::new();
    let start = cpu();
    while samples.len() < 3 || (samples.len() < 21 && cpu() - start < 1.0) {
        let t = cpu();
        f();
        samples.push(cpu() - t);
    }
    samples.sort_by(f64::total_cmp);
    samples[samples.len() / 2]
}

fn load(text: &str) -> Mechanism {
    load_str("stress.toml", text, Format::Toml).unwrap_or_else(|e| panic!("{e}"))
}

/// The sweep's first `frames` frames.
fn frames(m: &Mechanism, frames: usize) -> Vec<Vec<f64>> {
    sweep_inputs(m, None).into_iter().take(frames).collect()
}

/// Median µs per frame of `driver` over 5 passes of `inputs`.
fn us_per_frame(driver: &mut dyn Animate, inputs: &[Vec<f64>]) -> f64 {
    let mut samples: Vec<f64> = (0..5)
        .map(|_| {
            driver.reset();
            let t = cpu();
            for i in inputs {
                black_box(driver.frame(black_box(i)));
            }
            (cpu() - t) * 1e6 / inputs.len() as f64
        })
        .collect();
    samples.sort_by(f64::total_cmp);
    samples[samples.len() / 2]
}

fn ms(seconds: f64) -> String {
    let ms = seconds * 1e3;
    if ms < 10.0 {
        format!("{ms:.2}")
    } else if ms < 100.0 {
        format!("{ms:.1}")
    } else {
        format!("{ms:.0}")
    }
}

fn main() {
    let loops: Vec<usize> = {
        let args: Vec<usize> = std::env::args()
            .skip(1)
            .map(|a| a.parse().expect("usage: scaling [LOOPS...] (whole numbers)"))
            .collect();
        if args.is_empty() {
            LOOPS.to_vec()
        } else {
            args
        }
    };
    println!(
        "| loops | bodies | joints | steps | load ms | analyse ms | rank ms | ranges ms | four-bars ms | `plan` ms | \
         `check` ms | `emit` ms | simulate µs/frame | compiled µs/frame |"
    );
    println!("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for n in loops {
        let text = stress_chain(n);
        let m = load(&text);
        let plan = analyse(&m).plan.expect("a stress chain plans");
        let steps = plan.steps.len();
        let t_load = median(|| {
            black_box(load(&text));
        });
        let t_analyse = median(|| {
            black_box(analyse(&m));
        });
        let t_rank = median(|| {
            black_box(rank_mobility(&m));
        });
        let t_ranges = median(|| {
            black_box(assembly_ranges(&m, &plan));
        });
        let t_four_bars = median(|| {
            black_box(four_bars(&m));
        });
        let t_plan = median(|| {
            let m = load(&text);
            let p = analyse(&m).plan.expect("plans");
            black_box(p.explain_all());
        });
        let t_check = median(|| {
            let m = load(&text);
            let p = analyse(&m).plan.expect("plans");
            black_box(rank_mobility(&m));
            black_box(assembly_ranges(&m, &p));
            black_box(four_bars(&m));
        });
        let t_emit = median(|| {
            let m = load(&text);
            let p = analyse(&m).plan.expect("plans");
            black_box(emit(&p));
        });
        // About 100 ms of frames per pass at most: fewer for long chains.
        let inputs = frames(&m, (20_000 / n).clamp(8, 361));
        let t_frame = us_per_frame(
            &mut Driver::new(Interpreter::new(plan), Options::default()),
            &inputs,
        );
        let t_compiled = match dofplan_generated::chains::driver(n, Options::default()) {
            Some(mut compiled) => format!("{:.1}", us_per_frame(compiled.as_mut(), &inputs)),
            None => "–".into(),
        };
        println!(
            "| {n} | {} | {} | {steps} | {} | {} | {} | {} | {} | {} | {} | {} | {t_frame:.1} | {t_compiled} |",
            m.bodies.len(),
            m.joints.len(),
            ms(t_load),
            ms(t_analyse),
            ms(t_rank),
            ms(t_ranges),
            ms(t_four_bars),
            ms(t_plan),
            ms(t_check),
            ms(t_emit),
        );
    }
}
