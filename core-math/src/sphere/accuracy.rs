//! The error bounds measured for the round-Earth backends against [`Reference`]
//! (figures and the command that prints them: `docs/accuracy.md`, `cargo xtask accuracy`).

use crate::error::ModelError;
use crate::model::{Backend, Camera};
use crate::sphere::{Geometry, Reference};

/// Relative tolerance of `CLOSED_F32`'s |v_P| and v1 against the f64 reference at the
/// same (f32-representable) inputs, anywhere in the domain the line of sight meets the
/// Earth. Measured maximum over the full sweep: 6.6e-7 (about 11 u). It does not grow
/// toward the limb, because the limb distance is carried in split precision.
pub const F32_REL_TOLERANCE: f64 = 1.0e-6;

/// Tolerance of `CLOSED_F32`'s v2 as a fraction of the reference |v_P|
/// (v2 can be exactly 0, so a relative bound on v2 itself would be meaningless).
/// Measured maximum: 3.8e-8 over the envelope, where v2 is at most a few percent of
/// |v_P|. At the domain's far edges (altitude 16 R, tan alpha = 1e4) v2 becomes the
/// larger component and its error reaches ~1.1e-7 of |v_P|; there only
/// [`F32_REL_TOLERANCE`] on |v_P| applies (`core-math/tests/stiff.rs`).
pub const F32_V2_TOLERANCE: f64 = 1.0e-7;

/// Relative tolerance of `CLOSED_F64` against the reference where the line of sight is
/// at least 0.01 deg from the limb. Closer in the reference's own asin route loses
/// digits (its error grows like u64 / q^2) and [`f64_rel_tolerance`] widens with it.
pub const F64_REL_TOLERANCE: f64 = 1.0e-12;

/// [`F32_REL_TOLERANCE`] for a case the reference accepts; the reference's refusal otherwise.
pub fn f32_rel_tolerance(
    camera: &Camera,
    geometry: &Geometry<f64>,
    n_px: f64,
) -> Result<f64, ModelError> {
    Reference.evaluate(camera, geometry, n_px)?;
    Ok(F32_REL_TOLERANCE)
}

/// Tolerance of the f64 closed form against the reference: [`F64_REL_TOLERANCE`], widened
/// near the limb by the reference's conditioning, 1e-16 * 4 / q^2 with q = cos(incidence).
pub fn f64_rel_tolerance(
    camera: &Camera,
    geometry: &Geometry<f64>,
    n_px: f64,
) -> Result<f64, ModelError> {
    let q = cos_incidence(camera, geometry, n_px)?;
    Ok(F64_REL_TOLERANCE.max(4.0e-16 / (q * q)))
}

/// cos(e), e the angle at the ground point between the line of sight and the local
/// vertical (0 at nadir, 1 at the limb), from the law of sines (Eq. 1).
pub fn cos_incidence(
    camera: &Camera,
    geometry: &Geometry<f64>,
    n_px: f64,
) -> Result<f64, ModelError> {
    let (eta, k) = nadir_angle_and_k(camera, geometry, n_px)?;
    let s = k * libm::sin(eta);
    if libm::cos(eta) <= 0.0 || !(s.abs() < 1.0) {
        return Err(ModelError::LineOfSightMissesEarth);
    }
    Ok(libm::sqrt((1.0 - s) * (1.0 + s)))
}

/// Angular distance (rad) from the line of sight to the Earth's limb, seen from the
/// camera: asin(R/(R+H)) - |roll + field angle|. Negative beyond the limb.
pub fn limb_margin_rad(
    camera: &Camera,
    geometry: &Geometry<f64>,
    n_px: f64,
) -> Result<f64, ModelError> {
    let (eta, k) = nadir_angle_and_k(camera, geometry, n_px)?;
    Ok(libm::asin(1.0 / k) - libm::fabs(eta))
}

/// The line of sight's nadir angle roll + alpha (Eq. 2's field angle) and k = (R+H)/R,
/// for a valid pixel and geometry.
fn nadir_angle_and_k(
    camera: &Camera,
    geometry: &Geometry<f64>,
    n_px: f64,
) -> Result<(f64, f64), ModelError> {
    let p = Reference.pixel(camera, n_px)?;
    geometry.validate()?;
    let k = 1.0 + geometry.altitude_m / geometry.earth_radius_m;
    Ok((geometry.roll_rad + p.field_rad, k))
}
