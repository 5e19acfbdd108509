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
    ranges_of(&Interpreter::new(plan.clone()), &m.inputs, m.size())
}

/// The assembly ranges of every input of the spatial mechanism `m`, by
/// running `plan` (the same search as [`assembly_ranges`]).
pub fn spatial_assembly_ranges(
    m: &crate::model::spatial::Mechanism,
    plan: &crate::plan::spatial::Plan,
) -> Vec<InputRanges> {
    ranges_of(
        &crate::interp::spatial::Interpreter::new(plan.clone()),
        &m.inputs,
        m.size(),
    )
}

/// The assembly ranges of `inputs` (in plan order) run by `solver`, slides
/// searched out to 1,000 times `size`.
pub fn ranges_of<S: Solver>(solver: &S, inputs: &[Input], size: f64) -> Vec<InputRanges> {
    (0..inputs.len())
        .map(|i| match inputs[i].kind {
            InputKind::Angle => angle_ranges(solver, i, inputs.len()),
            InputKind::Slide => slide_ranges(solver, i, inputs.len(), size),
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
fn sweep_side<S: Solver>(
    interp: &S,
    i: usize,
    n: usize,
    sign: f64,
    samples: usize,
    limit: f64,
) -> Vec<(End, End)> {
    let drawn = interp.initial_state();
    let mut runs = Vec::new();
    let mut last_ok: Option<(f64, S::State)> = Some((0.0, drawn.clone()));
    let mut start = End { at: 0.0, brk: None };
    for k in 1..=samples {
        let v = sign * limit * k as f64 / samples as f64;
        let from = last_ok.as_ref().map_or(&drawn, |(_, s)| s);
        match run(interp, from, i, n, v) {
            Ok(s) => {
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
                last_ok = Some((v, s));
            }
            Err(b) => {
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

/// Over −180°..180°.
fn angle_ranges<S: Solver>(interp: &S, i: usize, n: usize) -> InputRanges {
    let samples = 180 * PER_DEGREE;
    let up = sweep_side(interp, i, n, 1.0, samples, 180.0);
    let down = sweep_side(interp, i, n, -1.0, samples, 180.0);
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
