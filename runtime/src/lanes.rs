//! Several frames at once: [`Lanes`] holds one number of [`LANES`] frames
//! side by side, so a compiled plan's steps — the same generic runtime
//! functions a frame runs on `f64` — solve that many frames together, in
//! vector registers where the target has them.
//!
//! Under the keep-branch policy a closed-form plan's frames do not depend
//! on each other: the branch of each step is the one chosen at plan time,
//! and a frame reads nothing its predecessor wrote. So a sweep can be cut
//! into groups of [`LANES`] frames solved together. A step whose frames do
//! not all take its usual path (one at a dead point, one apart) gives up on
//! the group ([`BreakKind::LanesDiffer`](crate::frame::BreakKind::LanesDiffer)),
//! and [`crate::batch`] solves those frames one at a time.

use std::ops::{Add, Div, Mul, Neg, Sub};

use crate::planar::{Degrees, Rot};
use crate::scalar::{Factor, Real};

/// Frames a [`Lanes`] holds: eight `f64`s, two AVX or four SSE2 registers —
/// enough independent work to hide a square root's or a division's latency.
pub const LANES: usize = 8;

/// One number of [`LANES`] frames.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lanes(pub [f64; LANES]);

impl Lanes {
    /// Every lane `x`.
    #[inline(always)]
    pub const fn splat(x: f64) -> Lanes {
        Lanes([x; LANES])
    }

    /// `f` of each lane.
    #[inline(always)]
    pub fn map(self, f: impl Fn(f64) -> f64) -> Lanes {
        let mut r = self.0;
        for x in &mut r {
            *x = f(*x);
        }
        Lanes(r)
    }
}

// Plain loops over the lanes, not `array::from_fn`: in a plan of hundreds
// of steps the inliner's budget runs out, and an operation left as a call
// per lane is no longer done side by side.
macro_rules! lanewise {
    ($trait:ident, $method:ident, $op:tt) => {
        impl $trait for Lanes {
            type Output = Lanes;
            #[inline(always)]
            fn $method(self, o: Lanes) -> Lanes {
                let mut r = [0.0; LANES];
                for i in 0..LANES {
                    r[i] = self.0[i] $op o.0[i];
                }
                Lanes(r)
            }
        }
    };
}

lanewise!(Add, add, +);
lanewise!(Sub, sub, -);
lanewise!(Mul, mul, *);
lanewise!(Div, div, /);

impl Neg for Lanes {
    type Output = Lanes;
    #[inline(always)]
    fn neg(self) -> Lanes {
        let mut r = self.0;
        for x in &mut r {
            *x = -*x;
        }
        Lanes(r)
    }
}

impl Real for Lanes {
    const LANES: bool = true;

    #[inline(always)]
    fn cst(x: f64) -> Lanes {
        Lanes::splat(x)
    }

    /// The first lane's value. Steps decide with [`Real::all`] and
    /// [`Real::select`]; `value` is read only on a path the lanes leave
    /// by [`crate::frame::lanes_differ`] or a break, whose numbers are
    /// thrown away.
    #[inline(always)]
    fn value(self) -> f64 {
        self.0[0]
    }

    #[inline(always)]
    fn sqrt(self) -> Lanes {
        let mut r = self.0;
        for x in &mut r {
            *x = x.sqrt();
        }
        Lanes(r)
    }

    /// Positions only: lanes carry no rates, so no dead point to report.
    #[inline(always)]
    fn sqrt_dead(self, _: f64) -> Lanes {
        self.sqrt()
    }

    #[inline(always)]
    fn all(self, f: impl Fn(f64) -> bool) -> bool {
        // Not `Iterator::all`: its early exit would keep the comparisons
        // from being done side by side.
        self.0.iter().fold(true, |ok, &x| ok & f(x))
    }

    #[inline(always)]
    fn any(self, f: impl Fn(f64) -> bool) -> bool {
        self.0.iter().fold(false, |any, &x| any | f(x))
    }

    #[inline(always)]
    fn select(self, f: impl Fn(f64) -> bool, then: Lanes, otherwise: Lanes) -> Lanes {
        let mut r = otherwise.0;
        for ((r, x), t) in r.iter_mut().zip(self.0).zip(then.0) {
            if f(x) {
                *r = t;
            }
        }
        Lanes(r)
    }

    // What the spatial steps need (they are not run on lanes, but a
    // `Real` has them): lane by lane, as `f64` has them.
    const JETS: bool = false;

    /// Every lane `v` (on `f64`, the value itself).
    #[inline(always)]
    fn with_value(self, v: f64) -> Lanes {
        Lanes::splat(v)
    }

    #[inline(always)]
    fn atan2(self, x: Lanes) -> Lanes {
        let mut r = self.0;
        for (r, x) in r.iter_mut().zip(x.0) {
            *r = r.atan2(x);
        }
        Lanes(r)
    }

    #[inline(always)]
    fn sin_cos(self) -> (Lanes, Lanes) {
        (self.map(f64::sin), self.map(f64::cos))
    }

    #[inline(always)]
    fn mul_f64(self, k: f64) -> Lanes {
        // The lanewise product with k in every lane: the same numbers, and
        // the same plain loop the other operations are (see `lanewise`).
        self * Lanes::splat(k)
    }
}

/// Lanes multiply by lanes of their own kind (the constant factors are the
/// `f64`s every `Real` takes).
impl Factor<Lanes> for Lanes {
    #[inline(always)]
    fn times(self, x: Lanes) -> Lanes {
        x.vmul(self)
    }
    #[inline(always)]
    fn lift(self) -> Lanes {
        self
    }
}

impl Degrees for Lanes {
    #[inline(always)]
    fn degrees_rot(self) -> Rot<Lanes> {
        Rot::from_degrees_lanes(self)
    }
}

impl Rot<Lanes> {
    /// [`Rot::from_degrees`] of each lane, with its numbers exactly.
    #[inline(always)]
    pub fn from_degrees_lanes(degrees: Lanes) -> Rot<Lanes> {
        let mut r = Rot {
            c: Lanes::splat(0.0),
            s: Lanes::splat(0.0),
        };
        // The usual angles side by side (the table read is a gather);
        // huge or non-finite ones each by its own path.
        if degrees.all(Rot::in_table_range) {
            for i in 0..LANES {
                let x = Rot::from_degrees_in_range(degrees.0[i]);
                r.c.0[i] = x.c;
                r.s.0[i] = x.s;
            }
        } else {
            for i in 0..LANES {
                let x = Rot::from_degrees(degrees.0[i]);
                r.c.0[i] = x.c;
                r.s.0[i] = x.s;
            }
        }
        r
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each lane computes what `f64` computes, bit for bit, and decisions
    /// hold of every lane or of none.
    #[test]
    fn lanes_are_independent_f64s() {
        let a = Lanes(std::array::from_fn(|i| 1.0 + i as f64 * 0.37));
        let b = Lanes(std::array::from_fn(|i| 2.5 - i as f64 * 0.11));
        let r = (a * b - a / b).sqrt() + -a;
        for i in 0..LANES {
            let (x, y) = (a.0[i], b.0[i]);
            assert_eq!(r.0[i], (x * y - x / y).sqrt() + -x);
        }
        assert!(a.all(|x| x > 0.0));
        assert!(!a.all(|x| x > 1.0));
        let s = a.select(|x| x > 2.0, a, b);
        for i in 0..LANES {
            assert_eq!(s.0[i], if a.0[i] > 2.0 { a.0[i] } else { b.0[i] });
        }
        // Usual angles side by side, and a group with a huge and a
        // non-finite one, each lane as `Rot::from_degrees` gives it.
        let usual = Lanes(std::array::from_fn(|i| -400.0 + 97.3 * i as f64));
        let mut odd = usual;
        odd.0[1] = 3e15 + 90.0;
        odd.0[2] = f64::NAN;
        for d in [usual, odd] {
            let rot = Rot::from_degrees_lanes(d);
            for i in 0..LANES {
                let one = Rot::from_degrees(d.0[i]);
                assert_eq!(rot.c.0[i].to_bits(), one.c.to_bits());
                assert_eq!(rot.s.0[i].to_bits(), one.s.to_bits());
            }
        }
    }
}
