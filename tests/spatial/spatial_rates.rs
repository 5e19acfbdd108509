//! Velocities and accelerations of spatial plans by forward-mode
//! differentiation through the plan ([`Interpreter::rates`], the generated
//! modules' `rates` and `solve_rates`), against independent computations:
//! the Cardan joint's velocity ratio cos β / (1 − sin²β cos²θ₁) and its
//! derivative, with β and the phase of θ₁ read from the file's geometry,
//! and central differences of positions on every bundled spatial sweep;
//! the Stewart platform's leg lengths, whose rates must be the slides'.
//! Every frame solved here is held to its raw joint residuals.

use dofplan::interp::spatial::Interpreter;
use dofplan::model::spatial::Mechanism;
use dofplan::simulate::spatial::residual;
use dofplan::simulate::sweep_requests;
use dofplan_runtime::real::Rates;
use dofplan_runtime::real::{Jet2, RateError};
use dofplan_runtime::spatial::{cross, dot, Pose3, Vec3};
use dofplan_runtime::{Ctx, Driver, FrameStatus, Options, Solver};
use dofplan_tests::{bundled_spatial, load_spatial, plan_spatial, spatial_fixtures};

type M3 = [[f64; 3]; 3];

/// The matrices of a jet rotation: R, Ṙ and R̈.
fn parts(p: &Pose3<Jet2>) -> (M3, M3, M3) {
    let m = &p.rot.m;
    let take = |f: fn(&Jet2) -> f64| -> M3 { std::array::from_fn(|i| std::array::from_fn(|j| f(&m[i][j]))) };
    (take(|x| x.v), take(|x| x.d), take(|x| x.dd))
}

/// `a·bᵀ`.
fn mul_t(a: &M3, b: &M3) -> M3 {
    std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[j][k]).sum()))
}

/// The axial vector of the antisymmetric part of `m`.
fn vee(m: &M3) -> Vec3 {
    [
        0.5 * (m[2][1] - m[1][2]),
        0.5 * (m[0][2] - m[2][0]),
        0.5 * (m[1][0] - m[0][1]),
    ]
}

/// A body's angular velocity ω and acceleration α from its rotation's jets:
/// Ṙ·Rᵀ = [ω]× and R̈·Rᵀ = [α]× + [ω]×², whose antisymmetric part is [α]×.
fn omega_alpha(p: &Pose3<Jet2>) -> (Vec3, Vec3) {
    let (r, rd, rdd) = parts(p);
    (vee(&mul_t(&rd, &r)), vee(&mul_t(&rdd, &r)))
}

/// The bundled spatial mechanisms and the spatial fixtures
/// (tests/fixtures/spatial/: the steps no bundled one needs), by name.
fn every_spatial() -> Vec<String> {
    let mut names = bundled_spatial();
    names.extend(spatial_fixtures());
    names
}

/// Whether `m`'s plan has a numeric cluster.
fn has_cluster(m: &Mechanism) -> bool {
    plan_spatial(m)
        .steps
        .iter()
        .any(|s| matches!(s.kind, dofplan::plan::spatial::StepKind::Cluster(_)))
}

fn unit(v: Vec3) -> Vec3 {
    let n = dot(v, v).sqrt();
    [v[0] / n, v[1] / n, v[2] / n]
}

/// The Cardan joint of `mechanisms/spatial/cardan.toml`: at every frame of
/// its sweep, with the input shaft at a constant rate plus an acceleration,
/// the output shaft's angular velocity about its axis is
/// ω₂ = g(θ₁)·ω₁ with g = cos β / (1 − sin²β cos²θ₁), and its acceleration
/// α₂ = g(θ₁)·α₁ + g′(θ₁)·ω₁², g′ = −cos β sin²β sin 2θ₁ / (1 − sin²β cos²θ₁)².
/// β is the angle between the ground bearings' axes; θ₁ is the input
/// yoke's angle about the input axis from the plane of the shafts, measured
/// on the solved frame (so no convention for the input's zero is assumed).
/// Checked on the compiled module's `solve_rates` and on the interpreter.
#[test]
fn a_cardan_joint_has_its_velocity_ratio_and_its_derivative() {
    let m = load_spatial("cardan");
    let z = |name: &str| m.marker(m.find_marker(name).unwrap()).axes.unwrap().z;
    let (a1, a2) = (z("ground.A"), z("ground.B"));
    let beta = dot(a1, a2).clamp(-1.0, 1.0).acos();
    assert!(
        (beta.to_degrees() - 30.0).abs() < 1e-9,
        "β = {}°",
        beta.to_degrees()
    );
    // The input yoke's axis (shaft1's marker of the cross), and the
    // direction across the input shaft in the plane of the shafts.
    let yoke = z("shaft1.U");
    let in_plane = unit(cross(cross(a1, a2), a1));
    let body = |name: &str| m.bodies.iter().position(|b| b.name == name).unwrap();
    let (shaft1, shaft2) = (body("shaft1"), body("shaft2"));
    let (sb, cb) = beta.sin_cos();
    let g = |t: f64| cb / (1.0 - sb * sb * t.cos() * t.cos());
    let g_prime = |t: f64| {
        let q = 1.0 - sb * sb * t.cos() * t.cos();
        -cb * sb * sb * (2.0 * t).sin() / (q * q)
    };
    let interp = Interpreter::new(plan_spatial(&m));
    let mut di = Driver::new(interp.clone(), Options::default());
    let mut s = dofplan_generated::cardan::State::DRAWN;
    // 90°/s and 40°/s², in the inputs' units (degrees).
    let (rate, accel) = (90.0_f64, 40.0_f64);
    let (w1, e1) = (rate.to_radians(), accel.to_radians());
    let sweep = m.sweep.clone().unwrap();
    let mut checked = 0;
    for u in sweep_requests(&sweep, 1) {
        let mut ctx = Ctx::new(Default::default(), false);
        let jets = dofplan_generated::cardan::solve_rates(&mut s, &u, &[rate], &[accel], &mut ctx).unwrap();
        assert!(residual(&m, &s.poses, &u) <= 1e-9, "{u:?}: residual");
        assert_eq!(di.frame(&u), FrameStatus::Solved);
        let interpreted = interp.rates(di.state(), &u, &[rate], &[accel]).unwrap();
        let yoke_now = s.poses[shaft1].dir(yoke);
        let theta1 = dot(cross(in_plane, yoke_now), a1).atan2(dot(in_plane, yoke_now));
        for jets in [&jets[..], &interpreted[..]] {
            let (om1, al1) = omega_alpha(&jets[shaft1]);
            let (om2, al2) = omega_alpha(&jets[shaft2]);
            // The input shaft turns about its axis at the input's rates.
            assert!((dot(om1, a1) - w1).abs() < 1e-12 && (dot(al1, a1) - e1).abs() < 1e-12);
            let ratio = dot(om2, a2) / dot(om1, a1);
            assert!(
                (ratio - g(theta1)).abs() < 1e-9,
                "θ₁ {:.3}°: ratio {ratio} vs {}",
                theta1.to_degrees(),
                g(theta1)
            );
            // The output turns about its own axis only.
            assert!(dot(cross(om2, a2), cross(om2, a2)).sqrt() < 1e-12);
            let want = g(theta1) * e1 + g_prime(theta1) * w1 * w1;
            assert!(
                (dot(al2, a2) - want).abs() < 1e-9 * (1.0 + want.abs()),
                "θ₁ {:.3}°: α₂ {} vs {want}",
                theta1.to_degrees(),
                dot(al2, a2)
            );
        }
        checked += 1;
    }
    assert_eq!(checked, 361);
}

/// The sweep's direction in input space, largest component 1.
fn direction(m: &Mechanism) -> Vec<f64> {
    let sweep = m.sweep.as_ref().expect("a sweep");
    let mut dir = vec![0.0; m.inputs.len()];
    for s in &sweep.inputs {
        dir[s.input] = s.to - s.from;
    }
    let scale = dir.iter().fold(0.0_f64, |a, x| a.max(x.abs()));
    dir.iter().map(|x| x / scale).collect()
}

/// Every bundled spatial sweep, and every spatial fixture's: at frames
/// spread over it, every marker's position and axes have first and second
/// derivatives along the sweep's direction equal to central differences of
/// positions solved by the plan (h = 1e-3 of the direction); dead points
/// are reported singular, not as numbers. The plans with a numeric cluster
/// (the Stewart platform; the fixtures rps3 and rps3_mixed: their rates by
/// the implicit function theorem) are checked as every other.
#[test]
fn spatial_rates_agree_with_central_differences_on_every_bundled_sweep() {
    let mut checked = 0;
    let mut with_clusters = Vec::new();
    for name in every_spatial() {
        let m = load_spatial(&name);
        let interp = Interpreter::new(plan_spatial(&m));
        let n = m.inputs.len();
        let dir = direction(&m);
        let count = if name.starts_with("spatial_stress_") {
            3
        } else {
            12
        };
        let requests: Vec<Vec<f64>> = sweep_requests(m.sweep.as_ref().unwrap(), n).collect();
        let every = (requests.len() / count).max(1);
        let mut d = Driver::new(interp.clone(), Options::default());
        let size = m.size();
        let cluster = has_cluster(&m);
        for (i, u) in requests.into_iter().enumerate() {
            assert_eq!(d.frame(&u), FrameStatus::Solved, "{name} frame {i}");
            assert!(residual(&m, d.poses(), &u) <= 1e-9, "{name} frame {i}: residual");
            if i % every != 0 {
                continue;
            }
            let jets = match interp.rates(d.state(), &u, &dir, &vec![0.0; n]) {
                Ok(j) => j,
                Err(RateError::Singular) => continue,
                Err(e) => panic!("{name} frame {i}: {e}"),
            };
            // Positions at u ± h·dir, each solved from this frame. The
            // central differences are off by h²·(third derivative)/6: the
            // rps3 platform's legs turn fast enough for that to pass 1e-5 at
            // h = 1e-3 (it shrinks a hundredfold at 1e-4, towards the jets),
            // so the plans with a cluster take the smaller step.
            let h = if cluster { 1e-4 } else { 1e-3 };
            let at = |t: f64| -> Option<Vec<Pose3>> {
                let v: Vec<f64> = u.iter().zip(&dir).map(|(x, e)| x + t * e).collect();
                let mut state = d.state().clone();
                let mut ctx = Ctx::new(Default::default(), false);
                interp.solve(&mut state, &v, &mut ctx).ok()?;
                assert!(
                    residual(&m, &state.poses, &v) <= 1e-9,
                    "{name} frame {i} {t:+}: residual"
                );
                Some(state.poses.clone())
            };
            let (Some(plus), Some(minus)) = (at(h), at(-h)) else {
                continue; // at the edge of assembly
            };
            let here = d.poses().to_vec();
            for id in m.all_markers() {
                let mk = m.marker(id);
                let b = id.body;
                let at_jet = |q: Vec3| -> [Jet2; 3] { jets[b].world(q) };
                let mut rows: Vec<([Jet2; 3], Vec3, Vec3, Vec3, f64)> = vec![(
                    at_jet(mk.at),
                    plus[b].world(mk.at),
                    minus[b].world(mk.at),
                    here[b].world(mk.at),
                    size,
                )];
                if let Some(axes) = mk.axes {
                    for v in [axes.z, axes.x] {
                        rows.push((
                            jets[b].dir(v),
                            plus[b].dir(v),
                            minus[b].dir(v),
                            here[b].dir(v),
                            1.0,
                        ));
                    }
                }
                for (j, pp, pm, p0, scale) in rows {
                    for k in 0..3 {
                        // The jets' values are the frame's (solved again from
                        // it, so to rounding).
                        assert!((j[k].v - p0[k]).abs() <= 1e-12 * scale, "{name} frame {i}");
                        let first = (pp[k] - pm[k]) / (2.0 * h);
                        let second = (pp[k] - 2.0 * p0[k] + pm[k]) / (h * h);
                        assert!(
                            (j[k].d - first).abs() <= 1e-5 * scale.max(j[k].d.abs()),
                            "{name} frame {i} {}: d {} vs {first}",
                            m.marker_name(id),
                            j[k].d
                        );
                        assert!(
                            (j[k].dd - second).abs() <= 1e-3 * scale.max(j[k].dd.abs()),
                            "{name} frame {i} {}: dd {} vs {second}",
                            m.marker_name(id),
                            j[k].dd
                        );
                    }
                }
            }
            checked += 1;
            if cluster && with_clusters.last() != Some(&name) {
                with_clusters.push(name.clone());
            }
        }
    }
    let clusters: Vec<String> = every_spatial()
        .into_iter()
        .filter(|n| has_cluster(&load_spatial(n)))
        .collect();
    assert!(clusters.contains(&"stewart".to_string()));
    assert_eq!(
        with_clusters, clusters,
        "the plans with numeric clusters, checked"
    );
    assert!(checked >= 100, "{checked} frames checked");
}

/// Bit for bit, not just `==` (which takes −0 for 0).
fn bits(poses: &[Pose3]) -> Vec<u64> {
    poses
        .iter()
        .flat_map(|p| {
            p.rot
                .m
                .iter()
                .flatten()
                .chain(&p.pos)
                .map(|x| x.to_bits())
                .collect::<Vec<_>>()
        })
        .collect()
}

/// The generated modules' `rates` (the same steps emitted for jets) equal
/// the interpreter's to 1e-12 on every frame of every bundled spatial
/// sweep and spatial fixture's (a spread of frames on the stress chains);
/// `solve_rates`, a frame and its rates in one pass on jets, gives exactly
/// `solve`'s positions, and the interpreter's rates from the frame before.
/// (A numeric cluster is solved by fixed-size Newton in generated code and
/// by the interpreter's own: their positions agree to rounding, 1e-12,
/// not bit for bit, and its rates to 1e-10.) The largest chains' steps are
/// split into functions, their rates' too.
#[test]
fn compiled_spatial_rates_equal_interpreted_rates() {
    let mut compared = 0;
    for name in every_spatial() {
        let m = load_spatial(&name);
        let interp = Interpreter::new(plan_spatial(&m));
        let n = m.inputs.len();
        let rates: Vec<f64> = (0..n).map(|k| 10.0 + k as f64).collect();
        let accels: Vec<f64> = (0..n).map(|k| 2.0 - k as f64).collect();
        let requests: Vec<Vec<f64>> = m
            .sweep
            .as_ref()
            .map(|s| sweep_requests(s, n).collect())
            .unwrap_or_default();
        let every = if name.starts_with("spatial_stress_") {
            40
        } else {
            1
        };
        dofplan_generated::with_spatial_plan!(name.as_str(), |compiled| {
            let mut dc = Driver::new(compiled, Options::default());
            let mut di = Driver::new(interp.clone(), Options::default());
            let mut out = vec![Pose3::<Jet2>::cst(Pose3::IDENTITY); m.bodies.len()];
            let mut fused_out = out.clone();
            let mut fused_state = Solver::initial_state(&compiled);
            let cluster = has_cluster(&m);
            for (k, u) in requests.iter().enumerate() {
                let before = di.state().clone();
                assert_eq!(dc.frame(u), di.frame(u), "{name}");
                let mut ctx = Ctx::new(Default::default(), false);
                let fused =
                    compiled.solve_rates_into(&mut fused_state, u, &rates, &accels, &mut ctx, &mut fused_out);
                assert_eq!(
                    bits(&fused_state.poses),
                    bits(&dc.state().poses),
                    "{name}: the fused pass's positions are solve's"
                );
                if k % every != 0 {
                    continue;
                }
                let c = compiled.rates_into(dc.state(), dc.inputs(), &rates, &accels, &mut out);
                let i = interp.rates(di.state(), di.inputs(), &rates, &accels);
                match (c, i) {
                    (Ok(()), Ok(jets)) => {
                        assert!(fused.is_ok(), "{name}: {fused:?}");
                        // The fused pass is the steps on jets from the frame
                        // before: the interpreter's rates from there. (The
                        // rates of an idle freedom, such as a rod spinning
                        // about its own axis, depend on where the steps
                        // start, so it is not compared with `rates`.)
                        let from_before = interp.rates(&before, u, &rates, &accels).unwrap();
                        let entries = |p: &Pose3<Jet2>| -> Vec<Jet2> {
                            p.pos.iter().chain(p.rot.m.iter().flatten()).copied().collect()
                        };
                        for (pair, what) in [((&out, &jets), "rates"), ((&fused_out, &from_before), "fused")]
                        {
                            for (a, b) in pair.0.iter().zip(pair.1.iter()) {
                                for (x, y) in entries(a).into_iter().zip(entries(b)) {
                                    if cluster {
                                        assert!((x.v - y.v).abs() <= 1e-12, "{name} {what}: values");
                                    } else {
                                        assert_eq!(x.v.to_bits(), y.v.to_bits(), "{name} {what}: values");
                                    }
                                    // A cluster's rates are solved through its
                                    // Jacobian's Gram matrix, which squares its
                                    // condition: rounding apart, 1e-10.
                                    let tol = if cluster { 1e-10 } else { 1e-12 };
                                    for (p, q) in [(x.d, y.d), (x.dd, y.dd)] {
                                        assert!(
                                            (p - q).abs() <= tol * (1.0 + q.abs()),
                                            "{name} {what}: {p} vs {q}"
                                        );
                                    }
                                }
                            }
                        }
                        compared += 1;
                    }
                    (Err(a), Err(b)) if a == b => {}
                    (c, i) => panic!("{name}: compiled {c:?}, interpreted {:?}", i.map(|_| ())),
                }
            }
        })
        .expect("every bundled spatial mechanism is compiled");
    }
    assert!(compared > 1500, "{compared} frames compared");
}

/// The split form of every small spatial plan (`dofplan_generated::chunked`:
/// two or three steps a function, a cluster's in one of its own) has the
/// rates of the plan in one function, bit for bit, from `solve_rates` (and
/// the same frames) and from `rates`, over each sweep and through its
/// breaks (the sweep run on three times as far backwards).
#[test]
fn split_spatial_plans_have_the_rates_of_the_whole_plan() {
    let mut compared = 0;
    macro_rules! same {
        ($($name:ident),*) => {$({
            use dofplan_generated::chunked::$name as split;
            use dofplan_generated::$name as whole;
            let name = stringify!($name);
            let m = load_spatial(name);
            let n = m.inputs.len();
            let rates: Vec<f64> = (0..n).map(|k| 10.0 + k as f64).collect();
            let accels: Vec<f64> = (0..n).map(|k| 2.0 - k as f64).collect();
            let mut sweep = m.sweep.clone().expect("a sweep");
            let mut requests: Vec<Vec<f64>> = sweep_requests(&sweep, n).collect();
            for s in &mut sweep.inputs {
                (s.from, s.to) = (s.to, s.to - 4.0 * (s.to - s.from));
            }
            requests.extend(sweep_requests(&sweep, n));
            let (mut a, mut b) = (split::State::DRAWN, whole::State::DRAWN);
            for u in &requests {
                let mut ctx = Ctx::new(Default::default(), false);
                let x = split::solve_rates(&mut a, u, &rates, &accels, &mut ctx);
                let mut ctx = Ctx::new(Default::default(), false);
                let y = whole::solve_rates(&mut b, u, &rates, &accels, &mut ctx);
                assert_eq!(x, y, "{name}");
                assert_eq!((a.poses, a.temps, a.branches, a.angles), (b.poses, b.temps, b.branches, b.angles), "{name}");
                let (x, y) = (split::rates(&a, u, &rates, &accels), whole::rates(&b, u, &rates, &accels));
                assert_eq!(x, y, "{name}");
                compared += usize::from(x.is_ok());
            }
        })*};
    }
    same!(
        bennett,
        cardan,
        double_cardan,
        excavator,
        rssr,
        sofa_bed,
        spherical_fourbar,
        stewart,
        tilted_fourbar,
        rps3,
        rps3_mixed
    );
    assert!(compared > 1000, "{compared} frames with rates compared");
}

/// The Stewart platform's legs are its inputs: leg i's length |Pᵢ − Bᵢ|
/// (the platform's sphere centre Pᵢ, the base's universal-joint centre Bᵢ,
/// both on the leg's axis) is its drawn length plus slide i. So along any
/// motion of the slides, the length's rate computed from the platform's
/// jets, l̇ = d·ḋ/l with d = Pᵢ − Bᵢ, is slide i's rate, and
/// l̈ = (ḋ·ḋ + d·d̈ − l̇²)/l its acceleration — the velocity and
/// acceleration loop closures of the six legs, which pin the platform's
/// twist and its derivative. Every frame of the sweep, six different leg
/// rates and accelerations, on the interpreter and the compiled module's
/// `solve_rates` (whose positions are `solve`'s).
#[test]
fn stewart_leg_lengths_move_at_their_slides_rates() {
    let m = load_spatial("stewart");
    assert!(has_cluster(&m));
    let interp = Interpreter::new(plan_spatial(&m));
    let n = m.inputs.len();
    assert_eq!(n, 6);
    let rates: Vec<f64> = (0..n).map(|k| 0.3 - 0.11 * k as f64).collect();
    let accels: Vec<f64> = (0..n).map(|k| -0.2 + 0.07 * k as f64).collect();
    let platform = m.bodies.iter().position(|b| b.name == "platform").unwrap();
    // Leg i: its input, the base centre Bᵢ (world) and the platform's Pᵢ (local).
    let legs: Vec<(usize, Vec3, Vec3)> = (1..=6)
        .map(|i| {
            let input = m.inputs.iter().position(|u| u.name == format!("leg{i}")).unwrap();
            let at = |name: String| m.marker(m.find_marker(&name).unwrap()).at;
            (input, at(format!("ground.U{i}")), at(format!("platform.S{i}")))
        })
        .collect();
    let drawn: Vec<f64> = legs
        .iter()
        .map(|(_, b, p)| {
            let d = [p[0] - b[0], p[1] - b[1], p[2] - b[2]];
            dot(d, d).sqrt()
        })
        .collect();
    let requests: Vec<Vec<f64>> = sweep_requests(m.sweep.as_ref().unwrap(), n).collect();
    assert_eq!(requests.len(), 41);
    let mut d = Driver::new(interp.clone(), Options::default());
    dofplan_generated::with_spatial_plan!("stewart", |compiled| {
        let mut state = Solver::initial_state(&compiled);
        let mut out = vec![Pose3::<Jet2>::cst(Pose3::IDENTITY); m.bodies.len()];
        for (f, u) in requests.iter().enumerate() {
            assert_eq!(d.frame(u), FrameStatus::Solved, "frame {f}");
            assert!(residual(&m, d.poses(), u) <= 1e-9, "frame {f}: residual");
            let mut ctx = Ctx::new(Default::default(), false);
            compiled
                .solve_rates_into(&mut state, u, &rates, &accels, &mut ctx, &mut out)
                .unwrap();
            assert!(
                residual(&m, &state.poses, u) <= 1e-9,
                "frame {f}: compiled residual"
            );
            let jets = interp.rates(d.state(), u, &rates, &accels).unwrap();
            for poses in [&jets, &out] {
                for (k, (input, b, p)) in legs.iter().enumerate() {
                    let at = poses[platform].world(*p);
                    let dv: Vec3 = std::array::from_fn(|i| at[i].v - b[i]);
                    let dd: Vec3 = std::array::from_fn(|i| at[i].d);
                    let ddd: Vec3 = std::array::from_fn(|i| at[i].dd);
                    let l = dot(dv, dv).sqrt();
                    assert!(
                        (l - drawn[k] - u[*input]).abs() < 1e-9,
                        "frame {f} leg {}: length",
                        k + 1
                    );
                    let l_dot = dot(dv, dd) / l;
                    let l_ddot = (dot(dd, dd) + dot(dv, ddd) - l_dot * l_dot) / l;
                    assert!(
                        (l_dot - rates[*input]).abs() < 1e-9,
                        "frame {f} leg {}: rate {l_dot} vs {}",
                        k + 1,
                        rates[*input]
                    );
                    assert!(
                        (l_ddot - accels[*input]).abs() < 1e-8,
                        "frame {f} leg {}: acceleration {l_ddot} vs {}",
                        k + 1,
                        accels[*input]
                    );
                }
            }
        }
    })
    .expect("stewart is compiled");
}
