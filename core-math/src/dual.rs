//! Dual numbers x + x' e with e^2 = 0: evaluating a function on (x, 1) gives its value
//! and its exact derivative, with no step size and no truncation error.

use core::ops::{Add, Div, Mul, Neg, Sub};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Dual {
    /// Value.
    pub re: f64,
    /// Derivative with respect to the seeded variable (here: time t, in 1/s).
    pub du: f64,
}

impl Dual {
    pub const fn constant(re: f64) -> Dual {
        Dual { re, du: 0.0 }
    }
    pub const fn new(re: f64, du: f64) -> Dual {
        Dual { re, du }
    }
    pub fn sin(self) -> Dual {
        let (s, c) = libm::sincos(self.re);
        Dual::new(s, c * self.du)
    }
    pub fn cos(self) -> Dual {
        let (s, c) = libm::sincos(self.re);
        Dual::new(c, -s * self.du)
    }
    /// sqrt(x), d sqrt(x) = dx / (2 sqrt(x)); for x > 0 only (callers check).
    pub fn sqrt(self) -> Dual {
        let r = libm::sqrt(self.re);
        Dual::new(r, self.du / (r + r))
    }
}

impl crate::vector::Sqrt for Dual {
    fn sqrt(self) -> Dual {
        Dual::sqrt(self)
    }
}

impl Add for Dual {
    type Output = Dual;
    fn add(self, o: Dual) -> Dual {
        Dual::new(self.re + o.re, self.du + o.du)
    }
}
impl Sub for Dual {
    type Output = Dual;
    fn sub(self, o: Dual) -> Dual {
        Dual::new(self.re - o.re, self.du - o.du)
    }
}
impl Mul for Dual {
    type Output = Dual;
    fn mul(self, o: Dual) -> Dual {
        Dual::new(self.re * o.re, self.re * o.du + self.du * o.re)
    }
}
impl Div for Dual {
    type Output = Dual;
    fn div(self, o: Dual) -> Dual {
        let re = self.re / o.re;
        Dual::new(re, (self.du - re * o.du) / o.re)
    }
}
impl Neg for Dual {
    type Output = Dual;
    fn neg(self) -> Dual {
        Dual::new(-self.re, -self.du)
    }
}
