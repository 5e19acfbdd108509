//! Tolerances on the dimensions: the worst-case first-order deviation
//! against every corner of the box, and the Monte-Carlo spread of
//! perturbed candidates against that bound.

use dofplan::model::MarkerId;
use dofplan::simulate::sweep_inputs;
use dofplan::synth::planar::{monte_carlo, sensitivity, worst_case, Design};
use dofplan::synth::spatial;
use dofplan_runtime::{Driver, Options};

/// Every corner of the box, one by one (2^P of them).
fn by_corners(d: &[[f64; 2]], t: f64) -> f64 {
    (0..1u32 << d.len())
        .map(|mask| {
            let mut s = [0.0; 2];
            for (k, v) in d.iter().enumerate() {
                let sign = if mask >> k & 1 == 1 { t } else { -t };
                s = [s[0] + sign * v[0], s[1] + sign * v[1]];
            }
            s[0].hypot(s[1])
        })
        .fold(0.0, f64::max)
}

#[test]
fn worst_case_is_the_largest_corner() {
    // A fixed pseudo-random sequence (no dependence on a generator's version).
    let mut x = 0x2545_f491_4f6c_dd1du64;
    let mut next = || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    for p in 1..=11 {
        for _ in 0..20 {
            let d: Vec<[f64; 2]> = (0..p).map(|_| [next(), next()]).collect();
            let (fast, slow) = (worst_case(&d, 0.3), by_corners(&d, 0.3));
            assert!(
                (fast - slow).abs() <= 1e-12 * slow.max(1.0),
                "P = {p}: {fast} vs {slow}"
            );
        }
    }
    // Parallel and zero derivatives: the corners still add up.
    assert!((worst_case(&[[1.0, 0.0], [-2.0, 0.0], [0.0, 0.0]], 0.5) - 1.5).abs() < 1e-15);
    assert_eq!(worst_case(&[], 1.0), 0.0);
}

/// Every corner of the box in space, one by one (2^P of them).
fn by_corners_3(d: &[[f64; 3]], t: f64) -> f64 {
    (0..1u32 << d.len())
        .map(|mask| {
            let mut s = [0.0; 3];
            for (k, v) in d.iter().enumerate() {
                let sign = if mask >> k & 1 == 1 { t } else { -t };
                s = [s[0] + sign * v[0], s[1] + sign * v[1], s[2] + sign * v[2]];
            }
            (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt()
        })
        .fold(0.0, f64::max)
}

#[test]
fn spatial_worst_case_is_the_largest_corner() {
    let mut x = 0x9e37_79b9_7f4a_7c15u64;
    let mut next = || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    let check = |d: &[[f64; 3]], what: &str| {
        let (fast, slow) = (spatial::worst_case(d, 0.3), by_corners_3(d, 0.3));
        assert!(
            (fast - slow).abs() <= 1e-12 * slow.max(1.0),
            "{what}, P = {}: {fast} vs {slow}",
            d.len()
        );
    };
    for p in 1..=11 {
        for _ in 0..20 {
            // In general position.
            let d: Vec<[f64; 3]> = (0..p).map(|_| [next(), next(), next()]).collect();
            check(&d, "general");
            // All in one plane (a planar motion seen in space), some off
            // it, and some parallel to others or zero.
            let flat: Vec<[f64; 3]> = (0..p).map(|_| [next(), next(), 0.0]).collect();
            check(&flat, "coplanar");
            let mut mixed = flat.clone();
            mixed[0] = [next(), next(), next()];
            if p > 2 {
                mixed[1] = mixed[2].map(|v| -2.0 * v);
                mixed[p - 1] = [0.0; 3];
            }
            check(&mixed, "mixed");
        }
    }
    check(&[[1.0, 0.0, 0.0], [-2.0, 0.0, 0.0], [0.0; 3]], "collinear");
    assert_eq!(spatial::worst_case(&[], 1.0), 0.0);
}

/// For a small tolerance, perturbed candidates stay within the
/// first-order bound (to its second-order error) and come near it.
#[test]
fn monte_carlo_stays_within_the_first_order_bound() {
    let file = format!("{}/mechanisms/fourbar.toml", env!("CARGO_MANIFEST_DIR"));
    let m = dofplan::load_file(std::path::Path::new(&file)).unwrap();
    let design = Design::new(&m).unwrap();
    let base = design.prepare(&design.drawn()).unwrap();
    let requested = sweep_inputs(&m, Some(73));
    let p: MarkerId = m.find_marker("coupler.P").unwrap();
    let t = 1e-5;
    let mut driver = Driver::new(base.interpreter.clone(), Options::default());
    let (mut nominal, mut bound) = (Vec::new(), 0.0f64);
    for inputs in &requested {
        assert!(driver.frame(inputs).is_solved());
        let poses = driver.poses();
        nominal.push(Some(vec![poses[p.body].world(m.marker(p).at)]));
        let s = sensitivity(&design, &base, poses, inputs).unwrap();
        bound = bound.max(worst_case(&s.marker(p), t));
    }
    let spread = monte_carlo(&design, &requested, &[p], &nominal, (40, t, 7));
    assert_eq!(spread.failed, 0);
    assert!(
        spread.largest[0] <= bound * (1.0 + 1e-3),
        "{} > {bound}",
        spread.largest[0]
    );
    assert!(
        spread.largest[0] >= 0.3 * bound,
        "{} ≪ {bound}",
        spread.largest[0]
    );
    assert!(spread.mean[0] > 0.0 && spread.mean[0] <= spread.largest[0]);
    // Seeded: the same seed, the same spread.
    assert_eq!(
        spread,
        monte_carlo(&design, &requested, &[p], &nominal, (40, t, 7))
    );
}
