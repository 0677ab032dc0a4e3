//! Helpers shared by the integration tests: the paper camera, the documented tolerance
//! of each backend, and checks of one case against the f64 reference, each backend at
//! its own input precision (the reference is evaluated at exactly the rounded inputs
//! the backend sees, so that a check measures the algorithm, not the input rounding).
//!
//! Each test crate compiles this module on its own and uses only part of it.
#![allow(dead_code)]

use core_math::sphere::accuracy::{
    f64_rel_tolerance, limb_margin_rad, F32_REL_TOLERANCE, F32_V2_TOLERANCE,
};
use core_math::sphere::fixed_point::{geometry_from_f64, motion_to_f64};
use core_math::sphere::{Geometry, NaiveF32, Reference, CLOSED_F32, CLOSED_F64, FIXED};
use core_math::{Backend, Camera, ImageMotion, ModelError};

/// The paper's camera: f = 0.555 m, A = 13 um.
pub const CAMERA: Camera = Camera {
    focal_m: 0.555,
    pixel_m: 13e-6,
};

/// `core_math::sphere::Fixed` against the reference, on |v_P|, v1 (relative) and v2 / |v_P|,
/// anywhere in its envelope, the limb included: the tolerance of docs/fixed-point.md
/// ("Tolerance of the tests: 5e-7"; measured maximum 1.1e-7, requirement 2e-6).
pub const FIXED_REL_TOLERANCE: f64 = 5.0e-7;

/// Limb-margin buckets (deg, lower bounds; the last is everything closer) and the bound
/// on `NaiveF32`'s relative |v_P| error in each (tests/naive.rs, which measures them:
/// about 2.5x the maximum over 200 000 cases of the envelope, roll <= 45 deg, field
/// <= 40 deg, 200-2000 km). Within 0.1 deg of the limb it may also refuse a ray the
/// reference accepts.
pub const NAIVE_BUCKETS_DEG: [f64; 6] = [1.0, 0.1, 0.01, 1e-3, 1e-4, 0.0];
pub const NAIVE_BOUND: [f64; 6] = [2.0e-5, 3.0e-5, 7.0e-5, 2.5e-4, 1.0e-3, 2.5e-3];
/// Below this limb margin (deg) `NaiveF32` may refuse a ray that meets the Earth.
pub const NAIVE_MAY_REFUSE_DEG: f64 = 0.1;

/// `NaiveF32`'s documented bound for a line of sight `margin_deg` from the limb.
pub fn naive_bound(margin_deg: f64) -> f64 {
    let b = NAIVE_BUCKETS_DEG
        .iter()
        .position(|lo| margin_deg >= *lo)
        .unwrap_or(NAIVE_BUCKETS_DEG.len() - 1);
    NAIVE_BOUND[b]
}

/// The reference's own error near the limb (docs/accuracy.md: ~4e-16 / q^2), which a
/// comparison against it must allow on top of the backend's tolerance.
fn reference_error(camera: &Camera, g: &Geometry<f64>, n_px: f64) -> f64 {
    f64_rel_tolerance(camera, g, n_px).expect("the reference accepts this case")
}

/// Asserts `m` against the reference `r`: |v_P| and v1 to `rel`, v2 to `v2_tol` x |v_P|.
#[track_caller]
pub fn assert_close(
    what: &str,
    m: &ImageMotion<f64>,
    r: &ImageMotion<f64>,
    rel: f64,
    v2_tol: f64,
    ctx: &dyn core::fmt::Debug,
) {
    let sp = r.speed_mps();
    let ev = (m.speed_mps() - sp).abs() / sp;
    let e1 = (m.v1_mps - r.v1_mps).abs() / r.v1_mps.abs();
    let e2 = (m.v2_mps - r.v2_mps).abs() / sp;
    assert!(
        ev <= rel && e1 <= rel && e2 <= v2_tol,
        "{what}: |v| {ev:.3e}, v1 {e1:.3e} (tol {rel:.1e}), v2/|v| {e2:.3e} (tol {v2_tol:.1e}) \
         for {m:?} vs reference {r:?} at {ctx:?}"
    );
}

/// `CLOSED_F64` against the reference at the same inputs (`f64_rel_tolerance`).
pub fn check_closed_f64(camera: &Camera, g: &Geometry<f64>, n_px: f64) -> ImageMotion<f64> {
    let r = Reference.evaluate(camera, g, n_px).expect("reference");
    let m = CLOSED_F64.evaluate(camera, g, n_px).expect("CLOSED_F64");
    let tol = reference_error(camera, g, n_px);
    assert_close("CLOSED_F64", &m, &r, tol, tol, &(g, n_px));
    m
}

/// `CLOSED_F32` against the reference at the f32 inputs (`F32_REL_TOLERANCE`,
/// `F32_V2_TOLERANCE`, plus the reference's own error near the limb).
pub fn check_closed_f32(camera: &Camera, g: &Geometry<f64>, n_px: f64) -> ImageMotion<f32> {
    check_closed_f32_v2(camera, g, n_px, F32_V2_TOLERANCE)
}

/// [`check_closed_f32`] with another tolerance for v2 / |v_P| (`F32_V2_TOLERANCE` was
/// measured where v2 is a few percent of |v_P|).
pub fn check_closed_f32_v2(
    camera: &Camera,
    g: &Geometry<f64>,
    n_px: f64,
    v2_tol: f64,
) -> ImageMotion<f32> {
    let g32 = g.to::<f32>();
    let gx = g32.to_f64();
    let r = Reference.evaluate(camera, &gx, n_px).expect("reference");
    let m = CLOSED_F32.evaluate(camera, &g32, n_px).expect("CLOSED_F32");
    let extra = reference_error(camera, &gx, n_px);
    assert_close(
        "CLOSED_F32",
        &widen(&m),
        &r,
        F32_REL_TOLERANCE + extra,
        v2_tol + extra,
        &(g32, n_px),
    );
    m
}

/// `FIXED` against the reference at the I24F40 inputs (`FIXED_REL_TOLERANCE`).
pub fn check_fixed(camera: &Camera, g: &Geometry<f64>, n_px: f64) -> ImageMotion<f64> {
    let gq = geometry_from_f64(g).expect("I24F40 range");
    let gx = gq.to_f64();
    let r = Reference.evaluate(camera, &gx, n_px).expect("reference");
    let m = motion_to_f64(&FIXED.evaluate(camera, &gq, n_px).expect("FIXED"));
    let tol = FIXED_REL_TOLERANCE + reference_error(camera, &gx, n_px);
    assert_close("FIXED", &m, &r, tol, tol, &(gx, n_px));
    m
}

/// `NaiveF32` against the reference at the f32 inputs, to its documented bound for the
/// case's limb margin; within [`NAIVE_MAY_REFUSE_DEG`] of the limb a refusal
/// (`LineOfSightMissesEarth`) is its documented behaviour too. `None` if it refused.
pub fn check_naive(camera: &Camera, g: &Geometry<f64>, n_px: f64) -> Option<ImageMotion<f32>> {
    let g32 = g.to::<f32>();
    let gx = g32.to_f64();
    let r = Reference.evaluate(camera, &gx, n_px).expect("reference");
    let margin_deg = limb_margin_rad(camera, &gx, n_px).unwrap().to_degrees();
    match NaiveF32.evaluate(camera, &g32, n_px) {
        Ok(m) => {
            let b = naive_bound(margin_deg);
            // The documented bound is on |v_P| (v1 follows it; v2 is a few percent of it).
            assert_close("NaiveF32", &widen(&m), &r, b, b, &(g32, n_px, margin_deg));
            Some(m)
        }
        Err(e) => {
            assert_eq!(e, ModelError::LineOfSightMissesEarth, "NaiveF32 at {g32:?}");
            assert!(
                margin_deg < NAIVE_MAY_REFUSE_DEG,
                "NaiveF32 refused a ray {margin_deg} deg inside the limb"
            );
            None
        }
    }
}

/// What each backend returned, widened to f64.
#[derive(Clone, Copy, Debug)]
pub struct All {
    pub reference: ImageMotion<f64>,
    pub f64: ImageMotion<f64>,
    pub f32: ImageMotion<f32>,
    pub fixed: ImageMotion<f64>,
    /// `None` where the naive route refused (documented within 0.1 deg of the limb).
    pub naive: Option<ImageMotion<f32>>,
}

/// Every backend against the reference, each at its own input precision. The case must
/// lie in the fixed backend's envelope (docs/fixed-point.md) and meet the Earth.
pub fn check_all(camera: &Camera, g: &Geometry<f64>, n_px: f64) -> All {
    All {
        reference: Reference.evaluate(camera, g, n_px).expect("reference"),
        f64: check_closed_f64(camera, g, n_px),
        f32: check_closed_f32(camera, g, n_px),
        fixed: check_fixed(camera, g, n_px),
        naive: check_naive(camera, g, n_px),
    }
}

/// Every float backend and the reference (the case is outside the fixed envelope).
pub fn check_floats(camera: &Camera, g: &Geometry<f64>, n_px: f64) -> ImageMotion<f64> {
    check_closed_f64(camera, g, n_px);
    check_closed_f32(camera, g, n_px);
    Reference.evaluate(camera, g, n_px).unwrap()
}

/// The verdict of each backend, each at its own inputs: (name, |v_P| widened to f64, or
/// the error).
pub fn verdicts(
    camera: &Camera,
    g: &Geometry<f64>,
    n_px: f64,
) -> [(&'static str, Result<f64, ModelError>); 5] {
    let g32 = g.to::<f32>();
    let fixed = geometry_from_f64(g)
        .and_then(|gq| FIXED.evaluate(camera, &gq, n_px))
        .map(|m| motion_to_f64(&m).speed_mps());
    [
        (
            "Reference",
            Reference.evaluate(camera, g, n_px).map(|m| m.speed_mps()),
        ),
        (
            "CLOSED_F64",
            CLOSED_F64.evaluate(camera, g, n_px).map(|m| m.speed_mps()),
        ),
        (
            "CLOSED_F32",
            CLOSED_F32
                .evaluate(camera, &g32, n_px)
                .map(|m| f64::from(m.speed_mps())),
        ),
        ("FIXED", fixed),
        (
            "NaiveF32",
            NaiveF32
                .evaluate(camera, &g32, n_px)
                .map(|m| f64::from(m.speed_mps())),
        ),
    ]
}

/// Asserts that every backend refuses the case with `err`.
#[track_caller]
pub fn assert_all_refuse(camera: &Camera, g: &Geometry<f64>, n_px: f64, err: ModelError) {
    for (name, v) in verdicts(camera, g, n_px) {
        assert_eq!(v.map(|_| ()), Err(err), "{name} at {g:?}, n_px {n_px}");
    }
}

pub fn widen(m: &ImageMotion<f32>) -> ImageMotion<f64> {
    ImageMotion {
        v1_mps: f64::from(m.v1_mps),
        v2_mps: f64::from(m.v2_mps),
    }
}

/// The (fractional) pixel whose line of sight is `margin_rad` short of the limb on the
/// side of positive field angles (`margin_rad` < 0: beyond it), for the geometry's roll.
pub fn pixel_at_margin(camera: &Camera, g: &Geometry<f64>, margin_rad: f64) -> f64 {
    let limb = libm::asin(g.earth_radius_m / (g.earth_radius_m + g.altitude_m));
    libm::tan(limb - margin_rad - g.roll_rad) * camera.focal_m / camera.pixel_m
}

/// The pixel of field angle `deg`.
pub fn pixel_at_field_deg(camera: &Camera, deg: f64) -> f64 {
    libm::tan(deg.to_radians()) * camera.focal_m / camera.pixel_m
}
