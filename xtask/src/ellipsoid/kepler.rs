//! Two-body propagation of an inertial state vector by Kepler's equation, for the
//! numerical image-motion model (`motion`): no integrator, no Taylor series in time, no
//! formula of `core_math`.
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

fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// 1 - cos x without cancellation.
fn one_minus_cos(x: f64) -> f64 {
    let s = (0.5 * x).sin();
    2.0 * s * s
}

/// x - sin x without cancellation (series below 0.5, where it converges fast).
fn x_minus_sin(x: f64) -> f64 {
    if x.abs() >= 0.5 {
        return x - x.sin();
    }
    // x^3/3! - x^5/5! + ...
    let x2 = x * x;
    let mut term = x * x2 / 6.0;
    let mut sum = 0.0;
    let mut k = 3.0;
    while term.abs() > 1e-40 && k < 60.0 {
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
        let r0n = dot(r0, r0).sqrt();
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
            n: (gm * inv_a * inv_a * inv_a).sqrt(),
            e_sin: dot(r0, v0) / (gm * a).sqrt(),
            e_cos: 1.0 - r0n * inv_a,
        })
    }

    /// Eccentricity (for reports): sqrt(e_cos^2 + e_sin^2).
    pub fn eccentricity(&self) -> f64 {
        self.e_cos.hypot(self.e_sin)
    }

    /// The change of eccentric anomaly over `dt_s`, by Newton's method.
    fn delta_e(&self, dt_s: f64) -> f64 {
        let m = self.n * dt_s;
        let mut x = m;
        for _ in 0..30 {
            let f = x + self.e_sin * one_minus_cos(x) - self.e_cos * x.sin() - m;
            let df = 1.0 + self.e_sin * x.sin() - self.e_cos * x.cos();
            let step = f / df;
            x -= step;
            // Quadratic convergence: the error left is ~ e step^2 / |x|, below 1e-20 of
            // |x| once the step is below 1e-10 of it.
            if step.abs() <= 1e-10 * x.abs() || step.is_nan() {
                break;
            }
        }
        x
    }

    /// The displacement r(t) - r0 and the velocity v(t) at `dt_s` from the epoch.
    pub fn at(&self, dt_s: f64) -> (V3, V3) {
        let de = self.delta_e(dt_s);
        let omc = one_minus_cos(de);
        let sin_de = de.sin();
        let f_m1 = -self.a / self.r0n * omc;
        let g = dt_s - x_minus_sin(de) / self.n;
        // r(t) = a (1 - e cos E): a - (a - r0) cos dE + sigma0 sqrt(a) sin dE.
        let r = self.a * (1.0 - self.e_cos * de.cos() + self.e_sin * sin_de);
        let fdot = -(self.gm * self.a).sqrt() * sin_de / (r * self.r0n);
        let gdot = 1.0 - self.a / r * omc;
        let dr = std::array::from_fn(|k| f_m1 * self.r0[k] + g * self.v0[k]);
        let v = std::array::from_fn(|k| fdot * self.r0[k] + gdot * self.v0[k]);
        (dr, v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core_math::GM_M3_S2;

    fn add(a: V3, b: V3) -> V3 {
        [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
    }

    fn cross(a: V3, b: V3) -> V3 {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    }

    /// Energy and angular momentum are conserved, a full period returns to the start,
    /// and the circular orbit turns at its mean motion.
    #[test]
    fn two_body_invariants() {
        let r0 = [6_900e3, 1_200e3, -300e3];
        let v0 = [-900.0, 6_200.0, 4_100.0];
        let k = Kepler::new(r0, v0, GM_M3_S2).unwrap();
        let energy = |r: V3, v: V3| 0.5 * dot(v, v) - GM_M3_S2 / dot(r, r).sqrt();
        let (e0, h0) = (energy(r0, v0), cross(r0, v0));
        for dt in [-1000.0, -0.3, 0.1, 37.0, 2500.0] {
            let (dr, v) = k.at(dt);
            let r = add(r0, dr);
            assert!((energy(r, v) / e0 - 1.0).abs() < 1e-13, "dt {dt}");
            let h = cross(r, v);
            for i in 0..3 {
                assert!((h[i] - h0[i]).abs() < 1e-12 * dot(h0, h0).sqrt());
            }
        }
        let period = std::f64::consts::TAU / k.n;
        let (dr, v) = k.at(period);
        assert!(dot(dr, dr).sqrt() < 1e-6 && (v[0] - v0[0]).abs() < 1e-9);
        // Circular: the position turns by n dt about the normal.
        let r = 7_016e3;
        let s = (GM_M3_S2 / r).sqrt();
        let c = Kepler::new([r, 0.0, 0.0], [0.0, s, 0.0], GM_M3_S2).unwrap();
        let (dr, _) = c.at(100.0);
        let th = c.n * 100.0;
        assert!((r + dr[0] - r * th.cos()).abs() < 1e-8 && (dr[1] - r * th.sin()).abs() < 1e-8);
        assert!(c.eccentricity() < 1e-15);
        assert!(Kepler::new([r, 0.0, 0.0], [0.0, 2.0 * s, 0.0], GM_M3_S2).is_none());
    }

    /// For small dt the displacement is r0 -> v0 dt + a0 dt^2 / 2 + j0 dt^3 / 6: the
    /// Taylor series, to its next term, checks the small-angle forms.
    #[test]
    fn small_steps_follow_taylor() {
        let r0 = [6_900e3, 1_200e3, -300e3];
        let v0 = [-900.0, 6_200.0, 4_100.0];
        let k = Kepler::new(r0, v0, GM_M3_S2).unwrap();
        let rn = dot(r0, r0).sqrt();
        let acc = r0.map(|x| -GM_M3_S2 * x / rn.powi(3));
        // Jerk: -GM (v / r^3 - 3 (r . v) r / r^5).
        let rv = dot(r0, v0);
        let jerk: V3 = std::array::from_fn(|i| {
            -GM_M3_S2 * (v0[i] / rn.powi(3) - 3.0 * rv * r0[i] / rn.powi(5))
        });
        let dt = 0.01;
        let (dr, _) = k.at(dt);
        for i in 0..3 {
            let t = v0[i] * dt + acc[i] * dt * dt / 2.0 + jerk[i] * dt.powi(3) / 6.0;
            // The jerk term is ~1.5e-9 m; the next, |r| n^4 dt^4 / 24, ~5e-15 m.
            assert!((dr[i] - t).abs() < 5e-14, "{i}: {} vs {t}", dr[i]);
        }
    }
}
