//! The satellite bus's own frames (protocol version 4, docs/telemetry.md): a GNSS fix
//! (ITRF position and velocity at its time of fix), a star-tracker ATTITUDE (the
//! quaternion of the body relative to the GCRF, gyro body rates, the time of validity)
//! and the TIME_SCALES configuration (GPS - UTC and UT1 - UTC). Times are microseconds
//! of GPS time since 1980-01-06T00:00:00 GPS: on a bus the controller's clock is GPS
//! time. Only the layout and finiteness are checked here; the window, envelope and
//! norm checks are the intake's ([`crate::intake`]).

use core_math::earth::frames::TimeScales;

use crate::bytes::{Reader, Writer};
use crate::fault::Fault;

/// GNSS payload: time of fix (u64) + ITRF position and velocity (6 f64).
pub const GNSS_LEN: usize = 8 + 6 * 8;
/// ATTITUDE payload: time of validity (u64) + quaternion (4 f32) + body rates (3 f32).
pub const ATTITUDE_LEN: usize = 8 + 4 * 4 + 3 * 4;
/// TIME_SCALES payload: GPS - UTC (i16), reserved (u16), UT1 - UTC (f32).
pub const TIME_SCALES_LEN: usize = 8;

/// A GNSS fix as the receiver gives it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Gnss {
    /// Time of fix (us of GPS time).
    pub fix_us: u64,
    /// ITRF position (m) and velocity relative to the ITRF (m/s).
    pub position_m: [f64; 3],
    pub velocity_mps: [f64; 3],
}

impl Gnss {
    pub fn decode(payload: &[u8]) -> Result<Gnss, Fault> {
        if payload.len() != GNSS_LEN {
            return Err(Fault::BadLength);
        }
        let mut r = Reader::new(payload);
        let fix_us = u64::from(r.u32().ok_or(Fault::BadLength)?)
            | (u64::from(r.u32().ok_or(Fault::BadLength)?) << 32);
        let mut v3 = || -> Option<[f64; 3]> { Some([r.f64()?, r.f64()?, r.f64()?]) };
        let position_m = v3().ok_or(Fault::BadLength)?;
        let velocity_mps = v3().ok_or(Fault::BadLength)?;
        if !position_m
            .iter()
            .chain(&velocity_mps)
            .all(|x| x.is_finite())
        {
            return Err(Fault::NonFinite);
        }
        Ok(Gnss {
            fix_us,
            position_m,
            velocity_mps,
        })
    }

    pub fn encode(&self, out: &mut [u8]) -> Option<usize> {
        let mut w = Writer::new(out);
        w.put(&self.fix_us.to_le_bytes())?;
        for x in self.position_m.iter().chain(&self.velocity_mps) {
            w.put(&x.to_le_bytes())?;
        }
        Some(w.len())
    }
}

/// A star tracker's attitude with the gyros' rates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StarAttitude {
    /// Time of validity (us of GPS time).
    pub valid_us: u64,
    /// `w, x, y, z`, scalar first, Hamilton: x_GCRF = R(q) x_body (Part II).
    pub q: [f32; 4],
    /// The body's angular velocity relative to inertial space, in body axes (rad/s).
    pub body_rate_rad_s: [f32; 3],
}

impl StarAttitude {
    // Out of line: the frame's check and the restart's restore of the blend's seed.
    #[inline(never)]
    pub fn decode(payload: &[u8]) -> Result<StarAttitude, Fault> {
        if payload.len() != ATTITUDE_LEN {
            return Err(Fault::BadLength);
        }
        let mut r = Reader::new(payload);
        let valid_us = u64::from(r.u32().ok_or(Fault::BadLength)?)
            | (u64::from(r.u32().ok_or(Fault::BadLength)?) << 32);
        let mut f = || r.f32().ok_or(Fault::BadLength);
        let q = [f()?, f()?, f()?, f()?];
        let body_rate_rad_s = [f()?, f()?, f()?];
        if !q.iter().chain(&body_rate_rad_s).all(|x| x.is_finite()) {
            return Err(Fault::NonFinite);
        }
        Ok(StarAttitude {
            valid_us,
            q,
            body_rate_rad_s,
        })
    }

    pub fn encode(&self, out: &mut [u8]) -> Option<usize> {
        let mut w = Writer::new(out);
        w.put(&self.valid_us.to_le_bytes())?;
        let (q, b) = (self.q, self.body_rate_rad_s);
        for x in [q[0], q[1], q[2], q[3], b[0], b[1], b[2]] {
            w.put(&x.to_le_bytes())?;
        }
        Some(w.len())
    }
}

/// Decodes a TIME_SCALES payload and checks it with core-math's rules
/// ([`TimeScales::validate`]): a non-finite UT1 - UTC is `non_finite`, leap seconds
/// outside 0..=60 or |UT1 - UTC| >= 0.9 s are `time_scales`.
// Out of line: the frame's check and the restart's restore each inlined it.
#[inline(never)]
pub fn decode_time_scales(payload: &[u8]) -> Result<TimeScales, Fault> {
    if payload.len() != TIME_SCALES_LEN {
        return Err(Fault::BadLength);
    }
    let mut r = Reader::new(payload);
    let leap = r.u16().ok_or(Fault::BadLength)? as i16;
    let _reserved = r.u16().ok_or(Fault::BadLength)?;
    let dut1_s = r.f32().ok_or(Fault::BadLength)?;
    if !dut1_s.is_finite() {
        return Err(Fault::NonFinite);
    }
    let scales = TimeScales {
        gps_utc_s: f64::from(leap),
        dut1_s: f64::from(dut1_s),
    };
    scales.validate().map_err(|_| Fault::TimeScales)?;
    Ok(scales)
}

/// The TIME_SCALES payload of `gps_utc_s` leap seconds and `dut1_s`.
pub fn encode_time_scales(gps_utc_s: i16, dut1_s: f32, out: &mut [u8]) -> Option<usize> {
    let mut w = Writer::new(out);
    w.put(&gps_utc_s.to_le_bytes())?;
    w.put(&[0, 0])?;
    w.put(&dut1_s.to_le_bytes())?;
    Some(w.len())
}

/// Seconds of GPS time of a clock instant (us): whole seconds and the rest apart, so
/// that nothing beyond the f64's own rounding of the sum is lost.
// Out of line: its 64-bit split was inlined into three cold callers (docs/target.md,
// flash).
#[inline(never)]
pub fn gps_s(t_us: u64) -> f64 {
    (t_us / 1_000_000) as f64 + (t_us % 1_000_000) as f64 * 1e-6
}
