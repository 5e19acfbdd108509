//! Move time per mechanism, compiled and interpreted: each iteration drives
//! the mechanism through its whole bundled sweep (keep-branch, limit
//! policy), and criterion reports time per frame via the throughput.
//!
//! `cargo bench --bench move_time` (add a filter such as `fourbar`).
//! `cargo run --release --example table` prints the summary table.

use std::hint::black_box;

#[path = "shared/design_path.rs"]
mod design_path;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use dofplan::interp::Interpreter;
use dofplan::load_file;
use dofplan::numeric::planar::drag::Drag;
use dofplan::numeric::spatial::pure_newton;
use dofplan::simulate::sweep_inputs;
use dofplan::simulate::sweep_requests;
use dofplan_runtime::{Driver, Options, Solver};
use dofplan_tests::{bundled, bundled_spatial, load, load_spatial, mechanisms_dir, plan};

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

/// The open chain of 15 links dragged by its end along a straight pull:
/// the compiled drag (`Config::drag`) and the library's planned `Drag`.
fn drag(c: &mut Criterion) {
    let m = load_file(&mechanisms_dir().join("drag/open_chain_15.toml")).expect("bundled");
    let end = m.find_marker("link_15.E").expect("bundled");
    let from = m.marker(end).at;
    let slides: Vec<Vec<f64>> = (0..400)
        .map(|i| vec![-0.01 * f64::from(i), 0.0125 * f64::from(i)])
        .collect();
    let targets: Vec<Vec<f64>> = slides
        .iter()
        .map(|s| vec![from[0] + s[0], from[1] + s[1]])
        .collect();
    let mut group = c.benchmark_group("drag_open_chain_15");
    group.throughput(Throughput::Elements(slides.len() as u64));
    let mut compiled = Driver::new(
        dofplan_generated::open_chain_15_drag_link_15_e::Plan,
        Options::default(),
    );
    group.bench_function("compiled", |b| {
        b.iter(|| {
            compiled.reset();
            sweep(&mut compiled, &slides)
        })
    });
    let mut library = Driver::new(Drag::new(&m, end).expect("mobile"), Options::default());
    group.bench_function("library", |b| {
        b.iter(|| {
            library.reset();
            sweep(&mut library, &targets)
        })
    });
    group.finish();
}

/// Spatial mechanisms: compiled, interpreted, and (for those small enough
/// for it) pure Newton with six unknowns a body and no analysis.
fn spatial(c: &mut Criterion) {
    for name in bundled_spatial() {
        let m = load_spatial(&name);
        let inputs: Vec<Vec<f64>> =
            sweep_requests(m.sweep.as_ref().expect("a sweep"), m.inputs.len()).collect();
        let mut group = c.benchmark_group(format!("spatial/{name}"));
        group.throughput(Throughput::Elements(inputs.len() as u64));
        dofplan_generated::with_spatial_plan!(name.as_str(), |plan| {
            let mut compiled = Driver::new(plan, Options::default());
            group.bench_function("compiled", |b| b.iter(|| sweep(&mut compiled, &inputs)));
        })
        .expect("compiled");
        let plan = dofplan::analysis::spatial::analyse(&m).expect("plans");
        let mut interpreted = Driver::new(
            dofplan::interp::spatial::Interpreter::new(plan),
            Options::default(),
        );
        group.bench_function("interpreted", |b| b.iter(|| sweep(&mut interpreted, &inputs)));
        if m.moving() <= 20 {
            let mut newton = Driver::new(
                dofplan::interp::spatial::Interpreter::new(pure_newton(&m)),
                Options::default(),
            );
            group.sample_size(10);
            group.bench_function("pure_newton", |b| b.iter(|| sweep(&mut newton, &inputs)));
        }
        group.finish();
    }
}

/// One four-bar candidate on an 18-point given-timing path (prepare, 18
/// frames, the error): compiled (`design::prepare` + `solve_with`), the
/// same with the frames in lanes (`solve_frames_with`), the same with its
/// Jacobian (`design::gradient`), and through the library
/// (`Design::prepare` + the interpreter).
fn design(c: &mut Criterion) {
    let library = dofplan::synth::planar::Design::new(&load("fourbar")).expect("a design");
    let targets = design_path::path_targets();
    let [a, b] = design_path::two_candidates();
    let mut group = c.benchmark_group("design_fourbar_18_points");
    let mut flip = false;
    group.bench_function("compiled", |bench| {
        bench.iter(|| {
            flip = !flip;
            design_path::compiled_candidate(black_box(if flip { &a } else { &b }), &targets)
        })
    });
    group.bench_function("compiled_in_lanes", |bench| {
        bench.iter(|| {
            flip = !flip;
            design_path::compiled_candidate_in_lanes(black_box(if flip { &a } else { &b }), &targets)
        })
    });
    let mut jacobian = [[0.0; 10]; 36];
    group.bench_function("compiled_with_jacobian", |bench| {
        bench.iter(|| {
            flip = !flip;
            design_path::compiled_candidate_with_jacobian(
                black_box(if flip { &a } else { &b }),
                &targets,
                &mut jacobian,
            )
        })
    });
    group.bench_function("library", |bench| {
        bench.iter(|| {
            flip = !flip;
            design_path::interpreted_candidate(&library, black_box(if flip { &a } else { &b }), &targets)
        })
    });
    group.finish();
}

criterion_group!(benches, move_time, drag, spatial, design);
criterion_main!(benches);
