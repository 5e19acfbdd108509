//! Large plans rolled into loops (`dofplan::emit`, `emit/planar/roll.rs`): a
//! stress chain's repeated steps become one loop over a table of their
//! numbers. The compiled chains of the user guide's scaling table
//! ("Plan time by size" in docs/guide/performance.md;
//! `dofplan_generated::chains`, 10 to 2,000 loops, compiled as a user's
//! build.rs compiles them) give the interpreter's frames, every joint
//! held, under every policy; and the code of a chain's module does not
//! grow with the chain, only its table does.

use dofplan::analysis::analyse;
use dofplan::emit::emit;
use dofplan::interp::Interpreter;
use dofplan::load_str;
use dofplan::model::{Format, Mechanism};
use dofplan::plan::Plan;
use dofplan::simulate::{max_relative_residual, sweep_inputs};
use dofplan_runtime::Driver;
use dofplan_tests::all_options;
use dofplan_tests::stress::stress_chain;

fn chain(loops: usize) -> (Mechanism, Plan) {
    let m = load_str("chain.toml", &stress_chain(loops), Format::Toml).unwrap_or_else(|e| panic!("{e}"));
    let plan = analyse(&m).plan.expect("a stress chain plans");
    (m, plan)
}

#[test]
fn compiled_chains_of_every_size_agree_with_the_interpreter_and_hold_every_joint() {
    for loops in dofplan_generated::chains::LOOPS {
        let (m, plan) = chain(loops);
        // Every 10° of the sweep's turn, and back: the keep-branch and
        // nearest policies then see frames that follow each other.
        let turn: Vec<Vec<f64>> = sweep_inputs(&m, None).into_iter().step_by(10).collect();
        let requested: Vec<Vec<f64>> = turn.iter().chain(turn.iter().rev()).cloned().collect();
        for options in all_options() {
            let mut compiled = dofplan_generated::chains::driver(loops, options).expect("compiled");
            let mut interpreted = Driver::new(Interpreter::new(plan.clone()), options);
            for (i, inputs) in requested.iter().enumerate() {
                let status = compiled.frame(inputs);
                assert_eq!(
                    status,
                    interpreted.frame(inputs),
                    "{loops} loops, frame {i} {options:?}"
                );
                assert!(status.is_solved(), "{loops} loops, frame {i}: {}", status.name());
                let r = max_relative_residual(&m, compiled.poses(), inputs);
                assert!(r <= 1e-9, "{loops} loops, frame {i}: relative residual {r:e}");
                for (b, (a, c)) in compiled.poses().iter().zip(interpreted.poses()).enumerate() {
                    let d = dofplan_tests::pose_gap(a, c);
                    assert!(
                        d <= 1e-12,
                        "{loops} loops, frame {i}, body {b}: compiled and interpreted differ by {d:e}"
                    );
                }
            }
        }
    }
}

/// The lines of the functions that run the steps (the modules `steps_…`
/// of `solve` and `rates_steps_…` of `solve_rates`) but the rows of their
/// tables, with digits (step numbers, row counts) taken out. The rest of
/// the module is data that grows with the chain by nature: the drawn
/// state, the names of bodies and markers.
fn code_lines(module: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut inside = false;
    for line in module.lines() {
        if line.starts_with("mod steps_") || line.starts_with("mod rates_steps_") {
            inside = true;
        }
        if inside && !line.trim_start().starts_with("Row { f: [") {
            out.push(line.chars().filter(|c| !c.is_ascii_digit()).collect());
        }
        if inside && line == "}" {
            inside = false;
        }
    }
    out
}

#[test]
fn a_long_chain_is_one_loop_over_a_table_whose_code_does_not_grow_with_it() {
    let modules: Vec<(usize, String)> = [1000, 2000].map(|n| (n, emit(&chain(n).1))).into();
    for (loops, module) in &modules {
        // Steps 0 and 1 place the crank; the 3 steps of each loop repeat.
        let last = 3 * loops + 1;
        let tables: Vec<&str> = module.lines().filter(|l| l.contains("static ROWS")).collect();
        assert_eq!(
            tables,
            [format!("    pub(super) static ROWS: [Row; {loops}] = [").as_str()],
            "{loops} loops: one table, a row a loop"
        );
        assert_eq!(module.matches("\n        Row { f: [").count(), *loops);
        // `solve_rates` runs the same loop on jets over the same table.
        assert!(
            module.contains(&format!("mod steps_2_to_{last} {{"))
                && module.contains(&format!("mod rates_steps_2_to_{last} {{"))
                && module.contains(&format!("use super::steps_2_to_{last}::ROWS;")),
            "{loops} loops: steps 2 to {last} rolled for values and jets"
        );
        assert_eq!(
            module
                .matches("for row in core::hint::black_box(&ROWS) {")
                .count(),
            2
        );
    }
    // The code that runs a frame is the same for 2,000 loops as for 1,000:
    // only the table grows.
    let (short, long) = (code_lines(&modules[0].1), code_lines(&modules[1].1));
    assert!(short.len() > 100, "{} lines of step code", short.len());
    assert_eq!(short, long);
}
