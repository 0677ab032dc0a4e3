//! The closed form (f64 and f32) against the independent reference chain, over random
//! cases spread across the envelope: altitude 200-2000 km, roll up to 45 deg, any
//! inclination and argument of latitude, lines of sight from nadir to 1e-6 rad short
//! of the limb on either side, several optics.

use core_math::sphere::accuracy::{f64_rel_tolerance, F32_REL_TOLERANCE, F32_V2_TOLERANCE};
use core_math::sphere::{
    Geometry, MicroF32, NaiveF32, Reference, CLOSED_F32, CLOSED_F64, CLOSED_MICROMATH,
};
use core_math::{Backend, Camera};
use proptest::prelude::*;

#[derive(Clone, Copy, Debug)]
struct Case {
    camera: Camera,
    geometry: Geometry<f64>,
    n_px: f64,
}

/// A case in the envelope whose line of sight meets the Earth: the nadir angle is drawn
/// between the two limbs, at least `min_margin_rad` inside, and the pixel that sees it
/// under the drawn roll is solved for.
fn case(min_margin_rad: f64) -> impl Strategy<Value = Case> {
    (
        200e3..2000e3f64,
        prop_oneof![Just(6_370e3f64), Just(6_378_137.0f64), 6_350e3..6_390e3f64],
        -45f64..45.0,
        0f64..180.0,
        0f64..360.0,
        -1f64..1.0,
        0.1f64..2.0,
        5e-6f64..2e-5,
    )
        .prop_filter_map(
            "field angle beyond 80 deg",
            move |(h, r, roll, i0, g0, frac, f, a)| {
                let g =
                    Geometry::circular(roll.to_radians(), i0.to_radians(), g0.to_radians(), h, r);
                let limb = libm::asin(r / (r + h));
                let eta = frac * (limb - min_margin_rad);
                let alpha = eta - g.roll_rad;
                if alpha.abs() > 80f64.to_radians() {
                    return None;
                }
                let camera = Camera {
                    focal_m: f,
                    pixel_m: a,
                };
                Some(Case {
                    camera,
                    geometry: g,
                    n_px: libm::tan(alpha) * f / a,
                })
            },
        )
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 5000, ..ProptestConfig::default() })]

    /// The derivation's proof in numbers: closed form == chain to 1e-12 (wider only
    /// within ~0.01 deg of the limb, where the reference's asin route loses digits).
    #[test]
    fn closed_form_f64_matches_reference(c in case(1e-6)) {
        let r = Reference.evaluate(&c.camera, &c.geometry, c.n_px).unwrap();
        let m = CLOSED_F64.evaluate(&c.camera, &c.geometry, c.n_px).unwrap();
        let tol = f64_rel_tolerance(&c.camera, &c.geometry, c.n_px).unwrap();
        prop_assert!(rel(m.v1_mps, r.v1_mps) <= tol, "v1 {} vs {} ({:?})", m.v1_mps, r.v1_mps, c);
        prop_assert!((m.v2_mps - r.v2_mps).abs() <= tol * r.speed_mps(), "v2 {} vs {} ({:?})", m.v2_mps, r.v2_mps, c);
        prop_assert!(rel(m.speed_mps(), r.speed_mps()) <= tol);
    }

    /// The shipped f32 path against the reference evaluated at exactly its f32 inputs.
    #[test]
    fn closed_form_f32_matches_reference(c in case(1e-6)) {
        let g32 = c.geometry.to::<f32>();
        let r = Reference.evaluate(&c.camera, &g32.to_f64(), c.n_px).unwrap();
        let m = CLOSED_F32.evaluate(&c.camera, &g32, c.n_px).unwrap();
        let sp = r.speed_mps();
        prop_assert!(rel(m.speed_mps() as f64, sp) <= F32_REL_TOLERANCE, "|v| {} vs {} ({:?})", m.speed_mps(), sp, c);
        prop_assert!(rel(m.v1_mps as f64, r.v1_mps) <= F32_REL_TOLERANCE, "v1 {} vs {} ({:?})", m.v1_mps, r.v1_mps, c);
        // v2's error: a floor of F32_V2_TOLERANCE |v_P| (v2 may be 0), plus the relative
        // tolerance of v2 itself where v2 is a large share of |v_P| (field angles near
        // 80 deg: proptest found 2.0e-7 |v_P| at 77.9 deg, regression file).
        let v2_tol = F32_V2_TOLERANCE * sp + F32_REL_TOLERANCE * r.v2_mps.abs();
        prop_assert!((m.v2_mps as f64 - r.v2_mps).abs() <= v2_tol, "v2 {} vs {} ({:?})", m.v2_mps, r.v2_mps, c);
    }

    /// The chain images pixel n at P2 = n A (Eq. 2's field angle, recovered through the
    /// ground point of Eqs. 1-6 and nine transforms), and at P1 = 0.
    #[test]
    fn chain_images_the_pixel_where_it_is(c in case(1e-4)) {
        let p = Reference.pixel(&c.camera, c.n_px).unwrap();
        let r = Reference::chain(&c.geometry, &p).unwrap();
        let n_a = c.n_px * c.camera.pixel_m;
        prop_assert!((r.p2_m - n_a).abs() <= 1e-11 * c.camera.focal_m.max(n_a.abs()), "{} vs {}", r.p2_m, n_a);
        prop_assert!(r.p1_m.abs() <= 1e-12 * c.camera.focal_m, "P1 {}", r.p1_m);
    }
}

/// Any f64 at all, NaN and infinities included, with a bias toward the edges.
fn any_f64() -> impl Strategy<Value = f64> {
    prop_oneof![
        any::<f64>(),
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(f64::NEG_INFINITY),
        Just(0.0),
        Just(-0.0),
        Just(f64::MIN_POSITIVE),
        Just(f64::MAX),
        -1e7f64..1e7,
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 3000, ..ProptestConfig::default() })]

    /// No input makes any backend panic or return a non-finite number.
    #[test]
    fn every_backend_is_total(
        v in proptest::collection::vec(any_f64(), 10),
    ) {
        let camera = Camera { focal_m: v[0], pixel_m: v[1] };
        let g = Geometry {
            roll_rad: v[2], inclination_rad: v[3], arg_latitude_rad: v[4], altitude_m: v[5],
            earth_radius_m: v[6], earth_rate_rad_s: v[7], orbit_rate_rad_s: v[8],
        };
        let n = v[9];
        if let Ok(m) = Reference.evaluate(&camera, &g, n) {
            prop_assert!(m.v1_mps.is_finite() && m.v2_mps.is_finite(), "{:?}", m);
        }
        if let Ok(m) = CLOSED_F64.evaluate(&camera, &g, n) {
            prop_assert!(m.v1_mps.is_finite() && m.v2_mps.is_finite() && m.speed_mps().is_finite(), "{:?}", m);
        }
        if let Ok(m) = CLOSED_F32.evaluate(&camera, &g.to::<f32>(), n) {
            prop_assert!(m.v1_mps.is_finite() && m.v2_mps.is_finite() && m.speed_mps().is_finite(), "{:?}", m);
        }
        // The report's variants too (FIXED has its own in tests/fixed_point.rs).
        if let Ok(m) = NaiveF32.evaluate(&camera, &g.to::<f32>(), n) {
            prop_assert!(m.v1_mps.is_finite() && m.v2_mps.is_finite() && m.speed_mps().is_finite(), "{:?}", m);
        }
        if let Ok(m) = CLOSED_MICROMATH.evaluate(&camera, &g.to::<MicroF32>(), n) {
            prop_assert!(m.v1_mps.0.is_finite() && m.v2_mps.0.is_finite() && m.speed_mps().0.is_finite(), "{:?}", m);
        }
    }
}
