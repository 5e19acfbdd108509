//! The ends of a slot: a pin runs along a straight or circular slot
//! between two ends, which are assembly limits like the circles' reach.

use super::Real;
use crate::frame::{lanes_differ, BreakKind};
use crate::{Break, Ctx, StepId};

/// Checks that a pin at `pin` lies between the ends of the slot through
/// `at` along the unit direction `dir` (both world): its position along
/// the slot, `(pin − at)·dir`, within `ends` (from `at`, in length units).
/// Past an end the frame breaks, by how far past as the gap (the stretch
/// policy lets the pin run on along the slot's line).
#[inline]
pub fn within_ends<T: Real>(
    ctx: &mut Ctx,
    step: StepId,
    at: [T; 2],
    dir: [T; 2],
    pin: [T; 2],
    ends: [f64; 2],
) -> Result<(), Break> {
    let along = (pin[0] - at[0]) * dir[0] + (pin[1] - at[1]) * dir[1];
    let [lo, hi] = ends;
    if along.any(|s| s < lo || s > hi) {
        lanes_differ::<T>(step)?;
        let value = |p: [T; 2]| [p[0].value(), p[1].value()];
        let gap = past_line_end(value(at), value(dir), value(pin), ends);
        ctx.fail(step, BreakKind::PastSlotEnd, gap)?;
    }
    Ok(())
}

/// Checks that a pin at `pin` lies between the ends of the circular slot
/// about `centre` (both world): its angle about the centre, counted
/// counter-clockwise from the unit direction `dir` (world) in degrees,
/// within `ends` (low then high, at most a turn apart; the angle is
/// taken in the turn that starts at the low end). Past an end the frame
/// breaks, by the arc length past the nearer end as the gap.
#[inline]
pub fn within_arc<T: Real>(
    ctx: &mut Ctx,
    step: StepId,
    centre: [T; 2],
    dir: [T; 2],
    pin: [T; 2],
    ends: [f64; 2],
) -> Result<(), Break> {
    let v = [pin[0] - centre[0], pin[1] - centre[1]];
    let across = dir[0] * v[1] - dir[1] * v[0];
    let along = dir[0] * v[0] + dir[1] * v[1];
    let angle = across.atan2(along).mul_f64(180.0 / std::f64::consts::PI);
    let [lo, hi] = ends;
    if angle.any(|deg| (deg - lo).rem_euclid(360.0) > hi - lo) {
        lanes_differ::<T>(step)?;
        let value = |p: [T; 2]| [p[0].value(), p[1].value()];
        let gap = past_arc_end(value(centre), value(dir), value(pin), ends);
        ctx.fail(step, BreakKind::PastSlotEnd, gap)?;
    }
    Ok(())
}

/// How far the pin at `pin` is past the nearer end of the straight slot
/// through `at` along the unit `dir` (all world), along it: positive past
/// an end, negative or zero between them.
pub fn past_line_end(at: [f64; 2], dir: [f64; 2], pin: [f64; 2], ends: [f64; 2]) -> f64 {
    let s = (pin[0] - at[0]) * dir[0] + (pin[1] - at[1]) * dir[1];
    (ends[0] - s).max(s - ends[1])
}

/// How far the pin at `pin` is past the nearer end of the circular slot
/// about `centre` whose ends are angles in degrees from the unit `dir`
/// (all world), as the arc length at the pin's radius: positive past an
/// end, negative or zero between them.
pub fn past_arc_end(centre: [f64; 2], dir: [f64; 2], pin: [f64; 2], ends: [f64; 2]) -> f64 {
    let v = [pin[0] - centre[0], pin[1] - centre[1]];
    let angle = (dir[0] * v[1] - dir[1] * v[0])
        .atan2(dir[0] * v[0] + dir[1] * v[1])
        .to_degrees();
    let (span, from_lo) = (ends[1] - ends[0], (angle - ends[0]).rem_euclid(360.0));
    let past = if from_lo <= span {
        -from_lo.min(span - from_lo)
    } else {
        // Past the high end by `from_lo − span`, or short of the low end
        // by the rest of the turn: the nearer of the two.
        (from_lo - span).min(360.0 - from_lo)
    };
    past.to_radians() * v[0].hypot(v[1])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::BranchPolicy;

    #[test]
    fn a_pin_past_an_end_breaks_by_how_far() {
        let mut ctx = Ctx::new(BranchPolicy::Keep, false);
        let at = [1.0, 0.0];
        let dir = [0.0, 1.0];
        assert!(within_ends(&mut ctx, 3, at, dir, [1.0, 0.5], [-1.0, 1.0]).is_ok());
        let brk = within_ends(&mut ctx, 3, at, dir, [1.0, 1.25], [-1.0, 1.0]).unwrap_err();
        assert_eq!((brk.step, brk.kind), (3, BreakKind::PastSlotEnd));
        assert!((brk.gap - 0.25).abs() < 1e-15);
        let brk = within_ends(&mut ctx, 3, at, dir, [1.0, -1.5], [-1.0, 1.0]).unwrap_err();
        assert!((brk.gap - 0.5).abs() < 1e-15);
    }

    #[test]
    fn a_pin_past_an_arc_end_breaks_by_the_arc_length() {
        let mut ctx = Ctx::new(BranchPolicy::Keep, false);
        let (c, dir) = ([1.0, 1.0], [0.0, 1.0]);
        let at = |deg: f64| {
            let (s, co) = (90.0 + deg).to_radians().sin_cos();
            [1.0 + 2.0 * co, 1.0 + 2.0 * s]
        };
        // Ends across the slot's dir's back: 150° to 210° is one arc.
        for deg in [150.5, 180.0, 209.5, -170.0] {
            assert!(
                within_arc(&mut ctx, 4, c, dir, at(deg), [150.0, 210.0]).is_ok(),
                "{deg}"
            );
        }
        let brk = within_arc(&mut ctx, 4, c, dir, at(215.0), [150.0, 210.0]).unwrap_err();
        assert_eq!((brk.step, brk.kind), (4, BreakKind::PastSlotEnd));
        assert!((brk.gap - 5f64.to_radians() * 2.0).abs() < 1e-12, "{}", brk.gap);
        // Nearer the low end than the high one: measured from the low end.
        let brk = within_arc(&mut ctx, 4, c, dir, at(140.0), [150.0, 210.0]).unwrap_err();
        assert!((brk.gap - 10f64.to_radians() * 2.0).abs() < 1e-12, "{}", brk.gap);
        // Between the ends: minus the arc length to the nearer one.
        let inside = past_arc_end(c, dir, at(200.0), [150.0, 210.0]);
        assert!((inside + 10f64.to_radians() * 2.0).abs() < 1e-12, "{inside}");
    }
}
