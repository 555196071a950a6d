//! Double-double arithmetic (about 32 significant digits) for the basis conversion only:
//! turning the Chebyshev coefficients of a fit into power-basis coefficients involves large
//! cancelling terms, so it is done in extended precision and rounded once at the end.

use std::ops::{Add, Mul, Neg, Sub};

/// An unevaluated sum `hi + lo` with |lo| ≤ ulp(hi)/2.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Dd {
    hi: f64,
    lo: f64,
}

#[inline]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    (s, (a - (s - bb)) + (b - bb))
}

#[inline]
fn quick_two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    (s, b - (s - a))
}

impl Dd {
    pub(crate) const ZERO: Dd = Dd { hi: 0.0, lo: 0.0 };

    pub(crate) fn from_f64(x: f64) -> Dd {
        Dd { hi: x, lo: 0.0 }
    }

    pub(crate) fn to_f64(self) -> f64 {
        self.hi + self.lo
    }
}

impl Add for Dd {
    type Output = Dd;
    fn add(self, o: Dd) -> Dd {
        let (s, e) = two_sum(self.hi, o.hi);
        let (t, f) = two_sum(self.lo, o.lo);
        let (s, e) = quick_two_sum(s, e + t);
        let (hi, lo) = quick_two_sum(s, e + f);
        Dd { hi, lo }
    }
}

impl Neg for Dd {
    type Output = Dd;
    fn neg(self) -> Dd {
        Dd {
            hi: -self.hi,
            lo: -self.lo,
        }
    }
}

impl Sub for Dd {
    type Output = Dd;
    fn sub(self, o: Dd) -> Dd {
        self + (-o)
    }
}

impl Mul for Dd {
    type Output = Dd;
    fn mul(self, o: Dd) -> Dd {
        let p = self.hi * o.hi;
        let e = self.hi.mul_add(o.hi, -p);
        let e = e + (self.hi * o.lo + self.lo * o.hi);
        let (hi, lo) = quick_two_sum(p, e);
        Dd { hi, lo }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_digits_f64_loses() {
        // (1 + 2^-60) - 1 = 2^-60 exactly in double-double, 0 in f64.
        let tiny = 2f64.powi(-60);
        let a = Dd::from_f64(1.0) + Dd::from_f64(tiny);
        assert_eq!((a - Dd::from_f64(1.0)).to_f64(), tiny);
        // (1 + 2^-30)^2 = 1 + 2^-29 + 2^-60
        let b = Dd::from_f64(1.0 + 2f64.powi(-30));
        let sq = b * b - Dd::from_f64(1.0 + 2f64.powi(-29));
        assert_eq!(sq.to_f64(), tiny);
    }
}
