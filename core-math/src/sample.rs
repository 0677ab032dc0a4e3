//! splitmix64: a seeded, dependency-free generator, so that a sample of the envelope
//! (the error report's, the tests') is the same on any machine.

use crate::model::{Camera, Geometry};

pub struct SplitMix64(pub u64);

impl SplitMix64 {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [lo, hi).
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
    }

    /// A circular-orbit geometry drawn uniformly over the envelope the error report and
    /// the tests share: roll within +/-45 deg, inclination 0-180 deg, argument of
    /// latitude 0-360 deg, altitude 200-2000 km, R = 6 371 km; rounded to f32 and
    /// widened back, so that f32, fixed point and the reference all see the same values.
    pub fn envelope_geometry(&mut self) -> Geometry<f64> {
        Geometry::circular(
            self.uniform(-45.0, 45.0).to_radians(),
            self.uniform(0.0, 180.0).to_radians(),
            self.uniform(0.0, 360.0).to_radians(),
            self.uniform(200e3, 2000e3),
            6_371e3,
        )
        .to::<f32>()
        .to_f64()
    }

    /// A pixel of `camera` for geometry `g`: three draws in four with the field angle
    /// uniform in +/-40 deg, one in four with the line of sight log-uniformly 1e-5 to
    /// 1 deg short of either limb (so that the near-limb cases are populated); `None`
    /// when that puts the field angle beyond 40 deg.
    pub fn envelope_pixel(&mut self, g: &Geometry<f64>, camera: &Camera) -> Option<f64> {
        let limb = libm::asin(g.earth_radius_m / (g.earth_radius_m + g.altitude_m));
        let alpha = if self.next_u64() & 3 == 0 {
            let margin = libm::pow(10.0, self.uniform(-5.0, 0.0)).to_radians();
            let side = if self.next_u64() & 1 == 0 { 1.0 } else { -1.0 };
            side * (limb - margin) - g.roll_rad
        } else {
            self.uniform(-40.0, 40.0).to_radians()
        };
        if alpha.abs() > 40f64.to_radians() {
            return None;
        }
        Some(libm::tan(alpha) * camera.focal_m / camera.pixel_m)
    }
}
