//! The split form of large plans (`dofplan::emit` gives a plan too large
//! for one function several functions over a working copy of the state):
//! `dofplan-generated` compiles every mechanism a second time in that form,
//! two or three steps per function, and it must give the very numbers of
//! the one-function form and of the interpreter, frame for frame, under
//! every policy, and leave the state untouched on a break.

use dofplan::interp::Interpreter;
use dofplan::simulate::sweep_inputs;
use dofplan_runtime::{BranchPolicy, Ctx, Driver};
use dofplan_tests::{all_options, bundled, load, plan};

/// The bundled mechanisms and the test fixtures, by module name and file.
fn mechanisms() -> Vec<(String, dofplan::model::Mechanism)> {
    let mut out: Vec<_> = bundled()
        .into_iter()
        .map(|name| {
            let m = load(&name);
            (dofplan::emit::ident_for(&m.name), m)
        })
        .collect();
    let fixture = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/sixbar_slotted.toml");
    let m = dofplan::load_file(&fixture).unwrap_or_else(|e| panic!("{e}"));
    out.push((dofplan::emit::ident_for(&m.name), m));
    out
}

#[test]
fn every_mechanism_is_split_into_several_functions() {
    for (module, m) in mechanisms() {
        let p = plan(&m);
        let one = dofplan::emit::emit(&p);
        let split = dofplan::emit::emit_chunked(&p, 150);
        assert!(
            !one.contains("struct Working"),
            "{module}: one function by default"
        );
        let functions = split.matches("\nmod step").count();
        // Steps of a rolled run (see `tests/compiled/rolled.rs`) are one function,
        // its loop, whatever their number.
        let rolled_steps: usize = rolled_runs(&split).iter().map(|r| r.len()).sum();
        assert!(
            functions > 1 && functions >= (p.steps.len() - rolled_steps) / 3,
            "{module}: {functions} functions for {} steps, {rolled_steps} of them rolled",
            p.steps.len()
        );
        // The bundled stress mechanisms are a loop repeated: their split
        // form is rolled, so the tests below check rolled code too.
        if module.starts_with("stress_") {
            assert!(
                rolled_steps >= p.steps.len() / 2,
                "{module}: {rolled_steps} steps rolled"
            );
        }
    }
}

/// The steps of each rolled run of a split module's `solve` (from the doc
/// comments of their loops: "Steps A to B: the P steps of the loop …").
fn rolled_runs(split: &str) -> Vec<std::ops::Range<usize>> {
    let mut runs: Vec<std::ops::Range<usize>> = split
        .lines()
        .filter_map(|l| l.trim_start().strip_prefix("/// Steps "))
        .filter_map(|l| l.split_once(": the ").map(|(range, _)| range))
        .filter_map(|range| range.split_once(" to "))
        .map(|(a, b)| a.parse::<usize>().unwrap()..b.parse::<usize>().unwrap() + 1)
        .collect();
    // Once for `solve`, once for `solve_rates`.
    runs.sort_by_key(|r| r.start);
    runs.dedup();
    runs
}

#[test]
fn split_and_whole_compiled_plans_and_the_interpreter_agree_on_every_frame() {
    for (module, m) in mechanisms() {
        let requested = sweep_inputs(&m, None);
        for options in all_options() {
            let mut split = dofplan_generated::chunked::driver(&module, options)
                .unwrap_or_else(|| panic!("{module} is not in dofplan_generated::chunked"));
            let mut whole = dofplan_generated::driver(&module, options).expect("compiled");
            let mut interpreted = Driver::new(Interpreter::new(plan(&m)), options);
            for (i, inputs) in requested.iter().enumerate() {
                let status = split.frame(inputs);
                assert_eq!(status, whole.frame(inputs), "{module} frame {i} {options:?}");
                assert_eq!(
                    status,
                    interpreted.frame(inputs),
                    "{module} frame {i} {options:?}"
                );
                // The same runtime calls in the same order: equal to the bit.
                assert_eq!(split.poses(), whole.poses(), "{module} frame {i} {options:?}");
                assert_eq!(split.inputs(), whole.inputs(), "{module} frame {i} {options:?}");
                for (a, b) in split.poses().iter().zip(interpreted.poses()) {
                    let d = dofplan_tests::pose_gap(a, b);
                    assert!(
                        d <= 1e-12,
                        "{module} frame {i}: split and interpreted differ by {d:e}"
                    );
                }
            }
        }
    }
}

/// rocker_rocker assembles only between about -105° and 45°: the plan breaks at a
/// circle intersection after earlier functions have written the working
/// copy, and the state is left exactly as it was.
#[test]
fn a_break_in_a_later_function_leaves_the_state_as_it_was() {
    use dofplan_generated::chunked::rocker_rocker as split;
    let mut s = split::State::DRAWN;
    let mut ctx = Ctx::new(BranchPolicy::Keep, false);
    split::solve(&mut s, &[-30.0], &mut ctx).expect("-30° is reachable");
    let before = s;
    let err = split::solve(&mut s, &[120.0], &mut ctx).expect_err("120° is out of reach");
    assert!(err.step > 0, "the break is not in the first step: {err:?}");
    assert_eq!(s, before);
}

/// The split form has rates too: its `solve_rates`, the same chunks written
/// on jets, gives the one-function form's frames and jets to the bit (the
/// same operations in the same order), through numeric clusters too, and
/// so does its `rates`; on a break both leave the state as it was.
#[test]
fn split_and_whole_rates_agree_to_the_bit() {
    use dofplan_runtime::real::RateError;
    let mut covered = Vec::new();
    macro_rules! check {
        ($($module:ident),* $(,)?) => {$({
            use dofplan_generated::chunked::$module as split;
            use dofplan_generated::$module as whole;
            let module = stringify!($module);
            let (_, m) = mechanisms().into_iter().find(|(n, _)| n == module).expect("a mechanism");
            let requested = sweep_inputs(&m, None);
            let n = m.inputs.len();
            let rates: Vec<f64> = (0..n).map(|k| 20.0 - 3.0 * k as f64).collect();
            let accels: Vec<f64> = (0..n).map(|k| 1.5 + k as f64).collect();
            let (mut s1, mut s2) = (split::State::DRAWN, whole::State::DRAWN);
            let mut solved = 0;
            for (i, u) in requested.iter().enumerate() {
                let before = s1;
                let mut ctx = Ctx::new(BranchPolicy::Keep, false);
                let a = split::solve_rates(&mut s1, u, &rates, &accels, &mut ctx);
                if let Err(RateError::Break(_)) = a {
                    assert_eq!(s1, before, "{module} frame {i}: a break leaves the state");
                }
                let mut ctx = Ctx::new(BranchPolicy::Keep, false);
                let b = whole::solve_rates(&mut s2, u, &rates, &accels, &mut ctx);
                assert_eq!(a, b, "{module} frame {i}");
                assert_eq!(
                    (s1.poses, s1.last, s1.branches),
                    (s2.poses, s2.last, s2.branches),
                    "{module} frame {i}"
                );
                assert_eq!(
                    split::rates(&s1, u, &rates, &accels),
                    whole::rates(&s2, u, &rates, &accels),
                    "{module} frame {i}"
                );
                solved += usize::from(matches!(a, Ok(_) | Err(RateError::Singular)));
            }
            assert!(solved * 3 >= requested.len(), "{module}: {solved} frames");
            covered.push(module.to_string());
        })*};
    }
    check!(
        chain_10,
        chain_15,
        chain_4,
        chain_6,
        chain_8,
        duplex,
        eightbar,
        fourbar,
        inverted_slider_crank,
        jansen,
        pantograph,
        parallelogram,
        peaucellier,
        rocker_rocker,
        sixbar_a,
        sixbar_b,
        slider_crank,
        stress_10,
        stress_20,
        stress_30,
        stress_40,
        stress_50,
        table,
        tenbar,
        trammel,
        vlink,
        sixbar_slotted,
    );
    let mut all: Vec<String> = mechanisms().into_iter().map(|(n, _)| n).collect();
    all.sort();
    covered.sort();
    assert_eq!(covered, all, "every mechanism");
}
