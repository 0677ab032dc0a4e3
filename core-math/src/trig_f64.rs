//! f64 sine and cosine for the arguments the model produces, without libm's reduction
//! for huge arguments.
//!
//! libm's `sin`, `cos` and `sincos` reduce every argument by pi/2 in `rem_pio2`, whose
//! Payne-Hanek path for |x| >= 2^20 pi/2 (the 1 584-bit table of 2/pi and
//! `rem_pio2_large`) is most of its code, 6 KB of the flight binary's flash. Every f64
//! angle the firmware takes the sine of is far smaller: the Earth-orientation angles
//! are reduced modulo 2 pi first, attitudes and anomalies are checked against their
//! envelopes, and the f32 trig's fallback starts at 12 800 rad.
//!
//! Here: fdlibm's code as libm 0.2.16 has it (`s_sin.c`'s `sincos`, `e_rem_pio2.c`
//! without its large case, `k_sin.c`, `k_cos.c`), the same operations in the same
//! order, so bit for bit libm's results for |x| < 2^20 pi/2 (`tests/trig.rs` checks it
//! over every magnitude). Beyond that, the argument cannot be reduced here and the
//! result is NaN, as for infinities: a typed refusal downstream rather than a sine of
//! an angle known to less than a radian.

/// From this |x| on (2^20 pi/2 to the f64 below it whose low word is zero: 1 647 099
/// rad) [`sin_cos`] gives NaN.
pub const SIN_COS_LIMIT_RAD: f64 = 1_647_099.0;

const TO_INT: f64 = 1.5 / f64::EPSILON;
// The constants by their bits, as fdlibm states them (its decimal forms carry more
// digits than an f64 holds).
const INV_PIO2: f64 = f64::from_bits(0x3FE4_5F30_6DC9_C883);
// pi/2 in three parts with their tails (fdlibm's PIO2_1 .. PIO2_3T): k * PIO2_n exact
// for the quadrant counts below 2^20.
const PIO2_1: f64 = f64::from_bits(0x3FF9_21FB_5440_0000);
const PIO2_1T: f64 = f64::from_bits(0x3DD0_B461_1A62_6331);
const PIO2_2: f64 = f64::from_bits(0x3DD0_B461_1A60_0000);
const PIO2_2T: f64 = f64::from_bits(0x3BA3_198A_2E03_7073);
const PIO2_3: f64 = f64::from_bits(0x3BA3_198A_2E00_0000);
const PIO2_3T: f64 = f64::from_bits(0x397B_839A_2520_49C1);

fn high_word(x: f64) -> u32 {
    (x.to_bits() >> 32) as u32
}

/// sin x on [-pi/4, pi/4], x + y the argument with y its tail (`iy` 0: y is zero).
fn k_sin(x: f64, y: f64, iy: i32) -> f64 {
    const S1: f64 = f64::from_bits(0xBFC5_5555_5555_5549);
    const S2: f64 = f64::from_bits(0x3F81_1111_1110_F8A6);
    const S3: f64 = f64::from_bits(0xBF2A_01A0_19C1_61D5);
    const S4: f64 = f64::from_bits(0x3EC7_1DE3_57B1_FE7D);
    const S5: f64 = f64::from_bits(0xBE5A_E5E6_8A2B_9CEB);
    const S6: f64 = f64::from_bits(0x3DE5_D93A_5ACF_D57C);
    let z = x * x;
    let w = z * z;
    let r = S2 + z * (S3 + z * S4) + z * w * (S5 + z * S6);
    let v = z * x;
    if iy == 0 {
        x + v * (S1 + z * r)
    } else {
        x - ((z * (0.5 * y - v * r) - y) - v * S1)
    }
}

/// cos x on [-pi/4, pi/4], x + y the argument.
// Out of line: sin, cos and sin_cos share one copy (docs/target.md, flash).
#[inline(never)]
fn k_cos(x: f64, y: f64) -> f64 {
    const C1: f64 = f64::from_bits(0x3FA5_5555_5555_554C);
    const C2: f64 = f64::from_bits(0xBF56_C16C_16C1_5177);
    const C3: f64 = f64::from_bits(0x3EFA_01A0_19CB_1590);
    const C4: f64 = f64::from_bits(0xBE92_7E4F_809C_52AD);
    const C5: f64 = f64::from_bits(0x3E21_EE9E_BDB4_B1C4);
    const C6: f64 = f64::from_bits(0xBDA8_FAE9_BE88_38D4);
    let z = x * x;
    let w = z * z;
    let r = z * (C1 + z * (C2 + z * C3)) + w * w * (C4 + z * (C5 + z * C6));
    let hz = 0.5 * z;
    let w = 1.0 - hz;
    w + (((1.0 - w) - hz) + (z * r - x * y))
}

/// Cody-Waite reduction by pi/2 in up to three rounds (fdlibm's `medium` case):
/// the quadrant and the remainder as a head and tail.
fn medium(x: f64, ix: u32) -> (i32, f64, f64) {
    let f_n = (x * INV_PIO2 + TO_INT) - TO_INT;
    let n = f_n as i32;
    let mut r = x - f_n * PIO2_1;
    let mut w = f_n * PIO2_1T;
    let mut y0 = r - w;
    let ex = (ix >> 20) as i32;
    let ey = (y0.to_bits() >> 52) as i32 & 0x7ff;
    if ex - ey > 16 {
        let t = r;
        w = f_n * PIO2_2;
        r = t - w;
        w = f_n * PIO2_2T - ((t - r) - w);
        y0 = r - w;
        let ey = (y0.to_bits() >> 52) as i32 & 0x7ff;
        if ex - ey > 49 {
            let t = r;
            w = f_n * PIO2_3;
            r = t - w;
            w = f_n * PIO2_3T - ((t - r) - w);
            y0 = r - w;
        }
    }
    let y1 = (r - y0) - w;
    (n, y0, y1)
}

/// One step of k pi/2 off x (|k| <= 4), exact to 85 bits (fdlibm's small cases).
fn step(x: f64, k: i32) -> (i32, f64, f64) {
    let kf = f64::from(k);
    let z = x - kf * PIO2_1;
    let y0 = z - kf * PIO2_1T;
    let y1 = (z - y0) - kf * PIO2_1T;
    (k, y0, y1)
}

/// x = n pi/2 + y0 + y1 for pi/4 < |x| < 2^20 pi/2 (`e_rem_pio2.c`, large case removed).
fn rem_pio2(x: f64, ix: u32) -> (i32, f64, f64) {
    let s = if x.is_sign_negative() { -1 } else { 1 };
    if ix <= 0x400f_6a7a {
        // |x| ~<= 5 pi/4; near pi/2 and pi the cancellation needs the medium case.
        if (ix & 0xf_ffff) == 0x9_21fb {
            return medium(x, ix);
        }
        return step(x, if ix <= 0x4002_d97c { s } else { 2 * s });
    }
    if ix <= 0x401c_463b {
        // |x| ~<= 9 pi/4; near 3 pi/2 and 2 pi the medium case.
        if ix <= 0x4015_fdbc {
            if ix == 0x4012_d97c {
                return medium(x, ix);
            }
            return step(x, 3 * s);
        }
        if ix == 0x4019_21fb {
            return medium(x, ix);
        }
        return step(x, 4 * s);
    }
    medium(x, ix)
}

/// x = n pi/2 + y0 + y1 with |y0| <= pi/4 for pi/4 < |x|, `ix` the high word of |x|;
/// None from 2^20 pi/2 on, for infinities and NaN.
fn reduce(x: f64, ix: u32) -> Option<(i32, f64, f64)> {
    if ix >= 0x4139_21fb {
        return None;
    }
    Some(rem_pio2(x, ix))
}

/// (sin x, cos x), bit for bit libm's `sincos` for |x| < [`SIN_COS_LIMIT_RAD`]; NaN
/// beyond, for infinities and for NaN.
// Out of line: fat LTO inlined it into the plan build and the pole beside this copy
// (docs/target.md, flash); soft-float f64 dwarfs the call.
#[inline(never)]
pub fn sin_cos(x: f64) -> (f64, f64) {
    let ix = high_word(x) & 0x7fff_ffff;
    if ix <= 0x3fe9_21fb {
        // |x| ~<= pi/4; below 2^-27 sqrt 2 sin x = x and cos x = 1 in f64.
        if ix < 0x3e46_a09e {
            return (x, 1.0);
        }
        return (k_sin(x, 0.0, 0), k_cos(x, 0.0));
    }
    let Some((n, y0, y1)) = reduce(x, ix) else {
        return (f64::NAN, f64::NAN);
    };
    let (s, c) = (k_sin(y0, y1, 1), k_cos(y0, y1));
    match n & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// sin x alone (one kernel, as libm's `sin`): [`sin_cos`]'s sine bit for bit.
pub fn sin(x: f64) -> f64 {
    let ix = high_word(x) & 0x7fff_ffff;
    if ix <= 0x3fe9_21fb {
        if ix < 0x3e46_a09e {
            return x;
        }
        return k_sin(x, 0.0, 0);
    }
    let Some((n, y0, y1)) = reduce(x, ix) else {
        return f64::NAN;
    };
    match n & 3 {
        0 => k_sin(y0, y1, 1),
        1 => k_cos(y0, y1),
        2 => -k_sin(y0, y1, 1),
        _ => -k_cos(y0, y1),
    }
}

/// cos x alone (one kernel, as libm's `cos`): [`sin_cos`]'s cosine bit for bit.
pub fn cos(x: f64) -> f64 {
    let ix = high_word(x) & 0x7fff_ffff;
    if ix <= 0x3fe9_21fb {
        if ix < 0x3e46_a09e {
            return 1.0;
        }
        return k_cos(x, 0.0);
    }
    let Some((n, y0, y1)) = reduce(x, ix) else {
        return f64::NAN;
    };
    match n & 3 {
        0 => k_cos(y0, y1),
        1 => -k_sin(y0, y1, 1),
        2 => -k_cos(y0, y1),
        _ => k_sin(y0, y1, 1),
    }
}
