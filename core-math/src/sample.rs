//! splitmix64: a seeded, dependency-free generator, so that a sample of the envelope
//! (the error report's, the tests') is the same on any machine.

use crate::model::Geometry;

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
}
