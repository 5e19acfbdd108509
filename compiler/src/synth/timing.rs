//! Free timing, for both dimensions: each target's input value is an
//! unknown of its own (as Pyslvs has it). The global search ranks a
//! candidate by how near its sampled curve passes each target, and starts
//! each target's input where that nearest point is; the polish then moves
//! the inputs with the parameters.

/// The sum over `targets` of the squared distance to the nearest point of
/// a sampled curve, and each target's input value there. `curve` holds
/// each sample's point (`None` where the frame is not solved); sample `s`
/// is at input `input_of(s)`. A target is projected on the segments
/// between neighbouring solved samples; with no such segment, it is
/// measured to the first solved sample. `None` if no sample is solved.
pub(crate) fn nearest(
    curve: &[Option<[f64; 3]>],
    input_of: impl Fn(usize) -> f64,
    targets: impl Iterator<Item = [f64; 3]>,
) -> Option<(f64, Vec<f64>)> {
    let values: Vec<(usize, [f64; 3])> = (curve.iter().enumerate())
        .filter_map(|(s, p)| p.map(|p| (s, p)))
        .collect();
    let first = values.first()?;
    // Each segment's direction and inverse squared length once, not once
    // per target: the search calls this for every candidate, with some
    // 180 segments and as many targets as the user gave.
    let segments: Vec<Segment> = (values.windows(2))
        .filter(|w| w[1].0 == w[0].0 + 1)
        .map(|w| Segment::new(w[0], w[1]))
        .collect();
    let (mut total, mut inputs) = (0.0, Vec::new());
    for t in targets {
        let (mut best, mut at) = (f64::INFINITY, 0.0);
        for seg in &segments {
            let (d, u) = seg.project(&t);
            if d < best {
                best = d;
                at = input_of(seg.from) + u * (input_of(seg.from + 1) - input_of(seg.from));
            }
        }
        if !best.is_finite() {
            best = dist2(&t, &first.1);
            at = input_of(first.0);
        }
        total += best;
        inputs.push(at);
    }
    Some((total, inputs))
}

/// The segment from sample `from` to the next.
struct Segment {
    from: usize,
    a: [f64; 3],
    ab: [f64; 3],
    /// 1 / |ab|², 0 for a segment of no length (projected on its start).
    inv_l2: f64,
}

impl Segment {
    fn new((from, a): (usize, [f64; 3]), (_, b): (usize, [f64; 3])) -> Segment {
        let ab = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let l2 = ab[0] * ab[0] + ab[1] * ab[1] + ab[2] * ab[2];
        Segment {
            from,
            a,
            ab,
            inv_l2: if l2 > 0.0 { 1.0 / l2 } else { 0.0 },
        }
    }

    /// The squared distance from `t` to the segment and where along it (0
    /// at its start, 1 at its end) the nearest point is.
    fn project(&self, t: &[f64; 3]) -> (f64, f64) {
        let (a, ab) = (&self.a, &self.ab);
        let at = [t[0] - a[0], t[1] - a[1], t[2] - a[2]];
        let u = ((ab[0] * at[0] + ab[1] * at[1] + ab[2] * at[2]) * self.inv_l2).clamp(0.0, 1.0);
        let off = [at[0] - u * ab[0], at[1] - u * ab[1], at[2] - u * ab[2]];
        (off[0] * off[0] + off[1] * off[1] + off[2] * off[2], u)
    }
}

fn dist2(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    (0..3).map(|k| (a[k] - b[k]) * (a[k] - b[k])).sum()
}

#[cfg(test)]
mod tests {
    use super::nearest;

    #[test]
    fn targets_are_projected_on_the_curve_between_samples() {
        // A straight curve along x, sampled at inputs 0, 10, 20; the middle
        // sample missing cuts it in two pieces, neither a segment.
        let curve = [
            Some([0.0, 0.0, 0.0]),
            Some([1.0, 0.0, 0.0]),
            Some([2.0, 0.0, 0.0]),
        ];
        let (e, at) = nearest(
            &curve,
            |s| 10.0 * s as f64,
            [[0.25, 1.0, 0.0], [1.5, -2.0, 0.0]].into_iter(),
        )
        .unwrap();
        assert!((e - 5.0).abs() < 1e-12, "{e}");
        assert!(
            (at[0] - 2.5).abs() < 1e-12 && (at[1] - 15.0).abs() < 1e-12,
            "{at:?}"
        );
        let cut = [Some([0.0, 0.0, 0.0]), None, Some([2.0, 0.0, 0.0])];
        let (e, at) = nearest(&cut, |s| 10.0 * s as f64, [[2.0, 1.0, 0.0]].into_iter()).unwrap();
        assert_eq!((e, at), (5.0, vec![0.0]));
        assert!(nearest(&[None, None], |s| s as f64, [[0.0; 3]].into_iter()).is_none());
    }
}
