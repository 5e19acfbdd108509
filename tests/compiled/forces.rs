//! Compiled `solve_forces` (`Config::forces`): a frame's positions, rates
//! and forces in one pass, against the interpreter's reactions
//! (`forces::planar::reactions`) and virtual work's input forces (another
//! path, the plan's rates), held still and running, on every planar file
//! with loads (a pin in an arc slot's force included) and on the geared
//! hoist (a tooth force that leans by its sign); and its emitted module,
//! snapshotted.

use dofplan::forces::planar::{describe, force_plan, input_forces, reactions, runtime_blocks, Moving};
use dofplan::interp::Interpreter;
use dofplan::simulate::{sweep_rates, sweep_requests};
use dofplan_runtime::planar::Pose;
use dofplan_runtime::real::Jet2;
use dofplan_runtime::{Ctx, Driver, Options};
use dofplan_tests::{load, plan};

/// The largest difference between the compiled and the interpreted
/// forces over the sweep, relative to the largest force, with how many
/// frames were compared; `running`: rate and acceleration of the first
/// input (rad/s, rad/s²), None held still.
macro_rules! agreement {
    ($module:ident, $name:expr, $running:expr) => {{
        use dofplan_generated::$module as compiled;
        let m = load($name);
        let forces_plan = force_plan(&m).unwrap();
        let interp = Interpreter::new(plan(&m));
        let mut d = Driver::new(interp.clone(), Options::default());
        let sweep = m.sweep.clone().unwrap();
        let running: Option<(f64, f64)> = $running;
        let (rates, accelerations) = match running {
            Some((w, a)) => (sweep_rates(&m, &sweep, w), sweep_rates(&m, &sweep, a)),
            None => (vec![0.0; m.inputs.len()], vec![0.0; m.inputs.len()]),
        };
        let mut state = compiled::State::DRAWN;
        let (mut worst, mut scale, mut frames) = (0.0f64, 0.0f64, 0);
        for requested in sweep_requests(&sweep, m.inputs.len()) {
            assert!(d.frame(&requested).is_solved(), "{}", $name);
            let jets: Option<Vec<Pose<Jet2>>> = running.map(|_| {
                interp
                    .rates(d.state(), d.inputs(), &rates, &accelerations)
                    .unwrap()
            });
            let r = reactions(&m, &forces_plan, d.poses(), jets.as_deref()).unwrap();
            let mut out = compiled::forces::Forces::default();
            let mut ctx = Ctx::new(Default::default(), false);
            compiled::forces::solve_forces(
                &mut state,
                &requested,
                &rates,
                &accelerations,
                &mut ctx,
                &mut out,
            )
            .unwrap_or_else(|e| panic!("{} at {requested:?}: {e:?}", $name));
            // Virtual work's input forces: the plan's rates, not the
            // bodies' equilibrium.
            let moving = running.map(|_| Moving {
                rates: &rates,
                accelerations: &accelerations,
            });
            let q = input_forces(&m, d.solver(), d.state(), d.inputs(), moving).unwrap();
            for (i, (&got, &want)) in out.inputs.iter().zip(&q).enumerate() {
                assert!(
                    (got - want).abs() <= 1e-9 * want.abs().max(1.0),
                    "{} input {i}: {got} against virtual work's {want}",
                    $name
                );
            }
            let pairs = (out.reactions.iter().flatten().zip(r.forces.iter().flatten()))
                .chain(out.moments.iter().zip(&r.moments))
                .chain(out.inputs.iter().zip(&r.inputs))
                .chain(out.slots.iter().flatten().zip(r.slots.iter().flatten()))
                .chain(out.teeth.iter().flatten().zip(r.teeth.iter().flatten()))
                .chain(out.shaking.iter().zip(&r.shaking));
            assert_eq!(out.slots.len(), r.slots.len(), "{}: a place per slot", $name);
            assert_eq!(out.teeth.len(), r.teeth.len(), "{}: a place per gear pair", $name);
            for (a, b) in pairs {
                worst = worst.max((a - b).abs());
                scale = scale.max(b.abs());
            }
            frames += 1;
        }
        (worst / scale, frames)
    }};
}

#[test]
fn compiled_forces_are_the_interpreter_s_held_and_running() {
    for running in [None, Some((2.0, 0.0)), Some((2.0, -7.0))] {
        let (fourbar, n) = agreement!(fourbar_weights, "loads/fourbar_weights", running);
        assert_eq!(n, 361);
        assert!(fourbar < 1e-12, "fourbar_weights {running:?}: {fourbar:e}");
        let (slider, n) = agreement!(slider_crank_press, "loads/slider_crank_press", running);
        assert_eq!(n, 361);
        assert!(slider < 1e-12, "slider_crank_press {running:?}: {slider:e}");
        let (arc, n) = agreement!(arc_yoke_press, "loads/arc_yoke_press", running);
        assert_eq!(n, 361);
        assert!(arc < 1e-12, "arc_yoke_press {running:?}: {arc:e}");
    }
}

/// The hoist's tooth force turns with the drum's load: where the pinion
/// drives the drum one way the teeth lean by the pressure angle one way,
/// where the drum drives back the other (the frame solved again, leaned).
/// Compiled and interpreted agree on every frame, and the tooth force
/// lies along the line of action that pushes the gears apart: 20° off
/// the common tangent (the vertical at the pitch point), its x part
/// pushing the drum (right of the pinion) away.
#[test]
fn compiled_forces_lean_the_teeth_by_the_sign_of_their_force() {
    for running in [None, Some((2.0, 0.0)), Some((2.0, -7.0))] {
        let (hoist, n) = agreement!(geared_hoist, "gears/geared_hoist", running);
        assert_eq!(n, 217);
        assert!(hoist < 1e-12, "geared_hoist {running:?}: {hoist:e}");
    }
    use dofplan_generated::geared_hoist as compiled;
    let (mut up, mut down) = (0, 0);
    let mut state = compiled::State::DRAWN;
    for k in 0..=216 {
        let theta = 5.0 * k as f64;
        let mut out = compiled::forces::Forces::default();
        let mut ctx = Ctx::new(Default::default(), false);
        compiled::forces::solve_forces(&mut state, &[theta], &[0.0], &[0.0], &mut ctx, &mut out).unwrap();
        let [fx, fy] = out.teeth[0];
        if fy.abs() < 1e-9 {
            continue;
        }
        // Along the line of action: |fx| = |fy| tan 20°, fx > 0 (the drum
        // pushed away from the pinion) whichever way fy points.
        let lean = (fx.abs() - fy.abs() * 20f64.to_radians().tan()).abs();
        assert!(lean <= 1e-9 * fy.abs(), "theta {theta}: {fx} {fy}");
        assert!(fx > 0.0, "theta {theta}: the teeth pull ({fx})");
        if fy > 0.0 {
            up += 1;
        } else {
            down += 1;
        }
    }
    assert!(up > 20 && down > 20, "both ways: {up} up, {down} down");
}

/// The emitted module of a planar file with loads: its `forces` module as
/// the build appends it.
fn forces_source(name: &str) -> String {
    let m = load(name);
    let forces_plan = force_plan(&m).unwrap();
    let described = describe(&m);
    let blocks = runtime_blocks(&forces_plan);
    dofplan::emit::emit_forces(&plan(&m), &described.table(&blocks), m.slots.len()).unwrap()
}

#[test]
fn the_forces_module_is_snapshotted_and_compiled_as_it_is() {
    let code = forces_source("loads/fourbar_weights");
    let mut s = insta::Settings::clone_current();
    s.set_prepend_module_to_snapshot(false);
    s.set_omit_expression(true);
    s.bind(|| insta::assert_snapshot!("forces_fourbar_weights", code));
    for (name, module) in [
        ("loads/fourbar_weights", "fourbar_weights"),
        ("loads/slider_crank_press", "slider_crank_press"),
    ] {
        let m = load(name);
        let expected = dofplan::emit::emit(&plan(&m)) + &forces_source(name);
        assert_eq!(
            dofplan_generated::source(module).expect("compiled"),
            expected,
            "{name}: dofplan-generated is stale"
        );
    }
}

#[test]
fn an_over_constrained_file_gets_no_compiled_forces_and_is_told_why() {
    // The V-linkage: its redundant pins' reactions need least squares.
    let m = load("vlink");
    let forces_plan = force_plan(&m).unwrap();
    let described = describe(&m);
    let blocks = runtime_blocks(&forces_plan);
    let err = dofplan::emit::emit_forces(&plan(&m), &described.table(&blocks), m.slots.len()).unwrap_err();
    assert!(err.contains("least squares"), "{err}");
}
