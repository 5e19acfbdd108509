//! Plan time by size: loading, analysing (planner and branch choice) and the
//! Jacobian rank of `check`, on stress chains of 100 and 1,000 four-bar
//! loops; criterion reports time per body via the throughput.
//!
//! `cargo bench --bench plan_time`. `cargo run --release --example scaling`
//! prints the user guide's table ("Plan time by size" in
//! docs/guide/performance.md) for 10 to 2,000 loops.

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use dofplan::analysis::analyse;
use dofplan::analysis::planar::rank::rank_mobility;
use dofplan::load_str;
use dofplan::model::Format;
use dofplan_tests::stress::stress_chain;

fn plan_time(c: &mut Criterion) {
    for loops in [100, 1000] {
        let text = stress_chain(loops);
        let m = load_str("chain.toml", &text, Format::Toml).expect("a stress chain loads");
        let mut group = c.benchmark_group(format!("plan_time_{loops}_loops"));
        group.sample_size(20);
        group.throughput(Throughput::Elements(m.bodies.len() as u64));
        group.bench_function("load", |b| {
            b.iter(|| load_str("chain.toml", black_box(&text), Format::Toml))
        });
        group.bench_function("analyse", |b| b.iter(|| analyse(black_box(&m))));
        group.bench_function("rank", |b| b.iter(|| rank_mobility(black_box(&m))));
        group.finish();
    }
}

/// Plan and check of the spatial stress chains (10 and 100 RSSR loops).
fn spatial_plan_time(c: &mut Criterion) {
    for name in ["spatial_stress_10", "spatial_stress_100"] {
        let m = dofplan_tests::load_spatial(name);
        let mut group = c.benchmark_group(format!("plan_time_{name}"));
        group.sample_size(20);
        group.throughput(Throughput::Elements(m.bodies.len() as u64));
        group.bench_function("analyse", |b| {
            b.iter(|| dofplan::analysis::spatial::analyse(black_box(&m)))
        });
        group.bench_function("count", |b| {
            b.iter(|| dofplan::analysis::spatial::count::count(black_box(&m)))
        });
        group.finish();
    }
}

criterion_group!(benches, plan_time, spatial_plan_time);
criterion_main!(benches);
