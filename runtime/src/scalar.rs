//! The numbers plan steps compute with: `f64` for positions, and [`Jet2`]
//! — a value with its first and second derivatives along one direction of
//! the inputs (time, or one input) — for velocities and accelerations by
//! forward-mode differentiation through the very same step functions —
//! and [`Tangent`], first derivatives along many directions at once (a
//! candidate's design parameters).
//!
//! The planar steps are written once, generic over [`Real`]; every
//! decision they take (which root, whether circles meet) is taken on
//! [`Real::value`], so a run with jets follows the branches of the run with
//! `f64` and only adds the derivatives.
//!
//! This is the bottom layer of the runtime: it names nothing else of the
//! crate, and lanes, poses and rates build on it (the crate's `real`
//! module re-exports it under the path generated code names).

use std::fmt::Debug;
use std::ops::{Add, Div, Mul, Neg, Sub};

mod tangent;
pub use tangent::Tangent;

/// A number a plan step computes with.
pub trait Real:
    Copy
    + Debug
    + PartialEq
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + Factor<Self>
{
    /// A constant (derivatives 0).
    fn cst(x: f64) -> Self;
    /// The value, on which every decision is taken.
    fn value(self) -> f64;
    /// The square root.
    fn sqrt(self) -> Self;
    /// The square root of a quantity that vanishes at a dead point (a
    /// half-chord squared): at or below `dead` (in the value's units) the
    /// rates through it are reported infinite — a value this close to the
    /// dead point has rates that are huge and meaningless, not numbers to
    /// print. The value itself is the plain square root.
    fn sqrt_dead(self, dead: f64) -> Self;

    /// Whether the number holds several frames' values side by side (the
    /// runtime's `Lanes`): a step then takes its usual path only when every
    /// lane does, and gives up on the frames together (a `LanesDiffer`
    /// break, after which they are solved one at a time) where one of them
    /// would take another.
    const LANES: bool = false;

    /// Whether `f` holds of the value (of every lane's value, for lanes):
    /// the test of a step's usual path.
    #[inline(always)]
    fn all(self, f: impl Fn(f64) -> bool) -> bool {
        f(self.value())
    }

    /// Whether `f` holds of the value (of some lane's value, for lanes):
    /// the test of leaving a step's usual path.
    #[inline(always)]
    fn any(self, f: impl Fn(f64) -> bool) -> bool {
        f(self.value())
    }

    /// Per value (per lane): `then` where `f` holds of `self`, else
    /// `otherwise`.
    #[inline(always)]
    fn select(self, f: impl Fn(f64) -> bool, then: Self, otherwise: Self) -> Self {
        if f(self.value()) {
            then
        } else {
            otherwise
        }
    }

    // --- What the spatial steps need besides (kept apart from the above).

    /// Whether this type carries derivatives (false for `f64`): a step
    /// whose `f64` path takes a shortcut that drops a dependence (a turn
    /// within rounding of none, taken as none) takes it on values only
    /// when this is true.
    const JETS: bool;
    /// `self`'s derivatives with the value `v` (for `f64`, `v`): a
    /// shortcut's exact value with the rates of the formula it stands for.
    fn with_value(self, v: f64) -> Self;
    /// The angle of the point (`x`, `self`), as `f64::atan2`.
    fn atan2(self, x: Self) -> Self;
    /// The sine and the cosine (radians).
    fn sin_cos(self) -> (Self, Self);
    /// `self·k` for a constant `k` (for `f64`, the same product).
    fn mul_f64(self, k: f64) -> Self;
    /// `self + o`, `self − o`, `self·o` and `self·k` as the spatial steps'
    /// vector and rotation arithmetic does them: the same numbers as the
    /// operators; on jets, in optimised x86_64 builds, with both rates in
    /// one two-lane register (about half the instructions for the rates —
    /// which the planar steps, whose points LLVM already packs by pairs of
    /// coordinates, do not gain from, so they keep the operators).
    #[inline(always)]
    fn vadd(self, o: Self) -> Self {
        self + o
    }
    /// See [`Real::vadd`].
    #[inline(always)]
    fn vsub(self, o: Self) -> Self {
        self - o
    }
    /// See [`Real::vadd`].
    #[inline(always)]
    fn vmul(self, o: Self) -> Self {
        self * o
    }
    /// See [`Real::vadd`].
    #[inline(always)]
    fn vmul_f64(self, k: f64) -> Self {
        self.mul_f64(k)
    }
    /// `1/self`: the quotient of a constant, whose zero derivatives jets
    /// need not carry through a division (the value is the plain `1.0 /
    /// self`).
    #[inline(always)]
    fn recip(self) -> Self {
        Self::cst(1.0) / self
    }
    /// Zero when the rates are exactly zero (always, for numbers without
    /// rates): a product by a factor without rates can then skip the
    /// terms that would multiply them.
    #[inline(always)]
    fn rate_bits(self) -> u64 {
        0
    }
}

/// A factor of a step's products: a number of the step's own kind, or a
/// plain constant (a fixed direction of the plan), which jets and lanes
/// multiply by at a third of a product's cost and with the same values
/// (`f64` products commute exactly).
pub trait Factor<T>: Copy {
    /// `x·self`.
    fn times(self, x: T) -> T;
    /// `self` as a number of the step's kind (a constant: derivatives 0).
    fn lift(self) -> T;
    /// `x·self` as the planar steps multiply a body's local point: for a
    /// constant, [`Real::mul_f64`] (whose points LLVM packs by pairs of
    /// coordinates already, see [`Real::vadd`]); otherwise [`times`](Self::times).
    #[inline(always)]
    fn scale(self, x: T) -> T {
        self.times(x)
    }
}

impl<T: Real> Factor<T> for f64 {
    #[inline(always)]
    fn times(self, x: T) -> T {
        x.vmul_f64(self)
    }
    #[inline(always)]
    fn scale(self, x: T) -> T {
        x.mul_f64(self)
    }
    #[inline(always)]
    fn lift(self) -> T {
        T::cst(self)
    }
}

impl Factor<Jet2> for Jet2 {
    #[inline(always)]
    fn times(self, x: Jet2) -> Jet2 {
        x.vmul(self)
    }
    #[inline(always)]
    fn lift(self) -> Jet2 {
        self
    }
}

impl Real for f64 {
    #[inline(always)]
    fn cst(x: f64) -> f64 {
        x
    }
    #[inline(always)]
    fn value(self) -> f64 {
        self
    }
    #[inline(always)]
    fn sqrt(self) -> f64 {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn sqrt_dead(self, _: f64) -> f64 {
        f64::sqrt(self)
    }

    // --- Spatial steps.

    const JETS: bool = false;
    #[inline(always)]
    fn with_value(self, v: f64) -> f64 {
        v
    }
    #[inline(always)]
    fn atan2(self, x: f64) -> f64 {
        f64::atan2(self, x)
    }
    #[inline(always)]
    fn sin_cos(self) -> (f64, f64) {
        f64::sin_cos(self)
    }
    #[inline(always)]
    fn mul_f64(self, k: f64) -> f64 {
        self * k
    }
}

/// A value with its first and second derivatives along one direction:
/// `x(t)` as `x`, `ẋ`, `ẍ`. Seeded with an input's value, rate and
/// acceleration it carries velocities and accelerations; seeded with
/// (θ, 1, 0) it carries d/dθ and d²/dθ².
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Jet2 {
    /// The value.
    pub v: f64,
    /// The first derivative.
    pub d: f64,
    /// The second derivative.
    pub dd: f64,
}

impl Jet2 {
    /// A jet.
    pub const fn new(v: f64, d: f64, dd: f64) -> Jet2 {
        Jet2 { v, d, dd }
    }

    /// Whether the derivatives are finite (not at a dead point, where a
    /// square root of zero has a nonzero rate).
    pub fn finite(self) -> bool {
        self.d.is_finite() && self.dd.is_finite()
    }

    /// Zero when the derivatives are finite, nonzero when one is infinite
    /// or NaN (`x·0` is ±0 for a finite `x` and NaN otherwise; the sign is
    /// shifted out). The checks of whole frames OR these together: no
    /// branch a value, so they vectorise.
    #[inline(always)]
    pub fn nonfinite_bits(self) -> u64 {
        ((self.d * 0.0).to_bits() | (self.dd * 0.0).to_bits()) << 1
    }
}

impl Add for Jet2 {
    type Output = Jet2;
    #[inline(always)]
    fn add(self, o: Jet2) -> Jet2 {
        Jet2::new(self.v + o.v, self.d + o.d, self.dd + o.dd)
    }
}

impl Sub for Jet2 {
    type Output = Jet2;
    #[inline(always)]
    fn sub(self, o: Jet2) -> Jet2 {
        Jet2::new(self.v - o.v, self.d - o.d, self.dd - o.dd)
    }
}

impl Neg for Jet2 {
    type Output = Jet2;
    #[inline(always)]
    fn neg(self) -> Jet2 {
        Jet2::new(-self.v, -self.d, -self.dd)
    }
}

impl Mul for Jet2 {
    type Output = Jet2;
    /// (ab)' = a'b + ab', (ab)'' = a''b + 2a'b' + ab''.
    #[inline(always)]
    fn mul(self, o: Jet2) -> Jet2 {
        Jet2::new(
            self.v * o.v,
            self.d * o.v + self.v * o.d,
            self.dd * o.v + 2.0 * self.d * o.d + self.v * o.dd,
        )
    }
}

impl Div for Jet2 {
    type Output = Jet2;
    /// q = a/b: q' = (a' − q b')/b, q'' = (a'' − 2q' b' − q b'')/b.
    #[inline(always)]
    fn div(self, o: Jet2) -> Jet2 {
        // The value is the plain quotient (bit for bit the `f64` run's);
        // the derivatives multiply by the reciprocal, which divides
        // alongside it rather than in a chain of three divisions after it.
        let q = self.v / o.v;
        let inv = 1.0 / o.v;
        let d = (self.d - q * o.d) * inv;
        let dd = (self.dd - 2.0 * d * o.d - q * o.dd) * inv;
        Jet2::new(q, d, dd)
    }
}

impl Real for Jet2 {
    #[inline(always)]
    fn cst(x: f64) -> Jet2 {
        Jet2::new(x, 0.0, 0.0)
    }
    #[inline(always)]
    fn value(self) -> f64 {
        self.v
    }
    /// r = √a: r' = a'/(2r), r'' = (a'' − 2r'²)/(2r). At a = 0 with a
    /// nonzero rate the derivatives are infinite: a dead point, reported as
    /// such rather than as a huge number.
    #[inline(always)]
    fn sqrt(self) -> Jet2 {
        let r = self.v.sqrt();
        if r == 0.0 {
            let d = if self.d == 0.0 { 0.0 } else { f64::INFINITY };
            let dd = if self.d == 0.0 && self.dd == 0.0 {
                0.0
            } else {
                f64::INFINITY
            };
            return Jet2::new(0.0, d, dd);
        }
        // 1/(2r) as r·(1/2a): the division runs alongside the root rather
        // than after it (the two are the slowest operations a step has,
        // and small plans wait on them), and serves both derivatives.
        let inv = r * (0.5 / self.v);
        let d = self.d * inv;
        Jet2::new(r, d, (self.dd - 2.0 * d * d) * inv)
    }
    fn sqrt_dead(self, dead: f64) -> Jet2 {
        if self.v <= dead {
            Jet2::new(self.v.max(0.0).sqrt(), f64::INFINITY, f64::INFINITY)
        } else {
            self.sqrt()
        }
    }

    // --- Spatial steps.

    const JETS: bool = true;
    #[inline(always)]
    fn with_value(self, v: f64) -> Jet2 {
        Jet2::new(v, self.d, self.dd)
    }
    /// θ = atan2(y, x): θ' = (x y' − y x')/ρ², with ρ² = x² + y², and
    /// θ'' = ((x y'' − y x'') − 2 θ' (x x' + y y'))/ρ².
    #[inline(always)]
    fn atan2(self, x: Jet2) -> Jet2 {
        let y = self;
        let r2 = x.v * x.v + y.v * y.v;
        let d = (x.v * y.d - y.v * x.d) / r2;
        let dd = (x.v * y.dd - y.v * x.dd - 2.0 * d * (x.v * x.d + y.v * y.d)) / r2;
        Jet2::new(y.v.atan2(x.v), d, dd)
    }
    /// (sin θ)' = cos θ·θ', (sin θ)'' = cos θ·θ'' − sin θ·θ'², and the
    /// cosine likewise.
    #[inline(always)]
    fn sin_cos(self) -> (Jet2, Jet2) {
        let (s, c) = self.v.sin_cos();
        let (w, a) = (self.d, self.dd);
        (
            Jet2::new(s, c * w, c * a - s * w * w),
            Jet2::new(c, -s * w, -s * a - c * w * w),
        )
    }
    #[inline(always)]
    fn mul_f64(self, k: f64) -> Jet2 {
        Jet2::new(self.v * k, self.d * k, self.dd * k)
    }
    #[inline(always)]
    fn vadd(self, o: Jet2) -> Jet2 {
        jet_rates::add(self, o)
    }
    #[inline(always)]
    fn vsub(self, o: Jet2) -> Jet2 {
        jet_rates::sub(self, o)
    }
    #[inline(always)]
    fn vmul(self, o: Jet2) -> Jet2 {
        jet_rates::mul(self, o)
    }
    #[inline(always)]
    fn vmul_f64(self, k: f64) -> Jet2 {
        jet_rates::mul_f64(self, k)
    }
    /// q = 1/b: q' = −q·b'/b, q'' = −(2q'b' + q·b'')/b, with 1/b = q.
    #[inline(always)]
    fn recip(self) -> Jet2 {
        let q = 1.0 / self.v;
        let d = -(q * self.d) * q;
        Jet2::new(q, d, -(2.0 * d * self.d + q * self.dd) * q)
    }
    /// The bits of both rates, their signs shifted out (−0 is zero too).
    #[inline(always)]
    fn rate_bits(self) -> u64 {
        (self.d.to_bits() | self.dd.to_bits()) << 1
    }
}

/// A jet's sum, difference, product and product by a constant for
/// [`Real::vadd`] and the like. In optimised builds for x86_64 the two rates
/// (d, dd) go side by side in one SSE2 register, so each takes two-lane
/// operations for them: the same IEEE operations in the same order as the
/// formulas written lane by lane (the same numbers; the test
/// `two_lane_rates_are_the_formulas`), in about half the instructions.
/// Elsewhere, and in unoptimised builds (where every two-lane temporary
/// takes a stack slot of its own and the largest generated plans overflow a
/// thread's stack), the formulas lane by lane.
mod jet_rates {
    use super::Jet2;

    #[cfg(all(target_arch = "x86_64", not(debug_assertions)))]
    pub use two_lane::{add, mul, mul_f64, sub};

    #[cfg(all(target_arch = "x86_64", not(debug_assertions)))]
    mod two_lane {
        use super::Jet2;
        use core::arch::x86_64::{
            __m128d, _mm_add_pd, _mm_cvtsd_f64, _mm_mul_pd, _mm_set1_pd, _mm_set_pd, _mm_sub_pd,
            _mm_unpackhi_pd,
        };

        // SAFETY (every `unsafe` below): these are SSE2 instructions, which
        // every x86_64 processor has (SSE2 is part of the architecture's
        // baseline); they read and write registers only.

        #[inline(always)]
        fn rates(j: Jet2) -> __m128d {
            unsafe { _mm_set_pd(j.dd, j.d) }
        }

        #[inline(always)]
        fn splat(a: f64) -> __m128d {
            unsafe { _mm_set1_pd(a) }
        }

        #[inline(always)]
        fn jet(v: f64, r: __m128d) -> Jet2 {
            unsafe { Jet2::new(v, _mm_cvtsd_f64(r), _mm_cvtsd_f64(_mm_unpackhi_pd(r, r))) }
        }

        #[inline(always)]
        pub fn add(a: Jet2, b: Jet2) -> Jet2 {
            jet(a.v + b.v, unsafe { _mm_add_pd(rates(a), rates(b)) })
        }

        #[inline(always)]
        pub fn sub(a: Jet2, b: Jet2) -> Jet2 {
            jet(a.v - b.v, unsafe { _mm_sub_pd(rates(a), rates(b)) })
        }

        /// Both rates at once, in the formula's order: (a'b + 0) + ab' and
        /// (a''b + 2a'b') + ab'' (the `+ 0` changes at most a zero's sign).
        #[inline(always)]
        pub fn mul(a: Jet2, b: Jet2) -> Jet2 {
            let r = unsafe {
                let x = _mm_add_pd(_mm_mul_pd(rates(a), splat(b.v)), _mm_set_pd(2.0 * a.d * b.d, 0.0));
                _mm_add_pd(x, _mm_mul_pd(splat(a.v), rates(b)))
            };
            jet(a.v * b.v, r)
        }

        #[inline(always)]
        pub fn mul_f64(a: Jet2, k: f64) -> Jet2 {
            jet(a.v * k, unsafe { _mm_mul_pd(rates(a), splat(k)) })
        }
    }

    #[cfg(not(all(target_arch = "x86_64", not(debug_assertions))))]
    pub use lane_by_lane::{add, mul, mul_f64, sub};

    /// Jet2's own operators.
    #[cfg(not(all(target_arch = "x86_64", not(debug_assertions))))]
    mod lane_by_lane {
        use super::super::Real;
        use super::Jet2;

        #[inline(always)]
        pub fn add(a: Jet2, b: Jet2) -> Jet2 {
            a + b
        }

        #[inline(always)]
        pub fn sub(a: Jet2, b: Jet2) -> Jet2 {
            a - b
        }

        #[inline(always)]
        pub fn mul(a: Jet2, b: Jet2) -> Jet2 {
            a * b
        }

        #[inline(always)]
        pub fn mul_f64(a: Jet2, k: f64) -> Jet2 {
            a.mul_f64(k)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The branch-free checks agree with `is_finite` and `== 0` on every
    /// kind of number a rate can be, signed zeros included.
    #[test]
    fn rate_bits_classify_as_the_plain_tests() {
        let xs = [
            0.0,
            -0.0,
            1.5,
            -2e300,
            5e-324,
            f64::MAX,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        for &d in &xs {
            for &dd in &xs {
                let j = Jet2::new(1.0, d, dd);
                assert_eq!(j.nonfinite_bits() == 0, j.finite(), "finite ({d}, {dd})");
                assert_eq!(j.rate_bits() == 0, d == 0.0 && dd == 0.0, "still ({d}, {dd})");
            }
        }
    }

    /// x(t) = 2 + 3t + t²/2 ⇒ against the derivatives of x², x/(1 + t)
    /// and √x written out by hand at t = 0.
    #[test]
    fn jets_carry_the_chain_rule() {
        let x = Jet2::new(2.0, 3.0, 1.0);
        let one_plus_t = Jet2::new(1.0, 1.0, 0.0);
        let sq = x * x; // (x²)' = 2xx' = 12, (x²)'' = 2x'² + 2xx'' = 18 + 4
        assert_eq!(sq, Jet2::new(4.0, 12.0, 22.0));
        let q = x / one_plus_t; // q = x/(1+t): q' = x' − x = 1, q'' = x'' − 2x' + 2x = 1 − 6 + 4
        assert!((q.v - 2.0).abs() < 1e-15 && (q.d - 1.0).abs() < 1e-15 && (q.dd + 1.0).abs() < 1e-15);
        let r = x.sqrt(); // r' = x'/(2√x), r'' = x''/(2√x) − x'²/(4 x^1.5)
        let s2 = 2f64.sqrt();
        assert!((r.d - 3.0 / (2.0 * s2)).abs() < 1e-15);
        assert!((r.dd - (1.0 / (2.0 * s2) - 9.0 / (4.0 * 2f64.powf(1.5)))).abs() < 1e-15);
        assert!(!Jet2::new(0.0, 1.0, 0.0).sqrt().finite());
    }

    /// `recip` is the quotient of one: the same value bit for bit, and the
    /// derivatives of 1/x(t) written out by hand (−x'/x², 2x'²/x³ − x''/x²).
    #[test]
    fn recip_is_one_over_the_jet() {
        for x in [
            Jet2::new(2.0, 3.0, 1.0),
            Jet2::new(-0.37, 0.25, -4.0),
            Jet2::new(1e-3, -7.0, 0.5),
        ] {
            let r = x.recip();
            assert_eq!(r.v.to_bits(), (1.0 / x.v).to_bits());
            let d = -x.d / (x.v * x.v);
            let dd = 2.0 * x.d * x.d / (x.v * x.v * x.v) - x.dd / (x.v * x.v);
            assert!((r.d - d).abs() <= 1e-14 * d.abs(), "{r:?}");
            assert!((r.dd - dd).abs() <= 1e-14 * dd.abs(), "{r:?}");
            let q = Jet2::cst(1.0) / x;
            assert!((r.d - q.d).abs() <= 1e-14 * q.d.abs() && (r.dd - q.dd).abs() <= 1e-14 * q.dd.abs());
        }
    }

    /// The two-lane rates give the formulas written lane by lane: equal
    /// (`==`, so up to a zero's sign) on every pair of a spread of jets.
    #[test]
    fn two_lane_rates_are_the_formulas() {
        let xs = [0.0, -0.0, 1.5, -2.25, 1e-300, 3e7, -7.125];
        for &v in &xs {
            for &d in &xs {
                let a = Jet2::new(v, d, d * 0.5 - 1.0);
                let b = Jet2::new(d - 0.75, v, v * v);
                let p = a.vmul(b);
                let want = Jet2::new(
                    a.v * b.v,
                    a.d * b.v + a.v * b.d,
                    a.dd * b.v + 2.0 * a.d * b.d + a.v * b.dd,
                );
                assert!(p == want && p.v.to_bits() == want.v.to_bits(), "{a:?} * {b:?}");
                assert_eq!(a.vadd(b), Jet2::new(a.v + b.v, a.d + b.d, a.dd + b.dd));
                assert_eq!(a.vsub(b), Jet2::new(a.v - b.v, a.d - b.d, a.dd - b.dd));
                assert_eq!(a.vmul_f64(d), Jet2::new(a.v * d, a.d * d, a.dd * d));
                assert!(a.vmul(b) == a * b && a.vadd(b) == a + b);
            }
        }
    }

    /// A plain factor multiplies a jet as a constant jet does: the same
    /// value bit for bit and the same rates (to the sign of a zero).
    #[test]
    fn a_plain_factor_is_a_constant_jet() {
        let x = Jet2::new(1.7, -0.4, 2.5);
        for k in [0.6, -3.25, 0.0] {
            let (plain, jet) = (k.times(x), Jet2::cst(k).times(x));
            assert_eq!(plain.v.to_bits(), jet.v.to_bits());
            assert!(plain.d == jet.d && plain.dd == jet.dd);
            assert_eq!(Factor::<Jet2>::lift(k), Jet2::cst(k));
        }
    }
}
