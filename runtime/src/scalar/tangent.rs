//! [`Tangent`]: a value with its first derivatives along `N` directions at
//! once — the derivatives of a frame with respect to every design
//! parameter of a mechanism in one run of its steps.

use std::ops::{Add, Div, Mul, Neg, Sub};

use super::{Factor, Real};

/// A value with its first derivatives with respect to `N` variables (a
/// candidate's design parameters): forward-mode differentiation along all
/// of them in one pass, where a [`Jet2`](super::Jet2) carries one direction
/// with its second derivative. Every operation computes the value as `f64`
/// does (bit for bit), so a run on tangents takes the decisions a run on
/// numbers takes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tangent<const N: usize> {
    /// The value.
    pub v: f64,
    /// The derivative with respect to each variable.
    pub d: [f64; N],
}

impl<const N: usize> Tangent<N> {
    /// Variable `k` at the value `v` (derivative 1 with respect to itself,
    /// 0 with respect to the others).
    #[inline(always)]
    pub fn var(v: f64, k: usize) -> Tangent<N> {
        let mut d = [0.0; N];
        d[k] = 1.0;
        Tangent { v, d }
    }

    /// Whether every derivative is finite (not at a dead point, where a
    /// square root of zero has an infinite derivative).
    pub fn finite(&self) -> bool {
        self.d.iter().all(|x| x.is_finite())
    }

    /// The value `v` with the derivatives `k·a`: the chain rule through a
    /// function whose derivative at the point is `k`.
    #[inline(always)]
    fn chain(v: f64, a: &[f64; N], k: f64) -> Tangent<N> {
        Tangent {
            v,
            d: std::array::from_fn(|i| a[i] * k),
        }
    }
}

impl<const N: usize> Add for Tangent<N> {
    type Output = Tangent<N>;
    #[inline(always)]
    fn add(self, o: Tangent<N>) -> Tangent<N> {
        Tangent {
            v: self.v + o.v,
            d: std::array::from_fn(|i| self.d[i] + o.d[i]),
        }
    }
}

impl<const N: usize> Sub for Tangent<N> {
    type Output = Tangent<N>;
    #[inline(always)]
    fn sub(self, o: Tangent<N>) -> Tangent<N> {
        Tangent {
            v: self.v - o.v,
            d: std::array::from_fn(|i| self.d[i] - o.d[i]),
        }
    }
}

impl<const N: usize> Neg for Tangent<N> {
    type Output = Tangent<N>;
    #[inline(always)]
    fn neg(self) -> Tangent<N> {
        Tangent {
            v: -self.v,
            d: self.d.map(|x| -x),
        }
    }
}

impl<const N: usize> Mul for Tangent<N> {
    type Output = Tangent<N>;
    /// (ab)′ = a′b + ab′.
    #[inline(always)]
    #[allow(clippy::suspicious_arithmetic_impl)] // the product rule adds
    fn mul(self, o: Tangent<N>) -> Tangent<N> {
        Tangent {
            v: self.v * o.v,
            d: std::array::from_fn(|i| self.d[i] * o.v + self.v * o.d[i]),
        }
    }
}

impl<const N: usize> Div for Tangent<N> {
    type Output = Tangent<N>;
    /// q = a/b: q′ = (a′ − q b′)/b (the value is the plain quotient).
    #[inline(always)]
    #[allow(clippy::suspicious_arithmetic_impl)] // the quotient rule
    fn div(self, o: Tangent<N>) -> Tangent<N> {
        let q = self.v / o.v;
        let inv = 1.0 / o.v;
        Tangent {
            v: q,
            d: std::array::from_fn(|i| (self.d[i] - q * o.d[i]) * inv),
        }
    }
}

impl<const N: usize> Factor<Tangent<N>> for Tangent<N> {
    #[inline(always)]
    fn times(self, x: Tangent<N>) -> Tangent<N> {
        x * self
    }
    #[inline(always)]
    fn lift(self) -> Tangent<N> {
        self
    }
}

impl<const N: usize> Real for Tangent<N> {
    #[inline(always)]
    fn cst(x: f64) -> Tangent<N> {
        Tangent { v: x, d: [0.0; N] }
    }
    #[inline(always)]
    fn value(self) -> f64 {
        self.v
    }
    /// r = √a: r′ = a′/(2r); at a = 0 a nonzero derivative is infinite (a
    /// dead point, reported as such rather than as a huge number).
    #[inline(always)]
    fn sqrt(self) -> Tangent<N> {
        let r = self.v.sqrt();
        if r == 0.0 {
            return Tangent {
                v: 0.0,
                d: self.d.map(|x| if x == 0.0 { 0.0 } else { f64::INFINITY }),
            };
        }
        Tangent::chain(r, &self.d, 0.5 / r)
    }
    fn sqrt_dead(self, dead: f64) -> Tangent<N> {
        if self.v <= dead {
            Tangent {
                v: self.v.max(0.0).sqrt(),
                d: [f64::INFINITY; N],
            }
        } else {
            self.sqrt()
        }
    }

    const JETS: bool = true;
    #[inline(always)]
    fn with_value(self, v: f64) -> Tangent<N> {
        Tangent { v, d: self.d }
    }
    /// θ = atan2(y, x): θ′ = (x y′ − y x′)/(x² + y²).
    #[inline(always)]
    fn atan2(self, x: Tangent<N>) -> Tangent<N> {
        let y = self;
        let r2 = x.v * x.v + y.v * y.v;
        Tangent {
            v: y.v.atan2(x.v),
            d: std::array::from_fn(|i| (x.v * y.d[i] - y.v * x.d[i]) / r2),
        }
    }
    #[inline(always)]
    fn sin_cos(self) -> (Tangent<N>, Tangent<N>) {
        let (s, c) = self.v.sin_cos();
        (Tangent::chain(s, &self.d, c), Tangent::chain(c, &self.d, -s))
    }
    #[inline(always)]
    fn mul_f64(self, k: f64) -> Tangent<N> {
        Tangent::chain(self.v * k, &self.d, k)
    }
    #[inline(always)]
    fn rate_bits(self) -> u64 {
        self.d.iter().fold(0, |b, x| b | x.to_bits()) << 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Central differences of `f` in each variable against its tangent.
    fn matches_differences(f: impl Fn([Tangent<2>; 2]) -> Tangent<2>, at: [f64; 2]) {
        let t = f([Tangent::var(at[0], 0), Tangent::var(at[1], 1)]);
        for k in 0..2 {
            let h = 1e-6;
            let mut hi = at;
            let mut lo = at;
            hi[k] += h;
            lo[k] -= h;
            let value = |p: [f64; 2]| f([Tangent::cst(p[0]), Tangent::cst(p[1])]).v;
            let fd = (value(hi) - value(lo)) / (2.0 * h);
            assert!(
                (t.d[k] - fd).abs() < 1e-7 * (1.0 + fd.abs()),
                "d{k}: {} vs {fd}",
                t.d[k]
            );
        }
    }

    #[test]
    fn every_operation_differentiates() {
        let at = [0.7, -1.3];
        matches_differences(|[x, y]| x * y + x / y - (-y), at);
        matches_differences(|[x, y]| (x * x + y * y).sqrt(), at);
        matches_differences(|[x, y]| y.atan2(x), at);
        matches_differences(|[x, y]| x.sin_cos().0 * y.sin_cos().1, at);
        matches_differences(|[x, y]| x.mul_f64(3.0) - y.recip(), at);
    }

    #[test]
    fn values_are_the_plain_numbers() {
        let (a, b) = (0.3f64, 1.7f64);
        let t = Tangent::<3>::var(a, 0) / Tangent::var(b, 2) + Tangent::cst(b).sqrt();
        assert_eq!(t.v, a / b + b.sqrt());
        assert_eq!(t.d[1], 0.0);
    }

    #[test]
    fn a_square_root_of_zero_with_a_rate_is_infinite() {
        let z = (Tangent::<2>::var(0.0, 0) * Tangent::cst(1.0)).sqrt();
        assert!(!z.finite());
        assert_eq!(z.d[1], 0.0);
    }
}
