//! Two-body propagation of an inertial state vector by Kepler's equation (feature
//! `reference`): the host tools' numerical image-motion model (`cargo xtask ellipsoid`)
//! and the f64 golden values of the controller's propagation (`controller::golden`).
//! No integrator, no Taylor series in time.
//!
//! From the state (r0, v0): the semi-major axis a from the vis-viva energy, the mean
//! motion n = sqrt(GM / a^3), sigma0 = r0 . v0 / sqrt(GM). The change of eccentric anomaly
//! dE over dt solves Kepler's equation written from the state (no perigee needed, so it
//! holds at e = 0):
//!
//! ```text
//! n dt = dE + (sigma0 / sqrt(a)) (1 - cos dE) - (1 - r0 / a) sin dE
//! ```
//!
//! (Newton's method from dE = n dt; the derivative is r(t) / a > 0). Then Lagrange's f
//! and g: r(t) = f r0 + g v0, v(t) = f' r0 + g' v0 with
//! f = 1 - (a / r0)(1 - cos dE), g = dt - (dE - sin dE) / n,
//! r(t) = a + (r0 - a) cos dE + sigma0 sqrt(a) sin dE,
//! f' = -sqrt(GM a) sin dE / (r r0), g' = 1 - (a / r)(1 - cos dE).
//!
//! Error: this is the exact two-body solution, so the only error is rounding. The
//! displacement r(t) - r0 = (f - 1) r0 + g v0 is formed directly (1 - cos dE as
//! 2 sin^2(dE/2), dE - sin dE by its series for small dE), so it carries a relative
//! error of a few 1e-16 of itself (1e-13 m over the 0.4 s of the model's stencil), not
//! of |r0|; Newton converges to the last bit of dE (about 1e-20 rad for dE ~ 1e-4).

use crate::vector::dot;

pub type V3 = [f64; 3];

/// An elliptic two-body orbit through a state vector.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Kepler {
    r0: V3,
    v0: V3,
    r0n: f64,
    gm: f64,
    /// Semi-major axis (m).
    a: f64,
    /// Mean motion (rad/s).
    n: f64,
    /// sigma0 / sqrt(a) = e sin E0 and 1 - r0 / a = e cos E0.
    e_sin: f64,
    e_cos: f64,
}

/// 1 - cos x without cancellation.
fn one_minus_cos(x: f64) -> f64 {
    let s = crate::trig_f64::sin(0.5 * x);
    2.0 * s * s
}

/// x - sin x without cancellation (series below 0.5, where it converges fast).
fn x_minus_sin(x: f64) -> f64 {
    if libm::fabs(x) >= 0.5 {
        return x - crate::trig_f64::sin(x);
    }
    // x^3/3! - x^5/5! + ...
    let x2 = x * x;
    let mut term = x * x2 / 6.0;
    let mut sum = 0.0;
    let mut k = 3.0;
    while libm::fabs(term) > 1e-40 && k < 60.0 {
        sum += term;
        term *= -x2 / ((k + 1.0) * (k + 2.0));
        k += 2.0;
    }
    sum
}

impl Kepler {
    /// The orbit through (r0, v0) under GM; None unless it is an ellipse (negative
    /// energy, non-zero radius).
    pub fn new(r0: V3, v0: V3, gm: f64) -> Option<Kepler> {
        let r0n = libm::sqrt(dot(r0, r0));
        let inv_a = 2.0 / r0n - dot(v0, v0) / gm;
        if !(r0n > 0.0 && inv_a > 0.0) {
            return None;
        }
        let a = 1.0 / inv_a;
        Some(Kepler {
            r0,
            v0,
            r0n,
            gm,
            a,
            n: libm::sqrt(gm * inv_a * inv_a * inv_a),
            e_sin: dot(r0, v0) / libm::sqrt(gm * a),
            e_cos: 1.0 - r0n * inv_a,
        })
    }

    /// Mean motion n = sqrt(GM / a^3) (rad/s).
    pub fn mean_motion_rad_s(&self) -> f64 {
        self.n
    }

    /// Eccentricity (for reports): sqrt(e_cos^2 + e_sin^2).
    pub fn eccentricity(&self) -> f64 {
        libm::hypot(self.e_cos, self.e_sin)
    }

    /// The change of eccentric anomaly over `dt_s`, by Newton's method.
    fn delta_e(&self, dt_s: f64) -> f64 {
        let m = self.n * dt_s;
        let mut x = m;
        for _ in 0..30 {
            let f = x + self.e_sin * one_minus_cos(x) - self.e_cos * crate::trig_f64::sin(x) - m;
            let df =
                1.0 + self.e_sin * crate::trig_f64::sin(x) - self.e_cos * crate::trig_f64::cos(x);
            let step = f / df;
            x -= step;
            // Quadratic convergence: the error left is ~ e step^2 / |x|, below 1e-20 of
            // |x| once the step is below 1e-10 of it.
            if libm::fabs(step) <= 1e-10 * libm::fabs(x) || step.is_nan() {
                break;
            }
        }
        x
    }

    /// The displacement r(t) - r0 and the velocity v(t) at `dt_s` from the epoch.
    pub fn at(&self, dt_s: f64) -> (V3, V3) {
        let de = self.delta_e(dt_s);
        let omc = one_minus_cos(de);
        let sin_de = crate::trig_f64::sin(de);
        let f_m1 = -self.a / self.r0n * omc;
        let g = dt_s - x_minus_sin(de) / self.n;
        // r(t) = a (1 - e cos E): a - (a - r0) cos dE + sigma0 sqrt(a) sin dE.
        let r = self.a * (1.0 - self.e_cos * crate::trig_f64::cos(de) + self.e_sin * sin_de);
        let fdot = -libm::sqrt(self.gm * self.a) * sin_de / (r * self.r0n);
        let gdot = 1.0 - self.a / r * omc;
        let dr = core::array::from_fn(|k| f_m1 * self.r0[k] + g * self.v0[k]);
        let v = core::array::from_fn(|k| fdot * self.r0[k] + gdot * self.v0[k]);
        (dr, v)
    }

    /// The state vector `dt_s` after the epoch.
    pub fn state_at(&self, dt_s: f64) -> crate::StateVector {
        let (dr, v) = self.at(dt_s);
        crate::StateVector {
            position_m: core::array::from_fn(|k| self.r0[k] + dr[k]),
            velocity_mps: v,
        }
    }
}
