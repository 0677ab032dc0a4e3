//! The reduced closed forms a scene plan may select agree with the full one wherever
//! their preconditions hold, and still refuse rays that miss the Earth.

use core_math::sphere::closed_form::LIMB_BRANCH_RAD;
use core_math::sphere::{Geometry, CLOSED_F32};
use core_math::{Backend, Camera, ModelError};
use proptest::prelude::*;

const CAM: Camera = Camera {
    focal_m: 0.555,
    pixel_m: 13e-6,
};

proptest! {
    #![proptest_config(ProptestConfig { cases: 5000, ..ProptestConfig::default() })]

    #[test]
    fn reduced_forms_match_the_full_one(
        h in 200e3f64..2000e3, roll in -45f64..45.0, i0 in 0f64..180.0, g0 in 0f64..360.0, n in -40_000f64..40_000.0,
    ) {
        let g = Geometry::circular(roll.to_radians(), i0.to_radians(), g0.to_radians(), h, 6_371e3).to::<f32>();
        let u = CLOSED_F32.update(&g).unwrap();
        let p = CLOSED_F32.pixel(&CAM, n).unwrap();
        let full = CLOSED_F32.motion(&u, &p);
        let no_drift = CLOSED_F32.motion_terms::<true, false>(&u, &p);
        match full {
            Ok(m) => {
                let d = no_drift.unwrap();
                prop_assert_eq!(d.v1_mps.to_bits(), m.v1_mps.to_bits());
                prop_assert_eq!(d.v2_mps, 0.0);
            }
            Err(e) => prop_assert_eq!(no_drift, Err(e)),
        }
        let gx = g.to_f64();
        let limb = libm::asin(gx.earth_radius_m / (gx.earth_radius_m + gx.altitude_m));
        let eta = gx.roll_rad + libm::atan(n * CAM.pixel_m / CAM.focal_m);
        let margin = limb - eta.abs();
        let direct = CLOSED_F32.motion_terms::<false, true>(&u, &p);
        if margin >= LIMB_BRANCH_RAD + 1e-6 {
            // Where the full form itself takes its direct branch: bit for bit.
            let (a, b) = (direct.unwrap(), full.unwrap());
            prop_assert_eq!(a.v1_mps.to_bits(), b.v1_mps.to_bits());
            prop_assert_eq!(a.v2_mps.to_bits(), b.v2_mps.to_bits());
        }
        if margin < -1e-6 || libm::cos(eta) <= 0.0 {
            prop_assert_eq!(direct, Err(ModelError::LineOfSightMissesEarth));
        }
    }
}
