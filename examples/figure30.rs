//! Brunkhart's Figure 30, measured: for each row, the unknowns and
//! equations handed to Newton–Raphson and the time per frame, for pure
//! Newton (3 unknowns per mobile link, no analysis) and for dofplan's plan.
//!
//! `cargo run --release --example figure30`
//!
//! Rows whose mechanism is not bundled yet (6-bar (b), 8-bar, 10-bar,
//! Duplex) are listed as such.

use std::hint::black_box;
use std::time::Instant;

use dofplan::interp::Interpreter;
use dofplan::load_file;
use dofplan::numeric::planar::drag::Drag;
use dofplan::numeric::PureNewton;
use dofplan::simulate::sweep_inputs;
use dofplan_runtime::{Driver, Options, Solver};
use dofplan_tests::{load, mechanisms_dir, plan};

/// Median µs per frame over `passes` sweeps of `inputs` (each pass stops
/// early after `budget` seconds, so pure Newton on large rows stays quick).
fn us_per_frame<S: Solver>(driver: &mut Driver<S>, inputs: &[Vec<f64>], passes: usize, budget: f64) -> f64 {
    let mut samples: Vec<f64> = (0..passes)
        .map(|_| {
            driver.reset();
            let t = Instant::now();
            let mut n = 0;
            for i in inputs {
                black_box(driver.frame(black_box(i)));
                n += 1;
                // Reading the clock costs as much as a compiled frame: only
                // every 64 frames.
                if n % 64 == 0 && t.elapsed().as_secs_f64() > budget {
                    break;
                }
            }
            t.elapsed().as_secs_f64() * 1e6 / n as f64
        })
        .collect();
    samples.sort_by(f64::total_cmp);
    samples[samples.len() / 2]
}

fn main() {
    // (row, bundled file, 1994 Newton fps, 1994 Mixed fps)
    let rows: [(&str, Option<&str>, &str, &str); 16] = [
        ("4-bar", Some("fourbar"), "370", "2875"),
        ("6-bar (a)", Some("sixbar_a"), "81", "1711"),
        ("Stress-10", Some("stress_10"), "14", "968"),
        ("Stress-20", Some("stress_20"), "0.3", "445"),
        ("Stress-30", Some("stress_30"), "0.07", "282"),
        ("Stress-40", Some("stress_40"), "≈0.02", "222"),
        ("Stress-50", Some("stress_50"), "–", "176"),
        ("6-bar (b)", Some("sixbar_b"), "85", "339"),
        ("8-bar", Some("eightbar"), "32", "86"),
        ("10-bar", Some("tenbar"), "5.1", "42"),
        ("Duplex", Some("duplex"), "2.9", "17"),
        ("Chain-4", Some("chain_4"), "140", "448"),
        ("Chain-6", Some("chain_6"), "55", "122"),
        ("Chain-8", Some("chain_8"), "23", "45"),
        ("Chain-10", Some("chain_10"), "10", "20"),
        ("Chain-15", Some("chain_15"), "0.8", "1.0"),
    ];
    println!(
        "| mechanism | mobile links | active joints | Newton unk/eqs | Newton µs/frame | mixed unk/eqs | \
         mixed µs/frame compiled | mixed µs/frame interpreted | Newton ÷ compiled | 1994 Newton fps | 1994 mixed fps |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
    for (row, file, newton94, mixed94) in rows {
        let Some(name) = file else {
            println!("| {row} | | | | not bundled yet | | | | | {newton94} | {mixed94} |");
            continue;
        };
        let m = load(name);
        let p = plan(&m);
        let (mu, me) = p.numeric_size();
        let inputs = sweep_inputs(&m, None);
        let mobile = m.bodies.iter().filter(|b| !b.fixed).count() - m.inputs.len();
        let joints = m.joints.len() - m.inputs.len();
        let newton = PureNewton::new(&m);
        let (nu, ne) = (newton.unknowns(), newton.equations());
        // Pure Newton on the large rows takes tens of ms per frame: time a
        // prefix of the sweep (at least 64 frames), three passes.
        let t_newton = us_per_frame(&mut Driver::new(newton, Options::default()), &inputs, 3, 0.5);
        let t_compiled = dofplan_generated::with_plan!(name, |plan| {
            us_per_frame(&mut Driver::new(plan, Options::default()), &inputs, 31, 1.0)
        })
        .expect("compiled");
        let t_interp = us_per_frame(
            &mut Driver::new(Interpreter::new(p), Options::default()),
            &inputs,
            31,
            1.0,
        );
        println!(
            "| {row} ({name}) | {mobile} | {joints} | {nu}/{ne} | {t_newton:.1} | {mu}/{me} | {t_compiled:.3} | {t_interp:.3} | {:.0}× | {newton94} | {mixed94} |",
            t_newton / t_compiled
        );
    }

    drag_row();
}

/// The open chain of 15 links pinned at one end and dragged by the other
/// along a straight path (800 targets there and back, each a small step as
/// a mouse makes), planned like an input and by task-priority pure Newton.
fn drag_row() {
    let m = load_file(&mechanisms_dir().join("drag/open_chain_15.toml")).expect("bundled");
    let end = m.find_marker("link_15.E").expect("bundled");
    let from = m.marker(end).at;
    let to = [6.0, 8.0];
    let targets: Vec<Vec<f64>> = (0..800)
        .map(|i| {
            let t = f64::from(if i < 400 { i } else { 799 - i }) / 399.0;
            vec![from[0] + t * (to[0] - from[0]), from[1] + t * (to[1] - from[1])]
        })
        .collect();
    let planned = Drag::new(&m, end).expect("mobile");
    let (u, e) = planned.planned().expect("an open chain has DOF to spare");
    let newton = Drag::unplanned(&m, end).expect("mobile");
    let (nu, ne) = (newton.unknowns(), newton.equations());
    let t_newton = us_per_frame(&mut Driver::new(newton, Options::default()), &targets, 3, 2.0);
    let t_planned = us_per_frame(&mut Driver::new(planned, Options::default()), &targets, 31, 1.0);
    // The compiled drag takes the target as offsets from the drawn end.
    let slides: Vec<Vec<f64>> = targets
        .iter()
        .map(|t| vec![t[0] - from[0], t[1] - from[1]])
        .collect();
    let compiled = dofplan_generated::open_chain_15_drag_link_15_e::Plan;
    let t_compiled = us_per_frame(&mut Driver::new(compiled, Options::default()), &slides, 31, 1.0);
    println!();
    println!(
        "| drag | Newton unk/eqs | Newton µs/frame | planned unk/eqs | planned µs/frame compiled | planned µs/frame \
         interpreted (library `Drag`) | Newton ÷ compiled |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|");
    println!(
        "| open chain of 15 links by its end | {nu}/{ne} | {t_newton:.1} | {u}/{e} | {t_compiled:.3} | {t_planned:.3} | {:.0}× |",
        t_newton / t_compiled
    );
}
