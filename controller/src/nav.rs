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
/// cost: docs/controller.md, "What it costs"). A core without an FPU takes the same
/// series in integers (`Propagator::parts_at_int`, with the feature `earth-fixed`).
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
    /// The same series in integers, for a core without an FPU
    /// ([`Propagator::parts_at_int`]); None where a term leaves its format.
    #[cfg(feature = "earth-fixed")]
    int: Option<SeriesInt>,
}

/// The state and the series' coefficients in integers: position Q16 (m), velocity Q20
/// (m/s), half the acceleration Q32 (m/s^2), a sixth of the jerk Q40 (m/s^3), |r|^2 - a^2
/// in m^2; each rounded once from f64.
#[cfg(feature = "earth-fixed")]
#[derive(Clone, Copy, Debug, PartialEq)]
struct SeriesInt {
    r_q16: [i64; 3],
    v_q20: [i64; 3],
    a2_q32: [i64; 3],
    j6_q40: [i64; 3],
    r2_minus_a2_m2: i64,
}

#[cfg(feature = "earth-fixed")]
impl SeriesInt {
    /// The bounds keep every product of [`Propagator::parts_at_int`] inside i64 for
    /// |dt| < 4 s: |r| < 2^24 m, |v| < 2^14 m/s, |a| / 2 < 2^3 m/s^2, |j| / 6 < 2^-6
    /// m/s^3 (a low orbit: 7.8 km/s, 4.6 m/s^2, 2e-3 m/s^3).
    fn new(
        r: [f64; 3],
        v: [f64; 3],
        a2: [f64; 3],
        j6: [f64; 3],
        r2_minus_a2: f64,
    ) -> Option<SeriesInt> {
        Some(SeriesInt {
            r_q16: q3(r, 65_536.0, 16_777_216.0)?,
            v_q20: q3(v, 1_048_576.0, 16_384.0)?,
            a2_q32: q3(a2, 4_294_967_296.0, 8.0)?,
            j6_q40: q3(j6, 1_099_511_627_776.0, 1.0 / 64.0)?,
            r2_minus_a2_m2: q1(r2_minus_a2, 1.0, 2.8e14)?,
        })
    }

    /// One component of [`Propagator::parts_at_int`]: the position and velocity `dt`
    /// (Q24 s) after the frame, as f32, and dr (2 r0 + dr) in Q16 m^2.
    // Out of line: unrolled three times, it was most of the route's flash.
    #[inline(never)]
    fn component(&self, k: usize, dt: i64) -> (f32, f32, i64) {
        let (r0, v0, a2, j6) = (
            self.r_q16[k % 3],
            self.v_q20[k % 3],
            self.a2_q32[k % 3],
            self.j6_q40[k % 3],
        );
        // Q24 x Q40 = Q64 -> Q32; Q24 x Q32 -> Q20; Q24 x Q20 -> Q16: each product below
        // 2^62 within the bounds above, each truncated once.
        let jt = (dt * j6) >> 32;
        let acc_v = v0 + ((dt * (a2 + jt)) >> 36);
        let dr = (dt * acc_v) >> 28;
        let dv = (dt * (2 * a2 + 3 * jt)) >> 36;
        let r = r0 + dr;
        // dr (Q16, below 2^32) times 2 r0 + dr to the metre (below 2^25).
        let grow = dr * ((r0 + r + (1 << 15)) >> 16);
        (
            core_math::wide::i64_to_f32_call(r, -16),
            core_math::wide::i64_to_f32_call(v0 + dv, -20),
            grow,
        )
    }
}

/// `x` times `scale` (a power of two), rounded, each |x| below `max`; None otherwise.
#[cfg(feature = "earth-fixed")]
#[inline(never)]
fn q3(x: [f64; 3], scale: f64, max: f64) -> Option<[i64; 3]> {
    Some([
        q1(x[0], scale, max)?,
        q1(x[1], scale, max)?,
        q1(x[2], scale, max)?,
    ])
}

/// [`q3`] of one value, rounded half away from zero.
// Out of line: twelve soft-f64 conversions inlined were 2.6 KB of the M3's flash.
#[cfg(feature = "earth-fixed")]
#[inline(never)]
fn q1(x: f64, scale: f64, max: f64) -> Option<i64> {
    if !(libm::fabs(x) < max) {
        return None;
    }
    let y = x * scale;
    Some((if y < 0.0 { y - 0.5 } else { y + 0.5 }) as i64)
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
            #[cfg(feature = "earth-fixed")]
            int: SeriesInt::new(
                r,
                v,
                r.map(|x| -0.5 * mu_r3 * x),
                core::array::from_fn(|k| -mu_r3 * (v[k] - 3.0 * rv_r2 * r[k]) / 6.0),
                r2 - a_m * a_m,
            ),
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

#[cfg(feature = "earth-fixed")]
impl Propagator {
    /// [`Propagator::parts_at`] in integers, for a core without an FPU: the same series
    /// by Horner's rule on `SeriesInt` with dt in Q24 (s), each product truncated once
    /// to its format, the increments added to the state exactly, |r|^2 - a^2 +
    /// dr.(2 r0 + dr) with 2 r0 + dr rounded to the metre, each output rounded once to
    /// f32 (docs/fixed-point.md, "The update on the Cortex-M3"). None where |dt| >= 4 s
    /// or the NAV state left `SeriesInt`'s bounds: the caller takes
    /// [`Propagator::parts_at`].
    pub fn parts_at_int(&self, dt_s: f32) -> Option<StateParts> {
        let p = self.int.as_ref()?;
        // dt in Q24 from its f32 bits, rounded (|dt| < 4 s: below 2^26).
        let bits = dt_s.to_bits();
        let biased = ((bits >> 23) & 0xff) as i32;
        let mant = i64::from((bits & 0x7f_ffff) | 0x80_0000);
        // |dt| 2^24 = mant 2^(biased - 126).
        let mag = match biased - 126 {
            _ if biased == 0 => 0,
            sh if sh >= 3 => return None,
            sh if sh >= 0 => mant << sh,
            sh if sh > -40 => (mant + (1 << (-sh - 1))) >> -sh,
            _ => 0,
        };
        let dt = if bits >> 31 != 0 { -mag } else { mag };
        let mut r = [0f32; 3];
        let mut v = [0f32; 3];
        let mut grow = 0i64;
        for k in 0..3 {
            let (rk, vk, g) = p.component(k, dt);
            (r[k], v[k]) = (rk, vk);
            grow += g;
        }
        Some(StateParts {
            position_m: r,
            velocity_mps: v,
            r2_minus_a2_m2: core_math::wide::i64_to_f32_call(
                p.r2_minus_a2_m2 + ((grow + (1 << 15)) >> 16),
                0,
            ),
        })
    }
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
    extern crate std;
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

    /// The integer series against the same series in f64 (the state, acceleration and
    /// jerk of `Propagator::new`'s formulas, every term in f64): each position and
    /// velocity within half an f32 ulp of itself plus 2e-3 m and 1e-5 m/s (the Q24 dt's
    /// rounding times the speed and the products' truncations), |r|^2 - a^2 within half an
    /// ulp plus 1e-9 of itself, over orbits from 200 to 2 500 km, eccentricities to 0.05
    /// and dt from -0.1 to 4 s; None from 4 s on.
    #[cfg(feature = "earth-fixed")]
    #[test]
    fn integer_parts_match_the_f64_series() {
        let mut rng = core_math::sample::SplitMix64(0x5EED_2026_1127_0031);
        let a_m = crate::EARTH.a_m;
        let (mut worst_r, mut worst_v, mut worst_c) = (0f64, 0f64, 0f64);
        for i in 0..20_000 {
            let radius = a_m + rng.uniform(200e3, 2_500e3);
            let s0 = core_math::earth::circular_state(
                radius,
                rng.uniform(0.0, core::f64::consts::PI),
                rng.uniform(-core::f64::consts::PI, core::f64::consts::PI),
            );
            let stretch = 1.0 + rng.uniform(-0.05, 0.05);
            let state = StateVector {
                position_m: s0.position_m,
                velocity_mps: s0.velocity_mps.map(|x| x * stretch),
            };
            let p = Propagator::new(&state);
            let dt = if i % 4 == 0 {
                rng.uniform(-0.1, 0.1) as f32
            } else {
                rng.uniform(-0.1, 3.99) as f32
            };
            let got = p.parts_at_int(dt).expect("inside the formats");
            let (r, v) = (state.position_m, state.velocity_mps);
            let r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
            let mu_r3 = core_math::GM_M3_S2 / (r2 * libm::sqrt(r2));
            let rv_r2 = (r[0] * v[0] + r[1] * v[1] + r[2] * v[2]) / r2;
            let t = f64::from(dt);
            let mut rt = [0f64; 3];
            for k in 0..3 {
                let a = -mu_r3 * r[k];
                let j = -mu_r3 * (v[k] - 3.0 * rv_r2 * r[k]);
                rt[k] = r[k] + v[k] * t + a * t * t / 2.0 + j * t * t * t / 6.0;
                let vt = v[k] + a * t + j * t * t / 2.0;
                let half_ulp = |x: f64| 0.5 * f64::from(f32::EPSILON) * x.abs();
                let dr = (f64::from(got.position_m[k]) - rt[k]).abs();
                let dv = (f64::from(got.velocity_mps[k]) - vt).abs();
                assert!(
                    dr <= half_ulp(rt[k]) + 2e-3,
                    "dt {dt}: r[{k}] off by {dr} m"
                );
                assert!(dv <= half_ulp(vt) + 1e-5, "dt {dt}: v[{k}] off by {dv} m/s");
                worst_r = worst_r.max(dr - half_ulp(rt[k]));
                worst_v = worst_v.max(dv - half_ulp(vt));
            }
            let c = rt[0] * rt[0] + rt[1] * rt[1] + rt[2] * rt[2] - a_m * a_m;
            let dc = (f64::from(got.r2_minus_a2_m2) - c).abs() / c;
            assert!(
                dc <= 0.5 * f64::from(f32::EPSILON) + 1e-9,
                "dt {dt}: |r|^2 - a^2 off by {dc:e}"
            );
            worst_c = worst_c.max(dc - 0.5 * f64::from(f32::EPSILON));
            assert!(p.parts_at_int(4.0).is_none() && p.parts_at_int(-4.5).is_none());
        }
        std::eprintln!(
            "integer propagation beyond the f32 rounding: {worst_r:.2e} m, {worst_v:.2e} m/s, \
             |r|^2 - a^2 {worst_c:.2e} relative"
        );
    }
}
