//! The ends of a slot: a pin runs along a straight slot between two ends,
//! which are assembly limits like the circles' reach.

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
        let s = along.value();
        ctx.fail(step, BreakKind::PastSlotEnd, (lo - s).max(s - hi))?;
    }
    Ok(())
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
}
