//! The NAV frame: orbit state from the on-board navigation and attitude relative to the
//! local orbital frame, checked field by field.

use core_math::{OrbitState, StateVector};

use crate::bytes::{Reader, Writer};
use crate::fault::Fault;

/// Payload length: 6 f64 (r, v) + 6 f32 (roll, pitch, yaw and their rates).
pub const NAV_LEN: usize = 6 * 8 + 6 * 4;

/// Attitude of the spacecraft relative to the local orbital frame (rad, rad/s).
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Attitude {
    pub roll_rad: f32,
    pub pitch_rad: f32,
    pub yaw_rad: f32,
    pub roll_rate_rad_s: f32,
    pub pitch_rate_rad_s: f32,
    pub yaw_rate_rad_s: f32,
}

impl Attitude {
    /// The six values in payload order: roll, pitch, yaw, then their rates.
    pub fn values(&self) -> [f32; 6] {
        [
            self.roll_rad,
            self.pitch_rad,
            self.yaw_rad,
            self.roll_rate_rad_s,
            self.pitch_rate_rad_s,
            self.yaw_rate_rad_s,
        ]
    }
}

/// A NAV payload as sent.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Nav {
    pub state: StateVector,
    pub attitude: Attitude,
}

impl Nav {
    /// Parses the payload; only the layout is checked here (see [`crate::control`] for
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
        for x in self.attitude.values() {
            w.put(&x.to_le_bytes())?;
        }
        Some(w.len())
    }

    /// Orbit quantities, with every value checked: finite, above the ground, in the
    /// controller's envelope.
    pub fn orbit(&self, earth_radius_m: f64) -> Result<OrbitState, Fault> {
        if !self.attitude.values().iter().all(|x| x.is_finite()) {
            return Err(Fault::NonFinite);
        }
        OrbitState::from_state(&self.state, earth_radius_m).map_err(Fault::from)
    }
}
