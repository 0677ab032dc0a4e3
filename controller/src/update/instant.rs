//! The NAV route's per-instant constants in integers, for a core without an FPU (the
//! Cortex-M3, `Config::fixed_point_pixels`): the general form's
//! `General::instant_parts_by` with every length over |r|, the products in Q30 and Q39,
//! each field rounded once to f32 at the end (docs/fixed-point.md, "The update on the
//! Cortex-M3"). The f32 route where a quantity leaves the formats.

use core_math::earth::{Attitude, General, GeneralInstant};
use core_math::wide::div_64_32;
use core_math::ModelError;

use core_math::wide::i64_to_f32_call as to_f32;

/// A finite f32 as m 2^e exactly (m signed, |m| < 2^24; zero and subnormals as 0; a
/// non-finite one as a mantissa times 2^105, past every format, so the f32 route).
#[inline(always)]
fn parts(x: f32) -> (i64, i32) {
    let bits = x.to_bits();
    let biased = ((bits >> 23) & 0xff) as i32;
    if biased == 0 {
        return (0, 0);
    }
    let m = i64::from((bits & 0x7f_ffff) | 0x80_0000);
    (if bits >> 31 != 0 { -m } else { m }, biased - 150)
}

/// m 2^sh rounded to nearest (ties up); None unless the result stays below 2^40 in
/// magnitude (every caller's values lie far inside it, or take the f32 route).
// Out of line, as the two below: a 64-bit shift by a variable is long on this core,
// and each inlined copy was another (docs/target.md, flash).
#[inline(never)]
fn round_shift(m: i64, sh: i32) -> Option<i64> {
    let r = if sh >= 0 {
        if sh > 40 || m.unsigned_abs() >= 1 << (40 - sh) {
            return (m == 0).then_some(0);
        }
        m << sh
    } else if sh > -63 {
        let k = sh.unsigned_abs();
        (m + (1 << (k - 1))) >> k
    } else {
        0
    };
    (r.unsigned_abs() < 1 << 40).then_some(r)
}

/// a b 2^-30, rounded (a b below 2^63 in magnitude at every call).
#[inline(always)]
fn mul(a: i64, b: i64) -> i64 {
    (a * b + (1 << 29)) >> 30
}

/// a b 2^-`k`, rounded (a b below 2^63 in magnitude, 1 <= k <= 62).
#[inline(never)]
fn mul_shr(a: i64, b: i64, k: u32) -> i64 {
    (a * b + (1 << (k - 1))) >> k
}

/// a b 2^-30 rounded, of two Q30 values (one 32 x 32 -> 64 product).
#[inline(always)]
fn q30(a: i32, b: i32) -> i64 {
    (i64::from(a) * i64::from(b) + (1 << 29)) >> 30
}

/// [`q30`] of two values whose product stays inside i32 after the shift (unit vectors,
/// the attitude matrix).
#[inline(always)]
fn q30_32(a: i32, b: i32) -> i32 {
    q30(a, b) as i32
}

/// A^T x (A by its columns in Q30): each column dotted with x, in x's format. Out of
/// line: W_L and V_L take it (inlined, a copy each).
#[inline(never)]
fn at_mul(cols: &[[i32; 3]; 3], x: &[i64; 3]) -> [i64; 3] {
    core::array::from_fn(|j| {
        let c = cols[j];
        mul(i64::from(c[0]), x[0]) + mul(i64::from(c[1]), x[1]) + mul(i64::from(c[2]), x[2])
    })
}

/// The largest |attitude rate| (rad/s) the integers take, 2^-4 (the fixed backend's
/// envelope: 0.04 rad/s), in Q35 inside 2^31.
const MAX_RATE_Q35: i64 = 1 << 31;

/// v / |r| (rad/s) in Q39 up to 2^-8 rad/s (8.9 km/s at 2 280 km, 49 km/s at the
/// largest |r| of the fixed backend's envelope), inside 2^31.
const MAX_V_OVER_R_Q39: i64 = 1 << 31;

/// `General::<f32>::instant_parts_by` for the NAV route, in integers: the orbital frame, the
/// attitude, W_B and V_B as the general form forms them but over |r| and in Q30 (unit
/// vectors, the attitude matrix) and Q39 (rates), each field rounded once to f32. A state
/// or attitude outside the formats (|v| / |r| >= 2^-8 rad/s, an orbit rate below 2^-19
/// rad/s, an angle of 4 rad or more, a rate of 2^-4 rad/s or more, |r| of 2^23.5 m or
/// more) takes the f32 route, with its state checks.
#[inline(never)]
pub(super) fn instant_int(
    r: [f32; 3],
    v: [f32; 3],
    r2_minus_a2: f32,
    attitude: &Attitude<f32>,
    earth_rate_rad_s: f32,
) -> Result<GeneralInstant<f32>, ModelError> {
    // No `check_state` here: every state the formats take lies well inside its
    // acceptance (|r| < 2^23.5 m against 1e9 m; each |v_k| / |r| < 2^-8 rad/s, so |v| <
    // 80 km/s against 100 km/s; an orbit rate of at least 2^-19 rad/s, so a flight-path
    // sine above 2.8e-4 against 1e-6), far beyond its f32 rounding: its f32 form passes
    // each one. The others take the f32 route, which checks.
    match instant_q(r, v, r2_minus_a2, attitude, earth_rate_rad_s) {
        Some(i) => Ok(i),
        None => instant_f32(r, v, r2_minus_a2, attitude, earth_rate_rad_s),
    }
}

#[cold]
#[inline(never)]
fn instant_f32(
    r: [f32; 3],
    v: [f32; 3],
    r2_minus_a2: f32,
    attitude: &Attitude<f32>,
    earth_rate_rad_s: f32,
) -> Result<GeneralInstant<f32>, ModelError> {
    General::<f32>::new().instant_parts_with(
        r,
        v,
        r2_minus_a2,
        attitude,
        earth_rate_rad_s,
        core_math::trig::sin_cos_int,
    )
}

/// The integer body of [`instant_int`]; None where a quantity leaves the formats.
#[inline(always)]
fn instant_q(
    r: [f32; 3],
    v: [f32; 3],
    r2_minus_a2: f32,
    attitude: &Attitude<f32>,
    w: f32,
) -> Option<GeneralInstant<f32>> {
    // r in Q7, exactly but for its rounding to 2^-8 m (|r_k| < 2^24 m, past the fixed
    // backend's envelope), and |r|^2 from it in u64 (each square below 2^62): where the
    // f32 dot product rounds three times, 2^-9 m here.
    let mut r2q = 0u64;
    for x in r {
        let (m, e) = parts(x);
        let q = round_shift(m, e + 7)?;
        if q.abs() >= 1 << 31 {
            return None;
        }
        r2q += q.unsigned_abs() * q.unsigned_abs();
    }
    // M = r2q 2^z in [2^62, 2^64), z even; |r| = s 2^h with s in [2^31, 2^32] (within 2
    // units), and 1/|r| = inv 2^(-62 - h), inv in (2^30, 2^31].
    if r2q == 0 || r2q >= 1 << 61 {
        return None;
    }
    let z = r2q.leading_zeros() & !1;
    let s = core_math::earth::fixed::sqrt_per_update(r2q << z);
    let h = -7 - (z / 2) as i32;
    let inv = i64::from(div_64_32(1 << 30, 0, s));
    // x / |r| in Q`frac` (x's mantissa times inv: below 2^55).
    let over_r = |x: f32, frac: i32| -> Option<i64> {
        let (m, e) = parts(x);
        round_shift(m * inv, e - 62 - h + frac)
    };
    let mut rh = [0i32; 3];
    let mut vh = [0i32; 3];
    for k in 0..3 {
        // |r_k| / |r| <= 1 (to the roundings): inside i32 in Q30.
        rh[k] = over_r(r[k], 30)? as i32;
        let q = over_r(v[k], 39)?;
        if q.abs() >= MAX_V_OVER_R_Q39 {
            return None;
        }
        vh[k] = q as i32;
    }
    // h / |r|^2 = r^ x (v / |r|), Q39 (each below 2^31.8).
    let hh = [
        q30(rh[1], vh[2]) - q30(rh[2], vh[1]),
        q30(rh[2], vh[0]) - q30(rh[0], vh[2]),
        q30(rh[0], vh[1]) - q30(rh[1], vh[0]),
    ];
    // The orbit rate nu = |h| / |r|^2, Q39: |h| / |r|^2 <= |v| / |r| < sqrt(3) 2^-8, so the
    // sum of squares stays below 3 2^62 in u64.
    let nu2 = hh
        .iter()
        .map(|&x| x.unsigned_abs() * x.unsigned_abs())
        .fold(0u64, u64::wrapping_add);
    let nu = i64::from(core_math::earth::fixed::sqrt_per_update(nu2));
    if !(1 << 20..1 << 32).contains(&nu) {
        return None;
    }
    // h^ = h / |h| in Q30: nu normalised to [2^31, 2^32), 2^62 / that, then a product.
    let lz = (nu as u64).leading_zeros();
    let inv_nu = i64::from(div_64_32(1 << 30, 0, ((nu as u64) << (lz - 32)) as u32));
    let hat = hh.map(|x| mul_shr(x, inv_nu, 64 - lz) as i32);
    // n = z in L: ((y_L x z_L)_z, h_z / |h|, r_z / |r|), Q30.
    let n_l = [q30_32(hat[0], rh[1]) - q30_32(hat[1], rh[0]), hat[2], rh[2]];
    // The Earth's rate, Q39 (7.3e-5 rad/s: 2^25.3).
    let (wm, we) = parts(w);
    let w39 = round_shift(wm, we + 39)? as i32;
    // V_L / |r| = (nu - w n_y, w n_x, r.v / |r|^2), W_L = (-w n_x, nu - w n_y, -w n_z),
    // Q39.
    let rdot = q30(rh[0], vh[0]) + q30(rh[1], vh[1]) + q30(rh[2], vh[2]);
    let wn = n_l.map(|n| q30(w39, n));
    let v_l = [nu - wn[1], wn[0], rdot];
    let w_l = [-wn[0], nu - wn[1], -wn[2]];

    let at = attitude;
    let (sp, cp) = core_math::trig::sin_cos_f32_q30(at.roll_rad)?;
    let (st, ct) = core_math::trig::sin_cos_f32_q30(at.pitch_rad)?;
    let (sy, cy) = core_math::trig::sin_cos_f32_q30(at.yaw_rad)?;
    let q = q30_32;
    let (sp_st, cp_st) = (q(sp, st), q(cp, st));
    // Columns of A = Rx(roll) Ry(pitch) Rz(yaw), Q30.
    let cols = [
        [
            q(ct, cy),
            q(cp, sy) + q(sp_st, cy),
            q(sp, sy) - q(cp_st, cy),
        ],
        [
            -q(ct, sy),
            q(cp, cy) - q(sp_st, sy),
            q(sp, cy) + q(cp_st, sy),
        ],
        [st, -q(sp, ct), q(cp, ct)],
    ];
    // The attitude rates in Q35.
    let rate = |x: f32| -> Option<i32> {
        let (m, e) = parts(x);
        round_shift(m, e + 35)
            .filter(|q| q.abs() < MAX_RATE_Q35)
            .map(|q| q as i32)
    };
    let (rr, pr, yr) = (
        rate(at.roll_rate_rad_s)?,
        rate(at.pitch_rate_rad_s)?,
        rate(at.yaw_rate_rad_s)?,
    );
    let w_a = [
        q30(q(rr, cy), ct) + q30(pr, sy),
        -q30(q(rr, sy), ct) + q30(pr, cy),
        q30(rr, st) + i64::from(yr),
    ];
    let n_b = at_mul(&cols, &n_l.map(i64::from));
    let w_b = at_mul(&cols, &w_l);
    let v_b = at_mul(&cols, &v_l);
    // |r| = s 2^h: s / 4 keeps each product below 2^63.
    let s4 = ((u64::from(s) + 2) >> 2) as i64;
    let times_r = |x: i64, frac: i32| to_f32(x * s4, h + 2 - frac);
    Some(GeneralInstant {
        n_b: n_b.map(|x| to_f32(x, -30)),
        // |r| A^T z_L: the third row of A (each column's z) times |r|.
        rho0_b_m: [
            times_r(i64::from(cols[0][2]), 30),
            times_r(i64::from(cols[1][2]), 30),
            times_r(i64::from(cols[2][2]), 30),
        ],
        r_z_m: r[2],
        // r2q < 2^61: the same bits as its u64 conversion.
        r2_m2: to_f32(r2q as i64, -14),
        r2_minus_a2_m2: r2_minus_a2,
        // W_B = A^T W_L + w_A: Q39, the rates' part from Q35.
        w_b_rad_s: core::array::from_fn(|k| to_f32(w_b[k] + (w_a[k] << 4), -39)),
        v_b_mps: v_b.map(|x| times_r(x, 39)),
    })
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use core_math::earth::check_state;
    use core_math::sample::SplitMix64;

    /// The integer instant against the general form in f64 (libm's sines) on the same
    /// f32 inputs widened: every field within half an f32 ulp of itself plus 1e-8 of its
    /// vector's magnitude (the Q30 and Q39 roundings, sqrt_u64's two units, the sines'
    /// three: docs/fixed-point.md), over orbits from 200 to 2 500 km with eccentricity to
    /// 0.05, any inclination and position, roll and pitch to 45 deg, any yaw, rates to
    /// 2.3 deg/s; and the f32 route's error beside it.
    #[test]
    fn integer_instant_matches_f64() {
        let mut rng = SplitMix64(0x5EED_2026_1127_0021);
        let a_m = crate::EARTH.a_m;
        let w = crate::config::EARTH_RATE_RAD_S;
        let f64_form = General::<f64>::new();
        let (mut worst, mut worst_f32) = (0f64, 0f64);
        for _ in 0..20_000 {
            let radius = a_m + rng.uniform(200e3, 2_500e3);
            let state = core_math::earth::circular_state(
                radius,
                rng.uniform(0.0, core::f64::consts::PI),
                rng.uniform(-core::f64::consts::PI, core::f64::consts::PI),
            );
            let stretch = 1.0 + rng.uniform(-0.05, 0.05);
            let r = state.position_m.map(|x| x as f32);
            let v = state.velocity_mps.map(|x| (x * stretch) as f32);
            let (r64, v64) = (r.map(f64::from), v.map(f64::from));
            let r2_minus_a2 = (r64[0] * r64[0] + r64[1] * r64[1] + r64[2] * r64[2]) - a_m * a_m;
            let deg = core::f64::consts::PI / 180.0;
            let att = Attitude {
                roll_rad: rng.uniform(-45.0, 45.0) * deg,
                pitch_rad: rng.uniform(-45.0, 45.0) * deg,
                yaw_rad: rng.uniform(-180.0, 180.0) * deg,
                roll_rate_rad_s: rng.uniform(-0.04, 0.04),
                pitch_rate_rad_s: rng.uniform(-0.04, 0.04),
                yaw_rate_rad_s: rng.uniform(-0.04, 0.04),
            };
            let att32 = Attitude {
                roll_rad: att.roll_rad as f32,
                pitch_rad: att.pitch_rad as f32,
                yaw_rad: att.yaw_rad as f32,
                roll_rate_rad_s: att.roll_rate_rad_s as f32,
                pitch_rate_rad_s: att.pitch_rate_rad_s as f32,
                yaw_rate_rad_s: att.yaw_rate_rad_s as f32,
            };
            let att64 = Attitude {
                roll_rad: f64::from(att32.roll_rad),
                pitch_rad: f64::from(att32.pitch_rad),
                yaw_rad: f64::from(att32.yaw_rad),
                roll_rate_rad_s: f64::from(att32.roll_rate_rad_s),
                pitch_rate_rad_s: f64::from(att32.pitch_rate_rad_s),
                yaw_rate_rad_s: f64::from(att32.yaw_rate_rad_s),
            };
            let w32 = w as f32;
            let r2ma2_32 = r2_minus_a2 as f32;
            let want = f64_form
                .instant_parts_by(r64, v64, f64::from(r2ma2_32), &att64, f64::from(w32), |x| {
                    (libm::sin(x), libm::cos(x))
                })
                .expect("inside the envelope");
            let got = instant_q(r, v, r2ma2_32, &att32, w32).expect("inside the formats");
            assert!(check_state(r, v).is_ok());
            let float = instant_f32(r, v, r2ma2_32, &att32, w32).unwrap();
            let norm = |x: [f64; 3]| libm::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
            let vectors = |i: &GeneralInstant<f32>| {
                [i.n_b, i.rho0_b_m, i.w_b_rad_s, i.v_b_mps].map(|x| x.map(f64::from))
            };
            let want_v = [want.n_b, want.rho0_b_m, want.w_b_rad_s, want.v_b_mps];
            for (name, (g, (f, x))) in ["n_B", "rho0_B", "W_B", "V_B"].iter().zip(
                vectors(&got)
                    .iter()
                    .zip(vectors(&float).iter().zip(want_v.iter())),
            ) {
                let scale = norm(*x);
                for k in 0..3 {
                    let err = (g[k] - x[k]).abs();
                    let half_ulp = 0.5 * f64::from(f32::EPSILON) * x[k].abs();
                    assert!(
                        err <= half_ulp + 1e-8 * scale,
                        "{name}[{k}]: {} vs {} (scale {scale:e})",
                        g[k],
                        x[k]
                    );
                    worst = worst.max((err - half_ulp).max(0.0) / scale);
                    worst_f32 = worst_f32.max((f[k] - x[k]).abs() / scale);
                }
            }
        }
        std::eprintln!(
            "integer instant: within {worst:.2e} of each vector's magnitude beyond the f32 \
             rounding (the f32 route: {worst_f32:.2e} with it)"
        );
    }

    /// Inputs outside the formats take the f32 route, with its refusals.
    #[test]
    fn outside_the_formats_the_f32_route() {
        let state = core_math::earth::circular_state(crate::EARTH.a_m + 700e3, 1.0, 0.3);
        let r = state.position_m.map(|x| x as f32);
        let v = state.velocity_mps.map(|x| x as f32);
        let att = Attitude {
            roll_rad: 0.1f32,
            pitch_rad: 0.2,
            yaw_rad: 0.3,
            roll_rate_rad_s: 0.01,
            pitch_rate_rad_s: 0.0,
            yaw_rate_rad_s: 0.0,
        };
        let w = crate::config::EARTH_RATE_RAD_S as f32;
        for a in [
            Attitude {
                roll_rad: 5.0,
                ..att
            },
            Attitude {
                roll_rate_rad_s: 0.07,
                ..att
            },
        ] {
            assert!(instant_q(r, v, 1e13, &a, w).is_none());
            assert_eq!(
                instant_int(r, v, 1e13, &a, w),
                instant_f32(r, v, 1e13, &a, w)
            );
        }
        let fast = v.map(|x| x * 8.0);
        assert!(instant_q(r, fast, 1e13, &att, w).is_none());
        // A degenerate state: check_state's refusal, as on the f32 route.
        let radial = r.map(|x| x * 1e-3);
        assert_eq!(
            instant_int(r, radial, 1e13, &att, w),
            Err(ModelError::DegenerateState)
        );
        assert!(instant_q(r, v, 1e13, &att, w).is_some());
        // The formats' corners pass the f32 state checks: |r| and |v| at their bounds,
        // and the slowest orbit rate the integers take with the fastest velocity.
        let r_max = [11_860_000.0f32, 0.0, 0.0];
        let v_max = [46_000.0f32, 46_000.0, 46_000.0];
        assert!(instant_q(r_max, v_max, 1e13, &att, w).is_some());
        assert!(check_state(r_max, v_max).is_ok());
        assert!(instant_q([11_870_000.0, 0.0, 0.0], v_max, 1e13, &att, w).is_none());
        // Non-finite states take the f32 route and its refusal.
        for bad in [f32::NAN, f32::INFINITY] {
            let rb = [bad, r[1], r[2]];
            assert!(instant_q(rb, v, 1e13, &att, w).is_none());
            assert_eq!(
                instant_int(rb, v, 1e13, &att, w),
                instant_f32(rb, v, 1e13, &att, w)
            );
            assert!(instant_int(rb, v, 1e13, &att, w).is_err());
        }
    }
}
