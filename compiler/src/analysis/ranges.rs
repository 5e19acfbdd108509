//! Assembly ranges: the values of each input (the others at 0) for which
//! the mechanism assembles, each end a break point found to 1e-9 with the
//! plan step that breaks there (Brunkhart's search policy, run over the
//! whole range rather than along one sweep).
//!
//! An angle input is sampled over −180°..180° every degree, from the
//! drawn pose outward in both directions, each sample warm-started from
//! the last one that assembled (a numeric cluster starts near its root);
//! between a sample that assembles and one that does not, the break point
//! is bisected to 1e-9. A slide input has no natural range: from 0 it is
//! pushed out in doubling steps (from 1/64 of the mechanism's size) until
//! the plan breaks or the slide passes 1,000 sizes, and the break point is
//! bisected the same way. An island narrower than the sampling step (1°,
//! or the doubling step for slides) can be missed; the ends found are exact.
//!
//! A gap narrower than the step is not missed where it matters: near a
//! mechanism at a change point (s + l a hair above p + q), the crank's
//! assembly interval ends at two dead points a fraction of a degree apart,
//! and samples on either side both assemble. Approaching a dead point, the
//! pose moves like the square root of the distance to it, not smoothly:
//! where three samples in a row do not lie on a smooth path (the middle
//! pose off the mean of its neighbours by more than [`SMOOTH`] of the
//! mechanism's size), the angles between them are halved until the path is
//! smooth again or a probe does not assemble. A gap down to about 1e-6 rad
//! wide is found that way (a four-bar 1e-12 of its size past its change
//! point).
//!
//! The search only runs a [`Solver`], so planar plans ([`assembly_ranges`])
//! and spatial ones ([`spatial_assembly_ranges`]) share it.

use dofplan_runtime::{BranchPolicy, Break, Ctx, Solver};

use crate::interp::Interpreter;
use crate::model::{Input, InputKind, Mechanism};
use crate::plan::Plan;

/// Break points are found to this, in the input's unit.
pub const TOLERANCE: f64 = 1e-9;

/// Samples of an angle input per degree.
const PER_DEGREE: usize = 1;

/// How far (relative to the mechanism's size) a pose may be off the mean
/// of its two neighbours before the angles between them are halved.
pub const SMOOTH: f64 = 1e-3;

/// Halving stops at this step (degrees), however rough the path.
const FINEST: f64 = 1e-7;

/// A pose of either dimension as the points it carries: where the
/// mechanism's centre and the points one size from it along x and y go.
/// Poses are compared by these (a turn counts as far as it moves them).
pub trait Carried {
    /// The three points, in world coordinates (z = 0 in the plane).
    fn carried(&self, centre: [f64; 3], size: f64) -> [[f64; 3]; 3];
}

impl Carried for dofplan_runtime::Pose {
    fn carried(&self, centre: [f64; 3], size: f64) -> [[f64; 3]; 3] {
        [[0.0, 0.0], [size, 0.0], [0.0, size]].map(|[dx, dy]| {
            let [x, y] = self.world([centre[0] + dx, centre[1] + dy]);
            [x, y, 0.0]
        })
    }
}

impl Carried for dofplan_runtime::spatial::Pose3 {
    fn carried(&self, centre: [f64; 3], size: f64) -> [[f64; 3]; 3] {
        [[0.0, 0.0], [size, 0.0], [0.0, size]].map(|[dx, dy]| {
            let local = [centre[0] + dx, centre[1] + dy, centre[2]];
            let turned = self.rot.apply(local);
            [
                turned[0] + self.pos[0],
                turned[1] + self.pos[1],
                turned[2] + self.pos[2],
            ]
        })
    }
}

/// Where the mechanism is: its centre and size, to compare poses by.
#[derive(Clone, Copy, Debug)]
pub struct Scale {
    /// The mean of the markers as drawn.
    pub centre: [f64; 3],
    /// [`Mechanism::size`].
    pub size: f64,
}

/// One end of an interval where the mechanism assembles.
#[derive(Clone, Debug, PartialEq)]
pub struct End {
    /// The input's value there.
    pub at: f64,
    /// The break just beyond it (step and why); `None` at the end of the
    /// input's range (±180° for an angle, 1,000 sizes for a slide).
    pub brk: Option<Break>,
}

/// The intervals of one input.
#[derive(Clone, Debug, PartialEq)]
pub struct InputRanges {
    /// Index into the mechanism's inputs.
    pub input: usize,
    /// Where it assembles, in increasing order.
    pub intervals: Vec<(End, End)>,
    /// The range searched.
    pub range: (f64, f64),
}

impl InputRanges {
    /// Whether the input turns fully (an angle that assembles over the
    /// whole −180°..180°).
    pub fn full_turn(&self) -> bool {
        matches!(self.intervals.as_slice(), [(a, b)] if a.brk.is_none() && b.brk.is_none())
            && self.range == (-180.0, 180.0)
    }
}

/// The assembly ranges of every input of `m`, by running `plan`.
pub fn assembly_ranges(m: &Mechanism, plan: &Plan) -> Vec<InputRanges> {
    let markers = (m.bodies.iter().flat_map(|b| &b.markers)).map(|k| [k.at[0], k.at[1], 0.0]);
    ranges_of(
        &Interpreter::new(plan.clone()),
        &m.inputs,
        Scale::of(markers, m.size()),
    )
}

impl Scale {
    /// The scale of a mechanism of size `size` whose markers are drawn at
    /// `points`.
    fn of(points: impl Iterator<Item = [f64; 3]>, size: f64) -> Scale {
        let (sum, n) = points.fold(([0.0; 3], 0usize), |(s, n), p| {
            ([s[0] + p[0], s[1] + p[1], s[2] + p[2]], n + 1)
        });
        Scale {
            centre: sum.map(|c| c / n.max(1) as f64),
            size,
        }
    }
}

/// The assembly ranges of every input of the spatial mechanism `m`, by
/// running `plan` (the same search as [`assembly_ranges`]).
pub fn spatial_assembly_ranges(
    m: &crate::model::spatial::Mechanism,
    plan: &crate::plan::spatial::Plan,
) -> Vec<InputRanges> {
    let markers = (m.bodies.iter().flat_map(|b| &b.markers)).map(|k| k.at);
    ranges_of(
        &crate::interp::spatial::Interpreter::new(plan.clone()),
        &m.inputs,
        Scale::of(markers, m.size()),
    )
}

/// The assembly ranges of `inputs` (in plan order) run by `solver`, slides
/// searched out to 1,000 times the mechanism's size.
pub fn ranges_of<S: Solver>(solver: &S, inputs: &[Input], scale: Scale) -> Vec<InputRanges>
where
    S::Pose: Carried,
{
    (0..inputs.len())
        .map(|i| match inputs[i].kind {
            InputKind::Angle => angle_ranges(solver, i, inputs.len(), scale),
            InputKind::Slide => slide_ranges(solver, i, inputs.len(), scale.size),
        })
        .collect()
}

/// Runs the plan at input `i` = `v` (the others 0) from `from`.
fn run<S: Solver>(interp: &S, from: &S::State, i: usize, n: usize, v: f64) -> Result<S::State, Break> {
    let mut inputs = vec![0.0; n];
    inputs[i] = v;
    let mut state = from.clone();
    let mut ctx = Ctx::new(BranchPolicy::Keep, false);
    interp.solve(&mut state, &inputs, &mut ctx).map(|()| state)
}

/// The last value from `ok` toward `bad` at which the plan assembles (to
/// [`TOLERANCE`]), and the break just past it.
fn bisect<S: Solver>(
    interp: &S,
    from: &S::State,
    i: usize,
    n: usize,
    mut ok: f64,
    mut bad: f64,
    mut brk: Break,
) -> (f64, Break) {
    let mut state = from.clone();
    while (bad - ok).abs() > TOLERANCE {
        let mid = 0.5 * (ok + bad);
        if mid == ok || mid == bad {
            break;
        }
        match run(interp, &state, i, n, mid) {
            Ok(s) => {
                state = s;
                ok = mid;
            }
            Err(b) => {
                bad = mid;
                brk = b;
            }
        }
    }
    (ok, brk)
}

/// Samples outward from 0 in one direction (`sign`) up to `limit` (its
/// absolute value): the assembling runs met, each as (start, its break
/// before or `None`, end, its break after or `None`).
fn sweep_side<S: Solver>(interp: &S, at: Probe, sign: f64, samples: usize, limit: f64) -> Vec<(End, End)>
where
    S::Pose: Carried,
{
    let (i, n) = (at.input, at.inputs);
    let drawn = interp.initial_state();
    let mut runs = Vec::new();
    let mut last_ok: Option<(f64, S::State)> = Some((0.0, drawn.clone()));
    // The sample before `last_ok` in the same run, to see whether the path
    // through the last three is smooth; and the sample from which the
    // intervals were last halved (none is halved twice).
    let mut before: Option<(f64, S::State)> = None;
    let mut halved_from = f64::NAN;
    // The carried points of `before`, `last_ok` and the new sample: each
    // pose is carried once (a 20,000-loop chain has 40,000 bodies).
    let mut points: [Vec<Points>; 3] = Default::default();
    carry::<S>(&drawn, at.scale, &mut points[1]);
    let mut start = End { at: 0.0, brk: None };
    for k in 1..=samples {
        let v = sign * limit * k as f64 / samples as f64;
        let from = last_ok.as_ref().map_or(&drawn, |(_, s)| s);
        match run(interp, from, i, n, v) {
            Ok(s) => {
                carry::<S>(&s, at.scale, &mut points[2]);
                if let (Some((v0, s0)), Some((v1, s1))) = (&before, &last_ok) {
                    if off_mean(&points[0], &points[1], &points[2], at.scale) > SMOOTH {
                        // Each side of the rough middle sample, nearest
                        // first; a gap splits the run there.
                        let halves = [(*v0, s0, *v1, s1), (*v1, s1, v, &s)];
                        let gap = halves
                            .into_iter()
                            .filter(|h| h.0 != halved_from)
                            .find_map(|(a, sa, b, sb)| halve(interp, at, (a, sa), (b, sb)));
                        halved_from = *v1;
                        if let Some(gap) = gap {
                            let (ends, next) = split(interp, at, gap);
                            runs.push((std::mem::replace(&mut start, next), ends));
                        }
                    }
                }
                if last_ok.is_none() {
                    // A new run after a gap: its start is a break point,
                    // approached from this side.
                    let prev = sign * limit * (k - 1) as f64 / samples as f64;
                    let brk = run(interp, &s, i, n, prev).err();
                    let (at, brk) = match brk {
                        Some(b) => {
                            let (at, b) = bisect(interp, &s, i, n, v, prev, b);
                            (at, Some(b))
                        }
                        None => (prev, None),
                    };
                    start = End { at, brk };
                }
                before = last_ok.replace((v, s));
                points.rotate_left(1);
            }
            Err(b) => {
                before = None;
                if let Some((ok, s)) = last_ok.take() {
                    let (at, b) = bisect(interp, &s, i, n, ok, v, b);
                    runs.push((start.clone(), End { at, brk: Some(b) }));
                }
            }
        }
    }
    if let Some((v, _)) = last_ok {
        runs.push((start, End { at: v, brk: None }));
    }
    runs
}

/// Which input is searched, of how many, and the mechanism's scale.
#[derive(Clone, Copy)]
struct Probe {
    input: usize,
    inputs: usize,
    scale: Scale,
}

/// A gap met between two samples that assemble: the last value that
/// assembled before it (with its pose), the value found not to assemble,
/// its break, and the first sample past it (with its pose).
struct Gap<State> {
    ok: (f64, State),
    bad: f64,
    brk: Break,
    past: (f64, State),
}

/// A body's carried points (see [`Carried`]).
type Points = [[f64; 3]; 3];

/// Every body's carried points in `state`, into `out`.
fn carry<S: Solver>(state: &S::State, scale: Scale, out: &mut Vec<Points>)
where
    S::Pose: Carried,
{
    out.clear();
    out.extend(
        S::poses(state)
            .iter()
            .map(|p| p.carried(scale.centre, scale.size)),
    );
}

/// How far the poses `mid` are off the mean of `a` and `b`, relative to
/// the mechanism's size: the largest over every body's carried points.
fn off_mean(a: &[Points], mid: &[Points], b: &[Points], scale: Scale) -> f64 {
    let mut worst = 0.0_f64;
    for ((a, m), b) in a
        .iter()
        .flatten()
        .zip(mid.iter().flatten())
        .zip(b.iter().flatten())
    {
        let off = (0..3).map(|c| (m[c] - 0.5 * (a[c] + b[c])).powi(2)).sum::<f64>();
        worst = worst.max(off);
    }
    worst.sqrt() / scale.size
}

/// [`off_mean`] of three states.
fn deviation<S: Solver>(a: &S::State, mid: &S::State, b: &S::State, scale: Scale) -> f64
where
    S::Pose: Carried,
{
    let mut points: [Vec<Points>; 3] = Default::default();
    for (state, out) in [a, mid, b].into_iter().zip(&mut points) {
        carry::<S>(state, scale, out);
    }
    off_mean(&points[0], &points[1], &points[2], scale)
}

/// Halves the step from `a` to `b` (both assemble) while the path is not
/// smooth, down to [`FINEST`]: the first gap met, nearest `a`.
fn halve<S: Solver>(interp: &S, at: Probe, a: (f64, &S::State), b: (f64, &S::State)) -> Option<Gap<S::State>>
where
    S::Pose: Carried,
{
    let m = 0.5 * (a.0 + b.0);
    if (b.0 - a.0).abs() < FINEST || m == a.0 || m == b.0 {
        return None;
    }
    match run(interp, a.1, at.input, at.inputs, m) {
        Err(brk) => Some(Gap {
            ok: (a.0, a.1.clone()),
            bad: m,
            brk,
            past: (b.0, b.1.clone()),
        }),
        Ok(sm) => {
            if deviation::<S>(a.1, &sm, b.1, at.scale) <= SMOOTH {
                return None;
            }
            halve(interp, at, a, (m, &sm)).or_else(|| halve(interp, at, (m, &sm), b))
        }
    }
}

/// The end of the run before `gap` and the start of the run after it, each
/// bisected to the break point from its own side.
fn split<S: Solver>(interp: &S, at: Probe, gap: Gap<S::State>) -> (End, End) {
    let (i, n) = (at.input, at.inputs);
    let (end, brk) = bisect(interp, &gap.ok.1, i, n, gap.ok.0, gap.bad, gap.brk);
    let start = match run(interp, &gap.past.1, i, n, gap.bad) {
        Err(b) => {
            let (at, b) = bisect(interp, &gap.past.1, i, n, gap.past.0, gap.bad, b);
            End { at, brk: Some(b) }
        }
        // Assembles from the far side (a numeric cluster's other root):
        // the gap is as narrow as the probe shows.
        Ok(_) => End {
            at: gap.bad,
            brk: Some(brk),
        },
    };
    (
        End {
            at: end,
            brk: Some(brk),
        },
        start,
    )
}

/// Over −180°..180°.
fn angle_ranges<S: Solver>(interp: &S, i: usize, n: usize, scale: Scale) -> InputRanges
where
    S::Pose: Carried,
{
    let samples = 180 * PER_DEGREE;
    let at = Probe {
        input: i,
        inputs: n,
        scale,
    };
    let up = sweep_side(interp, at, 1.0, samples, 180.0);
    let down = sweep_side(interp, at, -1.0, samples, 180.0);
    InputRanges {
        input: i,
        intervals: join(up, down),
        range: (-180.0, 180.0),
    }
}

/// From 0 outward, doubling, to 1,000 sizes.
fn slide_ranges<S: Solver>(interp: &S, i: usize, n: usize, size: f64) -> InputRanges {
    let limit = 1000.0 * size;
    let side = |sign: f64| -> End {
        let mut state = interp.initial_state();
        let mut ok = 0.0;
        let mut step = size / 64.0;
        loop {
            let v = (ok + sign * step).clamp(-limit, limit);
            match run(interp, &state, i, n, v) {
                Ok(s) => {
                    state = s;
                    ok = v;
                    if v.abs() >= limit {
                        return End { at: v, brk: None };
                    }
                    step *= 2.0;
                }
                Err(b) => {
                    let (at, b) = bisect(interp, &state, i, n, ok, v, b);
                    return End { at, brk: Some(b) };
                }
            }
        }
    };
    let (hi, lo) = (side(1.0), side(-1.0));
    InputRanges {
        input: i,
        intervals: vec![(lo, hi)],
        range: (-limit, limit),
    }
}

/// The runs of both sides as intervals in increasing order: the two runs
/// that start at 0 are one interval.
fn join(up: Vec<(End, End)>, down: Vec<(End, End)>) -> Vec<(End, End)> {
    let mut out: Vec<(End, End)> = down.into_iter().map(|(a, b)| (b, a)).collect();
    out.reverse();
    let mut up = up.into_iter();
    match (out.last_mut(), up.next()) {
        (Some(last), Some(first)) if last.1.at == 0.0 && first.0.at == 0.0 => last.1 = first.1,
        (_, Some(first)) => out.push(first),
        _ => {}
    }
    out.extend(up);
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::analyse;
    use crate::conflict::load_str;
    use crate::model::Format;

    fn ranges_of(text: &str) -> Vec<InputRanges> {
        let m = load_str("m.toml", text, Format::Toml).unwrap();
        let plan = analyse(&m).plan.unwrap();
        assembly_ranges(&m, &plan)
    }

    /// A four-bar 6.6e-6 past its change point (s + l > p + q, a result
    /// of path synthesis): the crank stops at two dead points about a
    /// quarter of a degree apart, where the coupler and the rocker fold
    /// (|BD| = c − b). Samples every degree both assemble around that gap;
    /// the ends are found where the law of cosines in triangle ABD puts
    /// them, computed here from the markers.
    #[test]
    fn a_gap_narrower_than_a_sample_step_is_found() {
        // As synthesised, and mirrored (y → −y: the gap on the negative
        // side, found by the sweep downward from the drawing).
        for flip in [1.0, -1.0] {
            gap_is_found(flip);
        }
    }

    fn gap_is_found(flip: f64) {
        let [a, b, c, d, p] = [
            [0.88798882428, 0.12965620756],
            [1.83279395081, 0.76590906965],
            [1.82529464191, 1.98817236498],
            [-0.20150880004, 1.75524107588],
            [0.65772839492, 2.05154987731],
        ]
        .map(|[x, y]: [f64; 2]| format!("[{x:?}, {:?}]", flip * y));
        let text = include_str!("../../../mechanisms/fourbar.toml");
        let text = [
            ("{ A = [0, 0], D = [4, 0] }", format!("{{ A = {a}, D = {d} }}")),
            ("{ A = [0, 0], B = [1, 1] }", format!("{{ A = {a}, B = {b} }}")),
            (
                "{ B = [1, 1], C = [4.5, 2.5], P = [3, 3.5] }",
                format!("{{ B = {b}, C = {c}, P = {p} }}"),
            ),
            (
                "{ C = [4.5, 2.5], D = [4, 0] }",
                format!("{{ C = {c}, D = {d} }}"),
            ),
        ]
        .iter()
        .fold(text.to_string(), |t, (from, to)| {
            assert!(t.contains(from), "{from}");
            t.replace(from, to)
        });
        let m = load_str("m.toml", &text, Format::Toml).unwrap();
        let p = |b: &str, k: &str| {
            let body = m.bodies.iter().find(|x| x.name == b).unwrap();
            body.markers.iter().find(|x| x.name == k).unwrap().at
        };
        let d = |u: [f64; 2], v: [f64; 2]| (u[0] - v[0]).hypot(u[1] - v[1]);
        let (a, b, c, g) = (
            d(p("ground", "A"), p("crank", "B")),
            d(p("coupler", "B"), p("coupler", "C")),
            d(p("rocker", "C"), p("rocker", "D")),
            d(p("ground", "A"), p("ground", "D")),
        );
        assert!(
            a + c > b + g && a + c - b - g < 1e-5,
            "just past the change point"
        );
        // The crank's angle from AD at the dead points, and as drawn.
        let fold = ((a * a + g * g - (c - b) * (c - b)) / (2.0 * a * g))
            .acos()
            .to_degrees();
        let dir = |u: [f64; 2], v: [f64; 2]| (v[1] - u[1]).atan2(v[0] - u[0]).to_degrees();
        let drawn = dir(p("ground", "A"), p("crank", "B")) - dir(p("ground", "A"), p("ground", "D"));
        let wrap = |x: f64| (x + 540.0).rem_euclid(360.0) - 180.0;
        let (e1, e2) = (wrap(-fold - drawn), wrap(fold - drawn));
        let r = ranges_of(&text);
        assert!(!r[0].full_turn(), "{r:?}");
        let ends: Vec<f64> = (r[0].intervals.iter())
            .flat_map(|(lo, hi)| [lo, hi])
            .filter(|e| e.brk.is_some())
            .map(|e| e.at)
            .collect();
        assert_eq!(ends.len(), 2, "{r:?}");
        let (lo, hi) = (ends[0].min(ends[1]), ends[0].max(ends[1]));
        let (x1, x2) = (e1.min(e2), e1.max(e2));
        assert!(
            (lo - x1).abs() < 1e-7 && (hi - x2).abs() < 1e-7,
            "{lo} {hi} vs {x1} {x2}"
        );
        assert!(hi - lo < 0.5, "a gap of a fraction of a degree: {lo} … {hi}");
    }

    #[test]
    fn a_crank_rocker_turns_fully() {
        let r = ranges_of(include_str!("../../../mechanisms/fourbar.toml"));
        assert!(r[0].full_turn(), "{r:?}");
    }

    /// rocker_rocker's break points from the law of cosines in triangle
    /// ABD with B–C–D stretched (|BD| = b + c), computed here from its
    /// markers, not taken from the file's comment.
    #[test]
    fn a_double_rocker_breaks_where_the_law_of_cosines_says() {
        let text = include_str!("../../../mechanisms/rocker_rocker.toml");
        let m = load_str("m.toml", text, Format::Toml).unwrap();
        let p = |b: &str, k: &str| {
            let body = m.bodies.iter().find(|x| x.name == b).unwrap();
            body.markers.iter().find(|x| x.name == k).unwrap().at
        };
        let d = |u: [f64; 2], v: [f64; 2]| (u[0] - v[0]).hypot(u[1] - v[1]);
        let (a, b, c, g) = (
            d(p("input", "A"), p("input", "B")),
            d(p("coupler", "B"), p("coupler", "C")),
            d(p("output", "C"), p("output", "D")),
            d(p("ground", "A"), p("ground", "D")),
        );
        let drawn = {
            let v = p("input", "B");
            v[1].atan2(v[0]).to_degrees()
        };
        let star = ((a * a + g * g - (b + c) * (b + c)) / (2.0 * a * g))
            .acos()
            .to_degrees();
        let r = ranges_of(text);
        let [(lo, hi)] = r[0].intervals.as_slice() else {
            panic!("one interval: {r:?}")
        };
        assert!(
            (lo.at - (-star - drawn)).abs() < 1e-8,
            "{lo:?} vs {}",
            -star - drawn
        );
        assert!(
            (hi.at - (star - drawn)).abs() < 1e-8,
            "{hi:?} vs {}",
            star - drawn
        );
        assert!(lo.brk.is_some() && hi.brk.is_some());
    }

    /// The spatial Scotch yoke (tests/fixtures/spatial/yoke.toml): the
    /// rocker's pin C, at radius 1 about the z axis, stays in the slot
    /// x = 0.6 + s, which meets the circle while |0.6 + s| ≤ 1: s from −1.6
    /// to 0.4.
    #[test]
    fn a_spatial_yoke_slides_while_its_slot_meets_the_circle() {
        let text = include_str!("../../../tests/fixtures/spatial/yoke.toml");
        let crate::model::Model::Spatial(m) =
            crate::conflict::load_any_str("yoke.toml", text, Format::Toml).unwrap()
        else {
            panic!("a spatial file")
        };
        let plan = crate::analysis::spatial::analyse(&m).unwrap();
        let r = spatial_assembly_ranges(&m, &plan);
        let [(lo, hi)] = r[0].intervals.as_slice() else {
            panic!("one interval: {r:?}")
        };
        assert!(lo.brk.is_some() && hi.brk.is_some(), "{r:?}");
        assert!((lo.at + 1.6).abs() < 1e-8 && (hi.at - 0.4).abs() < 1e-8, "{r:?}");
    }

    #[test]
    fn a_trammel_slides_until_its_bar_cannot_reach() {
        let text = include_str!("../../../mechanisms/trammel.toml");
        let r = ranges_of(text);
        let [(lo, hi)] = r[0].intervals.as_slice() else {
            panic!("one interval: {r:?}")
        };
        assert!(lo.brk.is_some() && hi.brk.is_some(), "{r:?}");
        // The bar (L = 2) reaches the y track while its pin X = 1 + s is
        // within L of it: s from −3 to 1.
        assert!((lo.at + 3.0).abs() < 1e-6 && (hi.at - 1.0).abs() < 1e-6, "{r:?}");
    }
}
