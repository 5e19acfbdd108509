//! A compiled frame allocates nothing — nor does an interpreted one once
//! its buffers exist — under every breaking policy. Counted by a global
//! allocator that counts only on the thread and span being measured.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use dofplan::interp::Interpreter;
use dofplan::simulate::{sweep_inputs, sweep_requests};
use dofplan_runtime::{Driver, Options, Solver};
use dofplan_tests::{all_options, load, load_spatial, plan};

struct Counting;

thread_local! {
    static ARMED: Cell<bool> = const { Cell::new(false) };
    static COUNT: Cell<usize> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if ARMED.with(Cell::get) {
            COUNT.with(|c| c.set(c.get() + 1));
        }
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if ARMED.with(Cell::get) {
            COUNT.with(|c| c.set(c.get() + 1));
        }
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations made while running `f` on this thread.
fn allocations(f: impl FnOnce()) -> usize {
    COUNT.with(|c| c.set(0));
    ARMED.with(|a| a.set(true));
    f();
    ARMED.with(|a| a.set(false));
    COUNT.with(Cell::get)
}

/// Drives `solver` through `inputs` and counts allocations in the frames.
fn frame_allocations<S: Solver>(solver: S, options: Options, inputs: &[Vec<f64>]) -> usize {
    let mut driver = Driver::new(solver, options);
    allocations(|| {
        for i in inputs {
            std::hint::black_box(driver.frame(i));
        }
    })
}

#[test]
fn the_counter_counts() {
    // A test that cannot fail proves nothing: make sure an allocation in
    // the measured span is seen.
    assert_eq!(allocations(|| drop(std::hint::black_box(vec![1u8; 10]))), 1);
}

#[test]
fn compiled_frames_allocate_nothing() {
    for options in all_options() {
        let fourbar = sweep_inputs(&load("fourbar"), None);
        assert_eq!(
            frame_allocations(dofplan_generated::fourbar::Plan, options, &fourbar),
            0
        );
        let rocker = sweep_inputs(&load("rocker_rocker"), None);
        assert_eq!(
            frame_allocations(dofplan_generated::rocker_rocker::Plan, options, &rocker),
            0
        );
        let stress = sweep_inputs(&load("stress_50"), None);
        assert_eq!(
            frame_allocations(dofplan_generated::stress_50::Plan, options, &stress),
            0
        );
        let trammel = sweep_inputs(&load("trammel"), None);
        assert_eq!(
            frame_allocations(dofplan_generated::trammel::Plan, options, &trammel),
            0
        );
    }
}

/// Numeric clusters are emitted as straight-line code over fixed-size
/// matrices: their Newton solves (Cholesky or SVD steps, line search) run
/// on the stack.
#[test]
fn compiled_cluster_frames_allocate_nothing() {
    macro_rules! check {
        ($($name:ident),*) => {$(
            let inputs = sweep_inputs(&load(stringify!($name)), None);
            for options in all_options() {
                let n = frame_allocations(dofplan_generated::$name::Plan, options, &inputs);
                assert_eq!(n, 0, "{} {options:?}", stringify!($name));
            }
        )*};
    }
    check!(sixbar_b, eightbar, tenbar, duplex, chain_4, chain_15);

    // The compiled drag of the open chain, along a straight pull.
    let pull: Vec<Vec<f64>> = (0..=100)
        .map(|i| vec![-0.05 * f64::from(i), 0.06 * f64::from(i)])
        .collect();
    for options in all_options() {
        let drag = dofplan_generated::open_chain_15_drag_link_15_e::Plan;
        assert_eq!(frame_allocations(drag, options, &pull), 0, "drag {options:?}");
    }

    // A full turn takes sixbar_b past its dead points: the frames there end
    // at a least-squares point (SVD steps, damped line search) and break or
    // stretch, and still allocate nothing.
    let turn: Vec<Vec<f64>> = (0..=36).map(|i| vec![f64::from(i) * 10.0]).collect();
    for options in all_options() {
        let mut driver = Driver::new(dofplan_generated::sixbar_b::Plan, options);
        let statuses: Vec<_> = turn.iter().map(|i| driver.frame(i)).collect();
        assert!(
            statuses.iter().any(|s| !s.is_solved()),
            "{options:?}: no frame broke"
        );
        assert_eq!(
            frame_allocations(dofplan_generated::sixbar_b::Plan, options, &turn),
            0,
            "{options:?}"
        );
    }
}

/// The split form of large plans (a working copy of the state, one
/// function per run of steps): every mechanism again, compiled with two or
/// three steps per function.
#[test]
fn split_compiled_frames_allocate_nothing() {
    macro_rules! check {
        ($($name:ident),*) => {$(
            let inputs = sweep_inputs(&load(stringify!($name)), None);
            for options in all_options() {
                let n = frame_allocations(dofplan_generated::chunked::$name::Plan, options, &inputs);
                assert_eq!(n, 0, "{} {options:?}", stringify!($name));
            }
        )*};
    }
    check!(
        fourbar,
        rocker_rocker,
        stress_50,
        trammel,
        sixbar_b,
        chain_15,
        duplex
    );
}

/// The frames of a bundled spatial mechanism's sweep, then (`overreach`)
/// the sweep run three times as far backwards from its end, where frames
/// break: the Stewart platform's legs grow too short for it, and its
/// numeric cluster ends at least-squares points (SVD steps, damped line
/// search).
fn spatial_inputs(name: &str, overreach: bool) -> Vec<Vec<f64>> {
    let m = load_spatial(name);
    let mut sweep = m.sweep.clone().expect("every bundled file has a sweep");
    let mut out: Vec<Vec<f64>> = sweep_requests(&sweep, m.inputs.len()).collect();
    if !overreach {
        return out;
    }
    sweep.steps = sweep.steps.min(61);
    for s in &mut sweep.inputs {
        (s.from, s.to) = (s.to, s.to - 4.0 * (s.to - s.from));
    }
    out.extend(sweep_requests(&sweep, m.inputs.len()));
    out
}

/// Compiled spatial plans keep state in fixed-size arrays and solve a
/// numeric cluster (the Stewart platform's) over fixed-size matrices: no
/// frame allocates, under any policy, also where frames break.
#[test]
fn compiled_spatial_frames_allocate_nothing() {
    macro_rules! check {
        ($overreach:expr; $($name:ident),*) => {$(
            let inputs = spatial_inputs(stringify!($name), $overreach);
            for options in all_options() {
                let n = frame_allocations(dofplan_generated::$name::Plan, options, &inputs);
                assert_eq!(n, 0, "{} {options:?}", stringify!($name));
                let n = frame_allocations(dofplan_generated::chunked::$name::Plan, options, &inputs);
                assert_eq!(n, 0, "{} split {options:?}", stringify!($name));
            }
        )*};
    }
    check!(
        true;
        bennett,
        cardan,
        double_cardan,
        excavator,
        rssr,
        sofa_bed,
        spherical_fourbar,
        stewart,
        tilted_fourbar,
        // The fixtures: the other loci steps...
        puck,
        rssp,
        yoke
    );
    // ... and clusters of equation rows, along their sweeps (a debug
    // build's bisections over a 27-unknown cluster that breaks take long).
    check!(false; rps3, rps3_mixed);
    let inputs = spatial_inputs("spatial_stress_10", true);
    for options in all_options() {
        let n = frame_allocations(dofplan_generated::spatial_stress_10::Plan, options, &inputs);
        assert_eq!(n, 0, "spatial_stress_10 {options:?}");
    }

    // The Stewart platform's cluster did break on the way back, and did
    // run Newton.
    let stewart = spatial_inputs("stewart", true);
    for options in all_options() {
        let mut driver = Driver::new(dofplan_generated::stewart::Plan, options);
        let statuses: Vec<_> = stewart.iter().map(|i| driver.frame(i)).collect();
        assert!(
            statuses.iter().any(|s| !s.is_solved()),
            "{options:?}: no frame broke"
        );
        assert!(driver.numeric().is_some(), "{options:?}: no Newton report");
    }
}

#[test]
fn interpreted_frames_allocate_nothing_once_built() {
    for name in ["fourbar", "rocker_rocker", "inverted_slider_crank", "stress_10"] {
        let m = load(name);
        let inputs = sweep_inputs(&m, None);
        for options in all_options() {
            let n = frame_allocations(Interpreter::new(plan(&m)), options, &inputs);
            assert_eq!(n, 0, "{name} {options:?}");
        }
    }
}

/// A compiled frame's rates (`solve_rates`, one pass on jets, and `rates`
/// after a frame) allocate nothing either: fixed-size arrays of jets, and
/// through numeric clusters fixed-size matrices (the Newton solve and the
/// SVD of the implicit function theorem) on the stack.
#[test]
fn compiled_rates_allocate_nothing() {
    use dofplan_runtime::planar::Pose;
    use dofplan_runtime::real::{Jet2, Rates};
    use dofplan_runtime::Ctx;
    for name in [
        "fourbar",
        "rocker_rocker",
        "stress_50",
        "sixbar_b",
        "eightbar",
        "duplex",
        "chain_15",
    ] {
        let inputs = sweep_inputs(&load(name), None);
        let (count, ok) = dofplan_generated::with_plan!(name, |plan| {
            let mut state = plan.initial_state();
            let mut out = vec![Pose::<Jet2>::cst(Pose::IDENTITY); state.poses.len()];
            let (r, a) = ([30.0], [1.0]);
            let mut ok = 0;
            let count = allocations(|| {
                for i in &inputs {
                    let mut ctx = Ctx::new(Default::default(), false);
                    let fused = plan.solve_rates_into(&mut state, i, &r, &a, &mut ctx, &mut out);
                    let again = plan.rates_into(&state, i, &r, &a, &mut out);
                    ok += usize::from(
                        std::hint::black_box(fused).is_ok() && std::hint::black_box(again).is_ok(),
                    );
                }
            });
            (count, ok)
        })
        .expect("compiled");
        assert_eq!(count, 0, "{name}");
        // (rocker_rocker breaks over half its sweep.)
        assert!(
            ok * 3 >= inputs.len(),
            "{name}: rates on {ok} of {} frames",
            inputs.len()
        );
    }

    // The split form's rates (a working copy of jets, a cluster's chunk).
    macro_rules! split {
        ($($name:ident),*) => {$(
            let inputs = sweep_inputs(&load(stringify!($name)), None);
            let plan = dofplan_generated::chunked::$name::Plan;
            let mut state = plan.initial_state();
            let mut out = vec![Pose::<Jet2>::cst(Pose::IDENTITY); state.poses.len()];
            let (r, a) = ([30.0], [1.0]);
            let mut ok = 0;
            let count = allocations(|| {
                for i in &inputs {
                    let mut ctx = Ctx::new(Default::default(), false);
                    let fused = plan.solve_rates_into(&mut state, i, &r, &a, &mut ctx, &mut out);
                    let again = plan.rates_into(&state, i, &r, &a, &mut out);
                    ok += usize::from(std::hint::black_box(fused).is_ok() && std::hint::black_box(again).is_ok());
                }
            });
            assert_eq!(count, 0, "split {}", stringify!($name));
            assert!(ok * 10 >= inputs.len() * 9, "split {}: rates on {ok} frames", stringify!($name));
        )*};
    }
    split!(fourbar, stress_50, sixbar_b, chain_15);
}

/// A compiled spatial frame's rates (`solve_rates` and `rates`) allocate
/// nothing either, also where frames break, through numeric clusters (the
/// Stewart platform's, the rps3 fixtures': fixed-size Newton and implicit
/// function theorem), and in a split plan.
#[test]
fn compiled_spatial_rates_allocate_nothing() {
    use dofplan_runtime::real::Jet2;
    use dofplan_runtime::real::Rates;
    use dofplan_runtime::spatial::Pose3;
    use dofplan_runtime::Ctx;
    for name in [
        "cardan",
        "excavator",
        "rssr",
        "sofa_bed",
        "spatial_stress_10",
        "stewart",
        "rps3",
        "rps3_mixed",
    ] {
        let inputs = spatial_inputs(name, true);
        let n = inputs[0].len();
        let (r, a): (Vec<f64>, Vec<f64>) = ((0..n).map(|k| 30.0 + k as f64).collect(), vec![1.0; n]);
        let (count, ok) = dofplan_generated::with_spatial_plan!(name, |plan| {
            let mut state = plan.initial_state();
            let mut out = vec![Pose3::<Jet2>::cst(Pose3::IDENTITY); state.poses.len()];
            let mut ok = 0;
            let count = allocations(|| {
                for i in &inputs {
                    let mut ctx = Ctx::new(Default::default(), false);
                    let fused = plan.solve_rates_into(&mut state, i, &r, &a, &mut ctx, &mut out);
                    let again = plan.rates_into(&state, i, &r, &a, &mut out);
                    if std::hint::black_box(fused).is_ok() && std::hint::black_box(again).is_ok() {
                        ok += 1;
                    }
                }
            });
            (count, ok)
        })
        .expect("compiled");
        assert_eq!(count, 0, "{name}");
        // The sweep's frames have rates (the overreach's may break).
        assert!(
            ok * 2 >= inputs.len(),
            "{name}: rates on {ok} of {} frames",
            inputs.len()
        );
    }
    let inputs = spatial_inputs("cardan", true);
    let mut state = dofplan_generated::chunked::cardan::State::DRAWN;
    let count = allocations(|| {
        for i in &inputs {
            let mut ctx = dofplan_runtime::Ctx::new(Default::default(), false);
            let _ = std::hint::black_box(dofplan_generated::chunked::cardan::solve_rates(
                &mut state,
                i,
                &[30.0],
                &[1.0],
                &mut ctx,
            ));
        }
    });
    assert_eq!(count, 0, "cardan split");
}

/// A compiled `solve_forces` (positions, rates and forces in one pass)
/// allocates nothing, held still and running.
#[test]
fn compiled_forces_allocate_nothing() {
    use dofplan_runtime::Ctx;
    macro_rules! forces {
        ($($module:ident: $name:expr),*) => {$(
            let inputs = sweep_inputs(&load($name), None);
            let mut state = dofplan_generated::$module::State::DRAWN;
            let mut out = dofplan_generated::$module::forces::Forces::default();
            let mut ok = 0;
            let count = allocations(|| {
                for i in &inputs {
                    for (r, a) in [([0.0], [0.0]), ([90.0], [-30.0])] {
                        let mut ctx = Ctx::new(Default::default(), false);
                        let done = dofplan_generated::$module::forces::solve_forces(&mut state, i, &r, &a, &mut ctx, &mut out);
                        ok += usize::from(std::hint::black_box(done).is_ok());
                    }
                }
            });
            assert_eq!(count, 0, $name);
            assert_eq!(ok, 2 * inputs.len(), $name);
        )*};
    }
    forces!(
        fourbar_weights: "loads/fourbar_weights",
        slider_crank_press: "loads/slider_crank_press",
        arc_yoke_press: "loads/arc_yoke_press",
        geared_hoist: "gears/geared_hoist"
    );
}
