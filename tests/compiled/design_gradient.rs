//! Compiled derivatives with respect to the design parameters
//! (`design::gradient`): every bundled closed-form planar mechanism's,
//! against the library's (the implicit function theorem on the joints'
//! equations: an independent method), against central differences of the
//! compiled frames themselves, and on the four-bar against the hand
//! derivation of `tests/synth/gradients.rs`.

use dofplan::simulate::sweep_inputs;
use dofplan::synth::planar::{sensitivity, Design};
use dofplan_runtime::design::PrepareError;
use dofplan_runtime::{BranchPolicy, Ctx, Pose};
use dofplan_tests::{bundled, designed, load};

/// A frame's poses and, per body and parameter, the derivatives of its
/// translation and angle (radians): `[dx, dy, dθ]`.
type Frame = (Vec<Pose>, Vec<Vec<[f64; 3]>>);
/// A candidate's frames (`None` where the frame breaks or its derivatives
/// are infinite, at a dead point).
type Run = fn(&[f64], &[Vec<f64>]) -> Result<Vec<Option<Frame>>, PrepareError>;

macro_rules! gradient {
    ($m:ident) => {
        (
            stringify!($m),
            (|values: &[f64], frames: &[Vec<f64>]| {
                use dofplan_generated::$m::design;
                let p = design::Params(values.try_into().expect("one value per parameter"));
                let g = design::prepare(&p)?;
                let t = g.tangents();
                let mut s = g.state();
                let mut ctx = Ctx::new(BranchPolicy::Keep, false);
                Ok(frames
                    .iter()
                    .map(|u| {
                        design::solve_with(&g, &mut s, u, &mut ctx).ok()?;
                        let d = design::gradient(&t, &s, u).ok()?;
                        // The tangents' values are the frame's, bit for bit:
                        // the same operations on the same numbers.
                        for (a, b) in d.iter().zip(&s.poses) {
                            assert!(a.value() == *b, "values differ: {:?} vs {b:?}", a.value());
                        }
                        let per_body = d
                            .iter()
                            .map(|pose| {
                                let (c, sn) = (pose.rot.c, pose.rot.s);
                                (0..design::PARAMETERS)
                                    .map(|k| {
                                        [pose.at[0].d[k], pose.at[1].d[k], c.v * sn.d[k] - sn.v * c.d[k]]
                                    })
                                    .collect()
                            })
                            .collect();
                        Some((s.poses.to_vec(), per_body))
                    })
                    .collect())
            }) as Run,
        )
    };
}

/// Every design module dofplan-generated compiles.
fn modules() -> Vec<(&'static str, Run)> {
    vec![
        gradient!(fourbar),
        gradient!(inverted_slider_crank),
        gradient!(jansen),
        gradient!(pantograph),
        gradient!(parallelogram),
        gradient!(peaucellier),
        gradient!(rocker_rocker),
        gradient!(sixbar_a),
        gradient!(slider_crank),
        gradient!(table),
        gradient!(trammel),
        gradient!(vlink),
    ]
}

#[test]
fn every_design_module_is_checked_here() {
    let here: Vec<&str> = modules().iter().map(|m| m.0).collect();
    let expected: Vec<String> = bundled().into_iter().filter(|n| designed(n)).collect();
    assert_eq!(here, expected);
}

/// The drawing and two candidates moved by up to 2 % of the size: at every
/// fourth frame of a 37-frame sweep away from dead points, every body's
/// derivatives with respect to every parameter agree with the library's.
#[test]
fn compiled_derivatives_are_the_librarys_implicit_ones() {
    let (mut checked, mut near_dead) = (0, 0);
    for (name, run) in modules() {
        let m = load(name);
        let design = Design::new(&m).expect("a design");
        let size = m.size();
        let frames = sweep_inputs(&m, Some(37));
        let mut seed = 0x9e37_79b9_u64 ^ name.len() as u64;
        for candidate in 0..3 {
            let values: Vec<f64> = (design.drawn().iter())
                .map(|v| {
                    if candidate == 0 {
                        *v
                    } else {
                        v + 0.02 * size * next(&mut seed)
                    }
                })
                .collect();
            let Ok(replanned) = design.prepare(&values) else {
                continue;
            };
            let compiled =
                run(&values, &frames).unwrap_or_else(|e| panic!("{name} candidate {candidate}: {e}"));
            for (f, got) in compiled.iter().enumerate().step_by(4) {
                let Some((poses, d)) = got else { continue };
                let s = match sensitivity(&design, &replanned, poses, &frames[f]) {
                    Ok(s) if s.conditioning > 1e-4 && s.misfit.iter().all(|x| *x < 1e-9) => s,
                    _ => {
                        near_dead += 1;
                        continue;
                    }
                };
                for (b, per_param) in d.iter().enumerate() {
                    for (k, got) in per_param.iter().enumerate() {
                        let want = [
                            s.poses[(3 * b, k)],
                            s.poses[(3 * b + 1, k)],
                            s.poses[(3 * b + 2, k)],
                        ];
                        // Angles per unit of length: scaled by the size.
                        let gap = (got[0] - want[0])
                            .abs()
                            .max((got[1] - want[1]).abs())
                            .max(size * (got[2] - want[2]).abs());
                        let scale = 1.0 + want[0].abs().max(want[1].abs()).max(size * want[2].abs());
                        assert!(
                            gap <= 1e-7 * scale,
                            "{name} candidate {candidate} frame {f} body {b} d/d({}): compiled {got:?}, library {want:?}",
                            design.names()[k]
                        );
                    }
                }
                checked += 1;
            }
        }
    }
    eprintln!("{checked} frames compared, {near_dead} near a dead point");
    assert!(checked >= 150, "only {checked} frames compared");
}

/// Central differences of the compiled frames: each parameter moved by ±h
/// from the drawing, the sweep run again from each candidate's own drawn
/// state to the frame (so on the same branch).
#[test]
fn compiled_derivatives_are_central_differences_of_compiled_frames() {
    let mut checked = 0;
    for (name, run) in modules() {
        let m = load(name);
        let design = Design::new(&m).expect("a design");
        let size = m.size();
        let h = 1e-6 * size;
        let frames = sweep_inputs(&m, Some(37));
        let drawn = design.drawn();
        let exact = run(&drawn, &frames).expect("the drawing prepares");
        for f in [9, 18, 27] {
            let Some((_, d)) = &exact[f] else { continue };
            for k in 0..drawn.len() {
                let at = |sign: f64| {
                    let mut p = drawn.clone();
                    p[k] += sign * h;
                    run(&p, &frames[..=f]).ok().and_then(|r| r[f].clone())
                };
                // A mechanism drawn on a boundary of its class (the
                // parallelogram) stops turning on one side of it.
                let (Some((hi, _)), Some((lo, _))) = (at(1.0), at(-1.0)) else {
                    continue;
                };
                for (b, per_param) in d.iter().enumerate() {
                    let got = per_param[k];
                    let (a, c) = (hi[b], lo[b]);
                    let turn =
                        (a.rot.s * c.rot.c - a.rot.c * c.rot.s).atan2(a.rot.c * c.rot.c + a.rot.s * c.rot.s);
                    let fd = [
                        (a.at[0] - c.at[0]) / (2.0 * h),
                        (a.at[1] - c.at[1]) / (2.0 * h),
                        turn / (2.0 * h),
                    ];
                    let gap = (0..3).map(|i| (got[i] - fd[i]).abs() * if i == 2 { size } else { 1.0 });
                    let scale = 1.0 + got[0].abs().max(got[1].abs()).max(size * got[2].abs());
                    let gap = gap.fold(0.0, f64::max);
                    assert!(
                        gap <= 1e-5 * scale,
                        "{name} frame {f} body {b} d/d({}): exact {got:?}, central difference {fd:?}",
                        design.names()[k]
                    );
                }
            }
            checked += 1;
        }
    }
    assert!(checked >= 30, "only {checked} frames checked");
}

/// The hand derivation on the four-bar A(0,0) B(1,1) C(4.5,2.5) D(4,0) at
/// θ = 90° (see `tests/synth/gradients.rs`): dB/dA.x = (1, −1), dB/dB.x =
/// (0, 1), and dC/dD.x from differentiating the two circles C lies on.
#[test]
fn the_compiled_fourbar_matches_the_hand_derivation() {
    use dofplan_generated::fourbar::{design, marker};
    let g = design::prepare(&design::Params::DRAWN).expect("the drawing");
    let t = g.tangents();
    let mut s = g.state();
    let mut ctx = Ctx::new(BranchPolicy::Keep, false);
    for deg in 0..=90 {
        design::solve_with(&g, &mut s, &[deg as f64], &mut ctx).expect("turns");
    }
    let poses = design::gradient(&t, &s, &[90.0]).expect("not a dead point");
    let ix = |n: &str| design::Params::index(n).expect("a parameter");
    let b = t.marker(&poses, marker::CRANK_B).expect("fourbar's");
    let d = |p: [design::Dual; 2], k: usize| [p[0].d[k], p[1].d[k]];
    let close = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).abs().max((a[1] - b[1]).abs()) <= 1e-12;
    assert!(close(d(b, ix("A.x")), [1.0, -1.0]), "{:?}", d(b, ix("A.x")));
    assert!(close(d(b, ix("B.x")), [0.0, 1.0]), "{:?}", d(b, ix("B.x")));
    assert!(close(d(b, ix("D.x")), [0.0, 0.0]));

    let c = t.marker(&poses, marker::ROCKER_C).expect("fourbar's");
    let (bw, cw, dw) = ([b[0].v, b[1].v], [c[0].v, c[1].v], [4.0, 0.0]);
    let (c0, d0) = ([4.5, 2.5], [4.0, 0.0]);
    let l2 = f64::hypot(c0[0] - d0[0], c0[1] - d0[1]);
    let dl2 = (d0[0] - c0[0]) / l2;
    // [ (C−B)ᵀ ; (C−D)ᵀ ] dC = [ 0 ; L₂ dL₂ + (C−D)·e_x ]
    let (a11, a12, a21, a22) = (cw[0] - bw[0], cw[1] - bw[1], cw[0] - dw[0], cw[1] - dw[1]);
    let rhs = [0.0, l2 * dl2 + a21];
    let det = a11 * a22 - a12 * a21;
    let hand = [
        (rhs[0] * a22 - a12 * rhs[1]) / det,
        (a11 * rhs[1] - a21 * rhs[0]) / det,
    ];
    assert!(close(d(c, ix("D.x")), hand), "{:?} vs {hand:?}", d(c, ix("D.x")));
}

/// A deterministic number in [−1, 1) (no dependency for it).
fn next(seed: &mut u64) -> f64 {
    *seed = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
}
