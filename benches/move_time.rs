//! Move time per mechanism, compiled and interpreted: each iteration drives
//! the mechanism through its whole bundled sweep (keep-branch, limit
//! policy), and criterion reports time per frame via the throughput.
//!
//! `cargo bench --bench move_time` (add a filter such as `fourbar`).
//! `cargo run --release --example table` prints the summary table.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use dofplan::interp::Interpreter;
use dofplan::simulate::sweep_inputs;
use dofplan_runtime::{Driver, Options, Solver};
use dofplan_tests::{bundled, load, plan};

fn sweep<S: Solver>(driver: &mut Driver<S>, inputs: &[Vec<f64>]) {
    for i in inputs {
        black_box(driver.frame(black_box(i)));
    }
}

fn move_time(c: &mut Criterion) {
    for name in bundled() {
        let m = load(&name);
        let inputs = sweep_inputs(&m, None);
        let mut group = c.benchmark_group(&name);
        group.throughput(Throughput::Elements(inputs.len() as u64));
        dofplan_generated::with_plan!(name.as_str(), |plan| {
            let mut compiled = Driver::new(plan, Options::default());
            group.bench_function("compiled", |b| b.iter(|| sweep(&mut compiled, &inputs)));
        })
        .expect("compiled");
        let mut interpreted = Driver::new(Interpreter::new(plan(&m)), Options::default());
        group.bench_function("interpreted", |b| b.iter(|| sweep(&mut interpreted, &inputs)));
        group.finish();
    }
}

criterion_group!(benches, move_time);
criterion_main!(benches);
