//! Drags out of reach, measured: the library `Drag` (what `dofplan drag`
//! runs) pulling a marker toward a target it cannot reach, under each
//! breaking policy, and the unplanned (task-priority) drag of the open
//! chain in reach, as a baseline. Prints a Markdown table of medians.
//!
//! `cargo run --release --example drag_reach`

use std::hint::black_box;
use std::time::Instant;

use dofplan::load_file;
use dofplan::model::Mechanism;
use dofplan::numeric::planar::drag::Drag;
use dofplan_runtime::{BreakPolicy, Driver, FrameStatus, Options};
use dofplan_tests::mechanisms_dir;

/// Evenly spaced targets from `from` to `to`, both included.
fn path(from: [f64; 2], to: [f64; 2], n: usize) -> Vec<Vec<f64>> {
    (0..n)
        .map(|i| {
            let t = i as f64 / (n - 1) as f64;
            vec![from[0] + t * (to[0] - from[0]), from[1] + t * (to[1] - from[1])]
        })
        .collect()
}

/// Median over `passes` runs of the whole path from the drawn pose: µs per
/// frame, and the statuses of the last run.
fn measure(drag: Drag, policy: BreakPolicy, targets: &[Vec<f64>], passes: usize) -> (f64, Vec<FrameStatus>) {
    let options = Options {
        breaking: policy,
        ..Options::default()
    };
    let mut driver = Driver::new(drag, options);
    let mut statuses = Vec::new();
    let mut samples: Vec<f64> = (0..passes)
        .map(|_| {
            driver.reset();
            statuses.clear();
            let t = Instant::now();
            for target in targets {
                statuses.push(black_box(driver.frame(black_box(target))));
            }
            t.elapsed().as_secs_f64() * 1e6 / targets.len() as f64
        })
        .collect();
    samples.sort_by(f64::total_cmp);
    (samples[samples.len() / 2], statuses)
}

fn row(
    name: &str,
    m: &Mechanism,
    marker: &str,
    to: [f64; 2],
    unplanned: bool,
    policy: BreakPolicy,
    passes: usize,
) {
    let id = m.find_marker(marker).expect("bundled marker");
    let targets = path(m.marker(id).at, to, 50);
    let drag = if unplanned {
        Drag::unplanned(m, id)
    } else {
        Drag::new(m, id)
    }
    .expect("a mobile marker");
    let (us, statuses) = measure(drag, policy, &targets, passes);
    let count = |name: &str| statuses.iter().filter(|s| s.name() == name).count();
    println!(
        "| {name} | {policy:?} | {} solved, {} stretched, {} limited, {} searched | {us:.0} | {:.0} |",
        count("solved"),
        count("stretched"),
        count("limited"),
        count("searched"),
        1e6 / us
    );
}

fn main() {
    let chain = load_file(&mechanisms_dir().join("drag/open_chain_15.toml")).expect("bundled");
    let fourbar = load_file(&mechanisms_dir().join("fourbar.toml")).expect("bundled");
    println!("| drag (50 targets from the drawn marker) | policy | frames | µs/frame (median) | frames/s |");
    println!("|---|---|---|---:|---:|");
    for policy in [BreakPolicy::Stretch, BreakPolicy::Limit, BreakPolicy::Search] {
        let passes = if policy == BreakPolicy::Search { 3 } else { 11 };
        row(
            "open chain's link_15.E to (60, 80)",
            &chain,
            "link_15.E",
            [60.0, 80.0],
            false,
            policy,
            passes,
        );
    }
    for policy in [BreakPolicy::Stretch, BreakPolicy::Limit, BreakPolicy::Search] {
        row(
            "fourbar's coupler.P to (−3, 5)",
            &fourbar,
            "coupler.P",
            [-3.0, 5.0],
            false,
            policy,
            11,
        );
    }
    row(
        "open chain's link_15.E to (6, 8), unplanned (in reach)",
        &chain,
        "link_15.E",
        [6.0, 8.0],
        true,
        BreakPolicy::Limit,
        11,
    );
}
