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
    let m = dofplan::model::load_file(&fixture).unwrap_or_else(|e| panic!("{e}"));
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
        let functions = split.matches("\n#[inline(never)]\nfn step").count();
        assert!(
            functions >= p.steps.len() / 3 && functions > 1,
            "{module}: {functions} functions for {} steps",
            p.steps.len()
        );
    }
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
                    let d = (a.at[0] - b.at[0])
                        .abs()
                        .max((a.at[1] - b.at[1]).abs())
                        .max((a.rot.c - b.rot.c).abs())
                        .max((a.rot.s - b.rot.s).abs());
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
