//! The error bounds the project measured and relies on for the flown real-Earth model
//! (figures and the command that prints them: `docs/accuracy.md`, `cargo xtask accuracy
//! --model earth`); the round Earth's are in `sphere::accuracy`.

use crate::error::ModelError;
use crate::model::Backend;

/// Real-Earth model: relative tolerance (|dv| / |v|, dv the vector difference) of
/// `GENERAL_F64` against `EarthReference` over the envelope where the line of sight is
/// at least 0.001 deg inside the limb. Measured maximum over 50 000 draws: 1.2e-13
/// (`core-math/tests/earth.rs`; `cargo xtask accuracy` prints the bands).
pub const EARTH_F64_REL_TOLERANCE: f64 = 1.0e-12;

/// Real-Earth model: tolerance of `GENERAL_F32` against `EarthReference` (inputs as given
/// in f64: the attitude's rounding to f32 counts) where the line of sight is at least
/// 1 deg inside the limb and the problem's condition number [`earth_kappa`] is at most
/// [`EARTH_F32_KAPPA_LIMIT`] (about 90 % of the envelope).
pub const EARTH_F32_REL_TOLERANCE: f64 = 2.0e-6;
/// The same from 0.01 to 1 deg inside the limb.
pub const EARTH_F32_NEAR_LIMB_TOLERANCE: f64 = 2.0e-5;
/// Up to this condition number the two bounds above hold as stated. Beyond it (an
/// attitude rate cancelling most of the image motion, or a grazing ray) the problem
/// itself amplifies the f32 rounding of its inputs (the NAV attitude is f32) past them,
/// and [`EARTH_F32_KAPPA_C`] x kappa x u32 is the bound.
pub const EARTH_F32_KAPPA_LIMIT: f64 = 30.0;
/// err <= C kappa u32 (u32 = 2^-24) everywhere at least 0.01 deg inside the limb: the
/// f32 form is backward stable. Measured maximum of err / (kappa u32): 1.25 to 1.36 (three
/// seeds of 30 000 draws, `cargo xtask accuracy --model earth`, `cargo xtask report`).
pub const EARTH_F32_KAPPA_C: f64 = 2.0;

/// Componentwise relative condition number of the real-Earth image motion:
/// sum over every input x_i of |x_i| |dv/dx_i| / |v| (v the vector (v1, v2)), the
/// derivatives by central differences of `EarthReference` with a relative step of 1e-6
/// (truncation ~1e-12, rounding ~1e-10 relative: far below what the figure is used for).
/// Inputs: the six state components, the three angles and three rates, ground height,
/// focal length, p1 and p2 (the pixel's focal-plane position), a, flattening and the
/// Earth's rate. An input that is exactly 0 is exact in every scalar and adds nothing.
/// err <= C kappa u is what a backward-stable evaluation in precision u achieves.
pub fn earth_kappa(
    camera: &crate::earth::EarthCamera,
    geometry: &crate::earth::EarthGeometry<f64>,
    n_px: f64,
) -> Result<f64, ModelError> {
    use crate::earth::{EarthCamera, EarthGeometry, EarthReference};
    type Case = (EarthCamera, EarthGeometry<f64>, f64);
    let eval = |c: &Case| EarthReference.evaluate(&c.0, &c.1, c.2);
    let base: Case = (*camera, *geometry, n_px);
    let v0 = eval(&base)?;
    let norm = libm::hypot(v0.v1_mps, v0.v2_mps);
    // Each input as a getter/setter pair on a case.
    type Field = fn(&mut Case) -> &mut f64;
    let fields: [Field; 19] = [
        |c| &mut c.1.state.position_m[0],
        |c| &mut c.1.state.position_m[1],
        |c| &mut c.1.state.position_m[2],
        |c| &mut c.1.state.velocity_mps[0],
        |c| &mut c.1.state.velocity_mps[1],
        |c| &mut c.1.state.velocity_mps[2],
        |c| &mut c.1.attitude.roll_rad,
        |c| &mut c.1.attitude.pitch_rad,
        |c| &mut c.1.attitude.yaw_rad,
        |c| &mut c.1.attitude.roll_rate_rad_s,
        |c| &mut c.1.attitude.pitch_rate_rad_s,
        |c| &mut c.1.attitude.yaw_rate_rad_s,
        |c| &mut c.1.ground_h_m,
        |c| &mut c.0.focal_m,
        |c| &mut c.0.p1_m,
        // p2 = n_px * pixel: perturbing n_px relatively perturbs p2 alone.
        |c| &mut c.2,
        |c| &mut c.1.ellipsoid.a_m,
        |c| &mut c.1.ellipsoid.flattening,
        |c| &mut c.1.earth_rate_rad_s,
    ];
    let mut kappa = 0.0;
    for field in fields {
        let mut probe = base;
        let x = *field(&mut probe);
        if x == 0.0 {
            continue;
        }
        let h = 1e-6 * x;
        *field(&mut probe) = x + h;
        let plus = eval(&probe)?;
        *field(&mut probe) = x - h;
        let minus = eval(&probe)?;
        let d = libm::hypot(plus.v1_mps - minus.v1_mps, plus.v2_mps - minus.v2_mps) / 2e-6;
        kappa += d / norm;
    }
    Ok(kappa)
}
