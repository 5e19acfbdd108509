//! Prints the move-time tables: for planar mechanisms, mobile links,
//! joints, plan steps, compiled ns/frame, interpreted ns/frame, ratio; for
//! spatial ones (`mechanisms/spatial/`), bodies, joints, equations,
//! redundant rows, plan steps, cluster unknowns, compiled and interpreted
//! ns/frame, pure Newton µs/frame (six unknowns a body, no analysis) and
//! its ratio to the compiled plan; then plan + check time of the spatial
//! stress chains.
//!
//! `cargo run --release --example table` (add mechanism names to restrict;
//! `spatial`, `planar`, `rates`, `batch`, `design` or `forces` for one table). The batch table
//! times each sweep, planar and spatial, through the driver and
//! `solve_batch`, and the sweep repeated to 20,000 frames through
//! `solve_batch` and `solve_batch_parallel`.
//! Each figure is the median over repeated timed passes of the mechanism's
//! sweep, driven frame by frame through `dofplan_runtime::Driver` exactly as
//! an animation would (warm start, keep-branch, limit policy).

use std::hint::black_box;

#[path = "../benches/shared/design_path.rs"]
mod design_path;
use design_path::{
    compiled_candidate, compiled_candidate_in_lanes, compiled_candidate_with_jacobian, interpreted_candidate,
    path_targets, two_candidates,
};
use std::time::Instant;

use dofplan::analysis::spatial::{analyse as analyse3, count::count};
use dofplan::interp::Interpreter;
use dofplan::numeric::spatial::pure_newton;
use dofplan::simulate::{sweep_inputs, sweep_requests};
use dofplan_runtime::{Driver, Options, Solver};
use dofplan_tests::{bundled, bundled_spatial, load, load_spatial, plan, spatial_fixtures};

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
    let args: Vec<String> = std::env::args().skip(1).collect();
    let only = |table: &str| args.is_empty() || args.iter().any(|a| a == table);
    let filter: Vec<String> = args
        .iter()
        .filter(|a| !["spatial", "planar", "rates", "batch", "design", "forces"].contains(&a.as_str()))
        .cloned()
        .collect();
    if only("planar") || !filter.is_empty() {
        planar(&filter);
    }
    if only("spatial") || !filter.is_empty() {
        spatial(&filter);
    }
    if only("rates") || !filter.is_empty() {
        rates(&filter);
    }
    if only("batch") || !filter.is_empty() {
        batch(&filter);
    }
    if only("design") {
        design();
    }
    if only("forces") {
        forces();
    }
}

/// The forces table: per bundled file with loads, a frame of the
/// interpreted plan alone, then with its input forces (virtual work) and
/// joint reactions held still, the reactions solved by the force plan
/// (blocks made once) and by least squares every frame (an SVD of the
/// whole system); medians over the sweep.
fn forces() {
    println!();
    println!("| mechanism | equations | force plan blocks | position ns/frame | + forces, plan ns/frame | ratio | + forces, least squares ns/frame | ratio |");
    println!("|---|---:|---|---:|---:|---:|---:|---:|");
    for file in [
        "loads/slider_crank_press",
        "loads/fourbar_weights",
        "loads/arc_yoke_press",
        "gears/geared_hoist",
    ] {
        use dofplan::forces::planar::{force_plan, input_forces, reactions};
        let m = load(file);
        let name = file.rsplit('/').next().unwrap_or(file);
        let interp = Interpreter::new(plan(&m));
        let rows = 3 * m.bodies.iter().filter(|b| !b.fixed).count();
        let row = force_row(
            Driver::new(interp.clone(), Options::default()),
            &sweep_inputs(&m, None),
            &force_plan(&m).expect("no constraints"),
            |d, fp| {
                black_box(input_forces(&m, &interp, d.state(), d.inputs(), None).ok());
                black_box(reactions(&m, fp, d.poses(), None));
            },
        );
        println!("| {name} | {rows} | {row}");
    }
    for name in ["cardan_torque", "excavator_load"] {
        use dofplan::forces::spatial::{force_plan, input_forces, reactions};
        let m = match dofplan::load_any(&dofplan_tests::mechanisms_dir().join(format!("loads/{name}.toml"))) {
            Ok(dofplan::model::Model::Spatial(m)) => m,
            _ => panic!("{name} is a spatial file"),
        };
        let interp = dofplan::interp::spatial::Interpreter::new(dofplan_tests::plan_spatial(&m));
        let inputs: Vec<Vec<f64>> =
            sweep_requests(m.sweep.as_ref().expect("a sweep"), m.inputs.len()).collect();
        let row = force_row(
            Driver::new(interp.clone(), Options::default()),
            &inputs,
            &force_plan(&m).expect("no constraints"),
            |d, fp| {
                black_box(input_forces(&m, &interp, d.state(), d.inputs(), None).ok());
                black_box(reactions(&m, fp, d.poses(), None));
            },
        );
        println!("| {name} | {} | {row}", 6 * m.moving());
    }
    compiled_forces();
}

/// The compiled forces table: per planar file with loads (compiled with
/// `Config::forces`; the geared hoist's leans its tooth force by its
/// sign, solving such frames twice), a compiled position frame (`solve`) against
/// `forces::solve_forces` (positions, rates and forces in one pass),
/// held still and running; medians over the sweep.
fn compiled_forces() {
    use dofplan_runtime::Ctx;
    println!();
    println!("| mechanism (compiled) | position ns/frame | solve_forces held ns/frame | ratio | solve_forces running ns/frame | ratio |");
    println!("|---|---:|---:|---:|---:|---:|");
    macro_rules! row {
        ($($module:ident: $file:expr),*) => {$({
            use dofplan_generated::$module as compiled;
            let inputs = sweep_inputs(&load($file), None);
            let n = inputs.len() as f64;
            let mut state = compiled::State::DRAWN;
            let position = time_ns(|| {
                for u in &inputs {
                    let mut ctx = Ctx::new(Default::default(), false);
                    black_box(compiled::solve(&mut state, u, &mut ctx)).ok();
                }
            });
            let mut out = compiled::forces::Forces::default();
            let mut forces = |r: [f64; 1], a: [f64; 1]| {
                time_ns(|| {
                    for u in &inputs {
                        let mut ctx = Ctx::new(Default::default(), false);
                        black_box(compiled::forces::solve_forces(&mut state, u, &r, &a, &mut ctx, &mut out)).ok();
                    }
                })
            };
            let (held, running) = (forces([0.0], [0.0]), forces([114.59], [-57.3]));
            println!(
                "| {} | {:.0} | {:.0} | {:.1} | {:.0} | {:.1} |",
                stringify!($module),
                position / n,
                held / n,
                held / position,
                running / n,
                running / position
            );
        })*};
    }
    row!(
        slider_crank_press: "loads/slider_crank_press",
        fourbar_weights: "loads/fourbar_weights",
        arc_yoke_press: "loads/arc_yoke_press",
        geared_hoist: "gears/geared_hoist"
    );
}

/// One row of the forces table after its first two cells: the plan's
/// blocks, a frame alone, a frame with `forces` by the plan, and by least
/// squares (ns per frame, and the ratios to a frame alone).
fn force_row<S: Solver>(
    mut d: Driver<S>,
    inputs: &[Vec<f64>],
    blocks: &dofplan::forces::plan::ForcePlan,
    mut forces: impl FnMut(&Driver<S>, &dofplan::forces::plan::ForcePlan),
) -> String {
    let whole = dofplan::forces::plan::ForcePlan::LeastSquares("timed");
    let position = time_ns(|| {
        for u in inputs {
            black_box(d.frame(u));
        }
    });
    let mut with = |fp: &dofplan::forces::plan::ForcePlan| {
        time_ns(|| {
            for u in inputs {
                d.frame(u);
                forces(&d, fp);
            }
        })
    };
    let (b, w) = (with(blocks), with(&whole));
    let n = inputs.len() as f64;
    format!(
        "{:?} | {:.0} | {:.0} | {:.1} | {:.0} | {:.1} |",
        blocks.block_sizes(),
        position / n,
        b / n,
        b / position,
        w / n,
        w / position
    )
}

/// Median ns of `f` over passes of about 5 ms each.
fn time_ns(mut f: impl FnMut()) -> f64 {
    let t = Instant::now();
    f();
    let once = t.elapsed().as_secs_f64().max(1e-9);
    let reps = ((5e-3 / once) as usize).max(1);
    median(
        (0..15)
            .map(|_| {
                let t = Instant::now();
                for _ in 0..reps {
                    f();
                }
                t.elapsed().as_secs_f64() * 1e9 / reps as f64
            })
            .collect(),
    )
}

/// The design table: the four-bar's design module against its own
/// `solve`, and one candidate on an 18-point given-timing path (prepare, 18
/// frames, the error) compiled and through the library.
fn design() {
    use dofplan_generated::fourbar::{self as module, design as d};
    use dofplan_runtime::{BranchPolicy, Ctx};
    let m = load("fourbar");
    let library = dofplan::synth::planar::Design::new(&m).expect("a design");
    let targets = path_targets();
    let [a, b] = two_candidates();
    let mut s = module::State::DRAWN;
    let mut ctx = Ctx::new(BranchPolicy::Keep, false);
    let g = d::prepare(&d::Params(a)).expect("a small move");
    let frames: Vec<[f64; 1]> = (0..360).map(|i| [f64::from(i)]).collect();
    let per_frame = |f: &mut dyn FnMut(&[f64; 1])| {
        time_ns(|| {
            for u in &frames {
                f(black_box(u));
            }
        }) / frames.len() as f64
    };
    let solve = per_frame(&mut |u| {
        let _ = black_box(module::solve(&mut s, u, &mut ctx));
    });
    let mut sw = g.state();
    let solve_with = per_frame(&mut |u| {
        let _ = black_box(d::solve_with(&g, &mut sw, u, &mut ctx));
    });
    let mut flip = false;
    let prepare = time_ns(|| {
        flip = !flip;
        let _ = black_box(d::prepare(&d::Params(black_box(if flip { a } else { b }))));
    });
    let compiled = time_ns(|| {
        flip = !flip;
        black_box(compiled_candidate(
            black_box(if flip { &a } else { &b }),
            &targets,
        ));
    });
    let in_lanes = time_ns(|| {
        flip = !flip;
        black_box(compiled_candidate_in_lanes(
            black_box(if flip { &a } else { &b }),
            &targets,
        ));
    });
    let mut jacobian = [[0.0; 10]; 36];
    let with_jacobian = time_ns(|| {
        flip = !flip;
        black_box(compiled_candidate_with_jacobian(
            black_box(if flip { &a } else { &b }),
            &targets,
            &mut jacobian,
        ));
    });
    let interpreted = time_ns(|| {
        flip = !flip;
        black_box(interpreted_candidate(
            &library,
            black_box(if flip { &a } else { &b }),
            &targets,
        ));
    });
    println!("| fourbar | ns |");
    println!("|---|---:|");
    println!("| `solve`, a frame of the drawing | {solve:.1} |");
    println!("| `design::solve_with`, a frame of a candidate | {solve_with:.1} |");
    println!("| `design::prepare`, a candidate | {prepare:.1} |");
    println!("| a candidate on an 18-point path (prepare + 18 frames + error), compiled | {compiled:.1} |");
    println!("| the same, the 18 frames in lanes (`design::solve_frames_with`), compiled | {in_lanes:.1} |");
    println!("| the same with its 36 × 10 Jacobian (`design::gradient` at each frame), compiled | {with_jacobian:.1} |");
    println!("| the same through the library (`Design::prepare` + interpreter) | {interpreted:.1} |");
    // The two paths give the same error: the figure is of the same work.
    let (ec, ei) = (
        compiled_candidate(&a, &targets),
        interpreted_candidate(&library, &a, &targets),
    );
    assert!(
        (ec - ei).abs() <= 1e-9 * ei.max(1.0),
        "compiled {ec} and library {ei} differ"
    );
    assert_eq!(ec, compiled_candidate_with_jacobian(&a, &targets, &mut jacobian));
    assert_eq!(ec.to_bits(), compiled_candidate_in_lanes(&a, &targets).to_bits());
}

/// The batch table: per compiled plan, planar then spatial, its sweep (one
/// pass, a few hundred frames, whose poses stay in the caches) frame by
/// frame through the driver against `solve_batch` on one core (lanes of
/// frames for closed-form planar plans; a spatial plan's frames in order);
/// then the sweep repeated to 20,000 frames (poses written to main memory)
/// through `solve_batch` and `solve_batch_parallel` on every core. Medians
/// of alternating passes.
fn batch(filter: &[String]) {
    use dofplan_runtime::planar::Pose;
    use dofplan_runtime::spatial::Pose3;
    // `BATCH_LONG=N` for another length of the long run.
    let long_frames: usize = std::env::var("BATCH_LONG")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(20_000);
    let wanted = |n: &String| filter.is_empty() || filter.contains(n);
    println!();
    println!(
        "| mechanism | plan steps | lanes | sweep frames | driver ns/frame | solve_batch ns/frame (one core) | speed-up | {long_frames} frames: solve_batch ns/frame | solve_batch_parallel ns/frame ({} cores) |",
        std::thread::available_parallelism().map_or(1, |n| n.get())
    );
    println!("|---|---:|---|---:|---:|---:|---:|---:|---:|");
    for name in bundled().into_iter().filter(wanted) {
        let m = load(&name);
        let steps = plan(&m).steps.len();
        let sweep = sweep_inputs(&m, None);
        let row = dofplan_generated::with_plan!(name.as_str(), |plan| {
            time_batch(plan, Pose::IDENTITY, m.bodies.len(), &sweep, long_frames)
        })
        .expect("compiled");
        print_batch_row(&name, steps, sweep.len(), row);
    }
    for name in bundled_spatial().into_iter().filter(wanted) {
        let m = load_spatial(&name);
        let steps = analyse3(&m).expect("plans").steps.len();
        let s = m.sweep.as_ref().expect("a sweep");
        let sweep: Vec<Vec<f64>> = sweep_requests(s, m.inputs.len()).collect();
        let row = dofplan_generated::with_spatial_plan!(name.as_str(), |plan| {
            time_batch(plan, Pose3::IDENTITY, m.bodies.len(), &sweep, long_frames)
        })
        .expect("compiled");
        print_batch_row(&name, steps, sweep.len(), row);
    }
}

/// One row of the batch table.
fn print_batch_row(name: &str, steps: usize, frames: usize, ([c, b, long_b, par], lanes): ([f64; 4], bool)) {
    println!(
        "| {name} | {steps} | {} | {frames} | {c:.1} | {b:.1} | {:.2} | {long_b:.1} | {par:.1} |",
        if lanes { "yes" } else { "no (in order)" },
        c / b
    );
}

/// The batch table's four timings of one compiled plan (driver, one-core
/// batch of the sweep, one-core and parallel batches of `long_frames`
/// frames, ns/frame) and whether its frames run in lanes.
fn time_batch<P>(
    plan: P,
    identity: P::Pose,
    bodies: usize,
    sweep: &[Vec<f64>],
    long_frames: usize,
) -> ([f64; 4], bool)
where
    P: dofplan_runtime::Batch + Copy + Sync,
    P::Pose: Send,
{
    use dofplan_runtime::batch::solve_batch_parallel;
    use dofplan_runtime::FrameStatus;
    let long: Vec<Vec<f64>> = sweep.iter().cycle().take(long_frames).cloned().collect();
    let flat = |rows: &[Vec<f64>]| -> Vec<f64> { rows.iter().flatten().copied().collect() };
    let (short_in, long_in) = (flat(sweep), flat(&long));
    let mut driver = Driver::new(plan, Options::default());
    let mut out = vec![identity; long_frames * bodies];
    let mut status = vec![FrameStatus::Solved; long_frames];
    let short = sweep.len();
    // Sweeps repeated to about 5 ms a pass.
    let reps = (5e6 / (40.0 * (bodies * short) as f64)).max(1.0) as usize;
    let time = |frames: usize, reps: usize, f: &mut dyn FnMut()| {
        let t = Instant::now();
        for _ in 0..reps {
            f();
        }
        t.elapsed().as_secs_f64() * 1e9 / (frames * reps) as f64
    };
    // Warm up first: on this VM, memory the process has just been
    // given is slow to write for the first tens of milliseconds
    // (the first passes over the long run's 32 MB took twice the
    // later ones), which is not what a design study sees.
    let warm = Instant::now();
    while warm.elapsed().as_secs_f64() < 0.3 {
        plan.solve_batch(&short_in, &mut out[..short * bodies], &mut status[..short]);
        plan.solve_batch(&long_in, &mut out, &mut status);
    }
    let mut v: [Vec<f64>; 4] = Default::default();
    for _ in 0..11 {
        v[0].push(time(short, reps, &mut || {
            driver.reset();
            for i in sweep {
                black_box(driver.frame(black_box(i)));
            }
        }));
        v[1].push(time(short, reps, &mut || {
            plan.solve_batch(
                black_box(&short_in),
                &mut out[..short * bodies],
                &mut status[..short],
            )
        }));
        v[2].push(time(long_frames, 1, &mut || {
            plan.solve_batch(black_box(&long_in), &mut out, &mut status)
        }));
    }
    // The parallel runs after every one-core run: rayon's workers
    // spin a while after their work, and on a machine whose cores
    // share a physical core that slows the thread being timed.
    for _ in 0..11 {
        v[3].push(time(long_frames, 1, &mut || {
            solve_batch_parallel(&plan, black_box(&long_in), &mut out, &mut status)
        }));
    }
    (v.map(median), plan.independent())
}

/// The spatial table.
fn spatial(filter: &[String]) {
    let names: Vec<String> = bundled_spatial()
        .into_iter()
        .filter(|n| filter.is_empty() || filter.contains(n))
        .chain(spatial_fixtures().into_iter().filter(|n| filter.contains(n)))
        .collect();
    if names.is_empty() {
        return;
    }
    println!();
    println!(
        "| spatial mechanism | bodies | joints | equations | redundant rows | plan steps | cluster unknowns | compiled ns/frame | interpreted ns/frame | pure Newton µs/frame | Newton / compiled |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for name in &names {
        let m = load_spatial(name);
        let p = analyse3(&m).expect("plans");
        let c = count(&m);
        let s = m.sweep.as_ref().expect("a sweep");
        let inputs: Vec<Vec<f64>> = sweep_requests(s, m.inputs.len()).collect();
        let mut interpreted = Driver::new(
            dofplan::interp::spatial::Interpreter::new(p.clone()),
            Options::default(),
        );
        let (compiled, interp) = dofplan_generated::with_spatial_plan!(name.as_str(), |plan| {
            compare(
                &mut Driver::new(plan, Options::default()),
                &mut interpreted,
                &inputs,
                21,
            )
        })
        .expect("compiled");
        // Pure Newton on every frame of the sweep, warm-started. Its dense
        // SVD grows with the cube of the unknowns: beyond 60 bodies (360
        // unknowns) one sweep takes minutes, and the column says so, as
        // Figure 30 leaves its slowest cell blank.
        let (u, _) = p.cluster_size();
        let newton = if m.moving() <= 60 {
            let mut newton = Driver::new(
                dofplan::interp::spatial::Interpreter::new(pure_newton(&m)),
                Options::default(),
            );
            let passes = if m.moving() > 15 { 3 } else { 11 };
            let reps = reps_for(&mut newton, &inputs);
            let n = median((0..passes).map(|_| pass(&mut newton, &inputs, reps)).collect());
            (format!("{:.1}", n / 1e3), format!("{:.0}", n / compiled))
        } else {
            ("–".to_string(), "–".to_string())
        };
        println!(
            "| {name} | {} | {} | {} | {} | {} | {u} | {compiled:.0} | {interp:.0} | {} | {} |",
            c.moving,
            m.joints.len(),
            c.equations,
            c.redundant_equations,
            p.steps.len(),
            newton.0,
            newton.1
        );
    }
    // Plan + check of the stress chains (load excluded: what `check` adds
    // to reading the file), median of 11.
    println!();
    println!("| spatial chain | bodies | plan + check ms |");
    println!("|---|---:|---:|");
    for name in names.iter().filter(|n| n.starts_with("spatial_stress_")) {
        let m = load_spatial(name);
        let t: Vec<f64> = (0..11)
            .map(|_| {
                let t = Instant::now();
                black_box(analyse3(black_box(&m)).expect("plans"));
                black_box(count(black_box(&m)));
                t.elapsed().as_secs_f64() * 1e3
            })
            .collect();
        println!("| {name} | {} | {:.2} |", m.moving(), median(t));
    }
}

/// The planar table.
fn planar(filter: &[String]) {
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

/// Medians over `inputs` (ns/frame) of a frame alone, a frame then its
/// rates (`rates`, after the driver's frame), and both in one pass
/// (`solve_rates`, frames by hand under keep-branch and limit, as the
/// driver runs them), passes alternating; `None` when the plan gives no
/// rates at the sweep's first frame.
fn rate_costs<S: Solver + Copy, P>(
    plan: S,
    inputs: &[Vec<f64>],
    mut out: Vec<P>,
    rates: impl Fn(&S::State, &[f64], &mut [P]) -> bool,
    solve_rates: impl Fn(&mut S::State, &[f64], &mut dofplan_runtime::Ctx, &mut [P]) -> bool,
) -> Option<(f64, f64, f64)> {
    let mut d = Driver::new(plan, Options::default());
    let time = |d: &mut Driver<S>, out: &mut [P], with: bool, reps: usize| {
        d.reset();
        let t = Instant::now();
        for _ in 0..reps {
            for i in inputs {
                black_box(d.frame(black_box(i)));
                if with {
                    black_box(rates(d.state(), d.inputs(), out));
                }
            }
        }
        t.elapsed().as_secs_f64() * 1e9 / (reps * inputs.len()) as f64
    };
    let fused = |out: &mut [P], reps: usize| {
        let mut st = plan.initial_state();
        let t = Instant::now();
        for _ in 0..reps {
            for i in inputs {
                let mut ctx = dofplan_runtime::Ctx::new(Default::default(), false);
                black_box(solve_rates(&mut st, black_box(i), &mut ctx, out));
            }
        }
        t.elapsed().as_secs_f64() * 1e9 / (reps * inputs.len()) as f64
    };
    d.frame(&inputs[0]);
    if !rates(d.state(), d.inputs(), &mut out) {
        return None;
    }
    let per = time(&mut d, &mut out, true, 1) * 1e-9;
    let reps = ((5e-3 / per) as usize / inputs.len()).max(1);
    let (mut without, mut with, mut one) = (Vec::new(), Vec::new(), Vec::new());
    for _ in 0..21 {
        without.push(time(&mut d, &mut out, false, reps));
        with.push(time(&mut d, &mut out, true, reps));
        one.push(fused(&mut out, reps));
    }
    Some((median(without), median(with), median(one)))
}

/// The rates table: per compiled planar plan with a generated `rates`, a
/// frame's cost with its velocities and accelerations against without
/// (medians of alternating passes over the sweep, as above).
fn rates(filter: &[String]) {
    use dofplan_runtime::planar::Pose;
    use dofplan_runtime::real::{Jet2, Rates};
    let names: Vec<String> = bundled()
        .into_iter()
        .filter(|n| filter.is_empty() || filter.contains(n))
        .collect();
    println!();
    println!(
        "| mechanism | plan steps | compiled ns/frame | solve then rates ns/frame | ratio | solve_rates (one pass) ns/frame | ratio |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|");
    for name in names {
        let m = load(&name);
        let p = plan(&m);
        let inputs = sweep_inputs(&m, None);
        let n = m.inputs.len();
        let (r, a) = (vec![30.0; n], vec![0.0; n]);
        let row = dofplan_generated::with_plan!(name.as_str(), |plan| {
            rate_costs(
                plan,
                &inputs,
                vec![Pose::<Jet2>::cst(Pose::IDENTITY); m.bodies.len()],
                |st, i, out| plan.rates_into(st, i, &r, &a, out).is_ok(),
                |st, i, ctx, out| plan.solve_rates_into(st, i, &r, &a, ctx, out).is_ok(),
            )
        })
        .expect("compiled");
        if let Some((c, w, f)) = row {
            println!(
                "| {name} | {} | {c:.1} | {w:.1} | {:.2} | {f:.1} | {:.2} |",
                p.steps.len(),
                w / c,
                f / c
            );
        }
    }
    spatial_rates(filter);
}

/// The rates table's spatial rows: per compiled spatial plan with a
/// generated `rates` (not split into functions; the spatial fixtures too
/// when named, such as rps3's numeric cluster), a
/// frame's cost with its velocities and accelerations against without
/// (medians of alternating passes over the sweep, as above).
fn spatial_rates(filter: &[String]) {
    use dofplan_runtime::real::Jet2;
    use dofplan_runtime::real::Rates;
    use dofplan_runtime::spatial::Pose3;
    let names: Vec<String> = bundled_spatial()
        .into_iter()
        .filter(|n| filter.is_empty() || filter.contains(n))
        .chain(spatial_fixtures().into_iter().filter(|n| filter.contains(n)))
        .collect();
    if names.is_empty() {
        return;
    }
    println!();
    println!(
        "| spatial mechanism | plan steps | compiled ns/frame | solve then rates ns/frame | ratio | solve_rates (one pass) ns/frame | ratio |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|");
    for name in names {
        let m = load_spatial(&name);
        let p = analyse3(&m).expect("plans");
        let s = m.sweep.as_ref().expect("a sweep");
        let inputs: Vec<Vec<f64>> = sweep_requests(s, m.inputs.len()).collect();
        let n = m.inputs.len();
        let (r, a) = (vec![30.0; n], vec![0.0; n]);
        let row = dofplan_generated::with_spatial_plan!(name.as_str(), |plan| {
            rate_costs(
                plan,
                &inputs,
                vec![Pose3::<Jet2>::cst(Pose3::IDENTITY); m.bodies.len()],
                |st, i, out| plan.rates_into(st, i, &r, &a, out).is_ok(),
                |st, i, ctx, out| plan.solve_rates_into(st, i, &r, &a, ctx, out).is_ok(),
            )
        })
        .expect("compiled");
        match row {
            Some((c, w, f)) => println!(
                "| {name} | {} | {c:.1} | {w:.1} | {:.2} | {f:.1} | {:.2} |",
                p.steps.len(),
                w / c,
                f / c
            ),
            None => println!("| {name} | {} | – | – | – | – | – |", p.steps.len()),
        }
    }
}
