//! The NAV frame: the satellite's inertial state (ECI, f64) from the on-board navigation
//! and the camera's attitude relative to the local orbital frame (f32 angles and their
//! rates), checked field by field; and the two-body propagation of that state to the
//! update instants it serves.

use core_math::earth::check_state;
pub use core_math::earth::Attitude;
use core_math::{StateVector, GM_M3_S2};

use crate::bytes::{Reader, Writer};
use crate::fault::Fault;

/// Payload length: 6 f64 (r, v) + 6 f32 (roll, pitch, yaw and their rates).
pub const NAV_LEN: usize = 6 * 8 + 6 * 4;

/// A NAV payload as sent.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Nav {
    pub state: StateVector,
    pub attitude: Attitude<f32>,
}

impl Nav {
    /// Parses the payload; only the layout is checked here (see [`crate::intake`] for
    /// the physical checks).
    pub fn decode(payload: &[u8]) -> Result<Nav, Fault> {
        if payload.len() != NAV_LEN {
            return Err(Fault::BadLength);
        }
        let mut r = Reader::new(payload);
        let mut v3 = || -> Option<[f64; 3]> { Some([r.f64()?, r.f64()?, r.f64()?]) };
        let position_m = v3().ok_or(Fault::BadLength)?;
        let velocity_mps = v3().ok_or(Fault::BadLength)?;
        let mut f = || r.f32().ok_or(Fault::BadLength);
        let attitude = Attitude {
            roll_rad: f()?,
            pitch_rad: f()?,
            yaw_rad: f()?,
            roll_rate_rad_s: f()?,
            pitch_rate_rad_s: f()?,
            yaw_rate_rad_s: f()?,
        };
        Ok(Nav {
            state: StateVector {
                position_m,
                velocity_mps,
            },
            attitude,
        })
    }

    pub fn encode(&self, out: &mut [u8]) -> Option<usize> {
        let mut w = Writer::new(out);
        for x in self.state.position_m.iter().chain(&self.state.velocity_mps) {
            w.put(&x.to_le_bytes())?;
        }
        for (x, _) in self.attitude.values() {
            w.put(&x.to_le_bytes())?;
        }
        Some(w.len())
    }

    /// Every value finite, and a state vector that defines an orbital frame (the
    /// model's own state checks, in f64). Returns |r| (m).
    pub fn check_state(&self) -> Result<f64, Fault> {
        let (r, v) = (self.state.position_m, self.state.velocity_mps);
        let finite = r.iter().chain(&v).all(|x| x.is_finite())
            && self.attitude.values().iter().all(|(x, _)| x.is_finite());
        if !finite {
            return Err(Fault::NonFinite);
        }
        let (r2, _) = check_state(r, v).map_err(|_| Fault::OutOfRange)?;
        Ok(libm::sqrt(r2))
    }
}

/// A NAV state ready to propagate: the state, and the two-body acceleration and jerk
/// at it (formed once per NAV frame, in f64, rounded to f32).
///
/// Propagation to dt is the Taylor series to the jerk: r + v dt + a dt^2/2 + j dt^3/6,
/// v + a dt + j dt^2/2. Its error is the snap's term, |s| ~ |a| n^2 (n the mean motion):
/// at 645 km, 4e-7 m and 1.7e-6 m/s (2e-10 of the speed) after 1 s, 2e-5 of the speed
/// only after 100 s. The increments are formed in f32 (0.5 mm for a 7.5 km step) and
/// added to the f64 state, so nothing of the state's own precision is lost.
///
/// The per-update route ([`Propagator::parts_at`]) stays in f32: the NAV position and
/// velocity are held as f32 pairs (value + remainder, 48 bits of mantissa: below 1e-7 m
/// at 7 000 km), the increment is added to the remainder first, and |r|^2 - a^2, the one
/// difference that cancels, is the NAV frame's (formed in f64) plus 2 r.dr + dr.dr. The
/// results round like the f64 sum rounded to f32, without the soft-f64 additions (their
/// cost: docs/controller.md, "What it costs").
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Propagator {
    pub state: StateVector,
    half_accel_mps2: [f32; 3],
    sixth_jerk_mps3: [f32; 3],
    position_hi_m: [f32; 3],
    position_lo_m: [f32; 3],
    velocity_hi_mps: [f32; 3],
    velocity_lo_mps: [f32; 3],
    /// |r|^2 - a^2 at the NAV instant (m^2), a of [`crate::EARTH`].
    r2_minus_a2_m2: f32,
}

/// The state at an update instant, in f32, ready for `General::instant_parts`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StateParts {
    pub position_m: [f32; 3],
    pub velocity_mps: [f32; 3],
    /// |r|^2 - a^2 (m^2), a of [`crate::EARTH`].
    pub r2_minus_a2_m2: f32,
}

impl Propagator {
    pub fn new(state: &StateVector) -> Propagator {
        let (r, v) = (state.position_m, state.velocity_mps);
        let r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
        let rn = libm::sqrt(r2);
        // a = -mu r / |r|^3; j = da/dt = -mu (v - 3 (r.v / |r|^2) r) / |r|^3.
        let mu_r3 = GM_M3_S2 / (r2 * rn);
        let rv_r2 = (r[0] * v[0] + r[1] * v[1] + r[2] * v[2]) / r2;
        let a_m = crate::EARTH.a_m;
        let mut p = Propagator {
            state: *state,
            position_hi_m: [0.0; 3],
            position_lo_m: [0.0; 3],
            velocity_hi_mps: [0.0; 3],
            velocity_lo_mps: [0.0; 3],
            r2_minus_a2_m2: (r2 - a_m * a_m) as f32,
            half_accel_mps2: [0.0; 3],
            sixth_jerk_mps3: [0.0; 3],
        };
        for k in 0..3 {
            [
                p.position_hi_m[k],
                p.position_lo_m[k],
                p.velocity_hi_mps[k],
                p.velocity_lo_mps[k],
                p.half_accel_mps2[k],
                p.sixth_jerk_mps3[k],
            ] = axis_terms(r[k], v[k], mu_r3, rv_r2);
        }
        p
    }

    /// The series' increments of position and velocity `dt_s` after the NAV instant,
    /// in f32 (the one series both routes below add to their state).
    fn increments(&self, dt_s: f32) -> ([f32; 3], [f32; 3]) {
        let (v, a2, j6) = (
            self.velocity_hi_mps,
            self.half_accel_mps2,
            self.sixth_jerk_mps3,
        );
        (
            core::array::from_fn(|k| dt_s * (v[k] + dt_s * (a2[k] + dt_s * j6[k]))),
            core::array::from_fn(|k| dt_s * (2.0 * a2[k] + dt_s * (3.0 * j6[k]))),
        )
    }

    /// The state `dt_s` after the NAV instant (dt may be negative: an update instant
    /// up to one update period before the frame's tag), in f64: the route
    /// [`Propagator::parts_at`] is checked against.
    pub fn at(&self, dt_s: f32) -> StateVector {
        let (dr, dv) = self.increments(dt_s);
        let (r0, v0) = (self.state.position_m, self.state.velocity_mps);
        StateVector {
            position_m: core::array::from_fn(|k| r0[k] + f64::from(dr[k])),
            velocity_mps: core::array::from_fn(|k| v0[k] + f64::from(dv[k])),
        }
    }

    /// The state `dt_s` after the NAV instant as [`StateParts`], all in f32: what the
    /// controller's update uses.
    pub fn parts_at(&self, dt_s: f32) -> StateParts {
        let (dr, dv) = self.increments(dt_s);
        let r0 = self.position_hi_m;
        // |r0 + dr|^2 - a^2 = (|r0|^2 - a^2) + dr.(2 r0 + dr): no cancellation left (r0's
        // remainder changes the product by 2 |lo| |dr| < 1e4 m^2, 1e-9 of the sum).
        let grow = (0..3).fold(0.0f32, |acc, k| acc + dr[k] * (2.0 * r0[k] + dr[k]));
        StateParts {
            position_m: core::array::from_fn(|k| r0[k] + (self.position_lo_m[k] + dr[k])),
            velocity_mps: core::array::from_fn(|k| {
                self.velocity_hi_mps[k] + (self.velocity_lo_mps[k] + dv[k])
            }),
            r2_minus_a2_m2: self.r2_minus_a2_m2 + grow,
        }
    }
}

/// One axis of a [`Propagator`] from its r and v (m, m/s), mu / |r|^3 and
/// r.v / |r|^2: r and v as f32 pairs (value, remainder), a / 2 and j / 6 (m/s^2,
/// m/s^3).
// Out of line: the three axes were unrolled, a soft-float copy for each.
#[inline(never)]
fn axis_terms(r: f64, v: f64, mu_r3: f64, rv_r2: f64) -> [f32; 6] {
    let hi = |x: f64| x as f32;
    let lo = |x: f64| (x - f64::from(x as f32)) as f32;
    [
        hi(r),
        lo(r),
        hi(v),
        lo(v),
        (-0.5 * mu_r3 * r) as f32,
        (-mu_r3 * (v - 3.0 * rv_r2 * r) / 6.0) as f32,
    ]
}

/// The attitude `dt_s` after its NAV instant: each angle at its own rate.
pub fn attitude_at(a: &Attitude<f32>, dt_s: f32) -> Attitude<f32> {
    Attitude {
        roll_rad: a.roll_rad + a.roll_rate_rad_s * dt_s,
        pitch_rad: a.pitch_rad + a.pitch_rate_rad_s * dt_s,
        yaw_rad: a.yaw_rad + a.yaw_rate_rad_s * dt_s,
        ..*a
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The f32 route against the f64 one of the same series: every component within the
    /// rounding of an f32 at 7 000 km (0.5 m; 1e-3 m/s at 7.5 km/s) and |r|^2 - a^2
    /// within 1e-7 of the f64 value.
    #[test]
    fn f32_parts_round_like_the_f64_state() {
        let a = crate::EARTH.a_m + 645e3;
        let speed = libm::sqrt(core_math::GM_M3_S2 / a) * 1.0006;
        for u in [0.0f64, 0.7, 2.1, -1.3] {
            let (su, cu) = (libm::sin(u), libm::cos(u));
            let (si, ci) = (libm::sin(1.71), libm::cos(1.71));
            let state = StateVector {
                position_m: [a * cu, a * su * ci, a * su * si],
                velocity_mps: [-speed * su, speed * cu * ci, speed * cu * si],
            };
            let p = Propagator::new(&state);
            for dt in [-0.02f32, 0.0, 0.37, 1.0, 5.0] {
                let f64_state = p.at(dt);
                let parts = p.parts_at(dt);
                for k in 0..3 {
                    let dr = (f64::from(parts.position_m[k]) - f64_state.position_m[k]).abs();
                    let dv = (f64::from(parts.velocity_mps[k]) - f64_state.velocity_mps[k]).abs();
                    assert!(dr <= 0.5, "u {u} dt {dt}: position {k} off by {dr} m");
                    assert!(dv <= 1e-3, "u {u} dt {dt}: velocity {k} off by {dv} m/s");
                }
                let r = f64_state.position_m;
                let exact =
                    r[0] * r[0] + r[1] * r[1] + r[2] * r[2] - crate::EARTH.a_m * crate::EARTH.a_m;
                let rel = (f64::from(parts.r2_minus_a2_m2) - exact).abs() / exact;
                assert!(rel <= 1e-7, "u {u} dt {dt}: |r|^2 - a^2 off by {rel:e}");
            }
        }
    }
}
