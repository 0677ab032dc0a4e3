//! One point of a map: the f32 and fixed-point backends against the f64 reference, and
//! the problem's condition number there.

use core_math::sphere::fixed_point::{geometry_from_f64, motion_to_f64};
use core_math::sphere::reference::RefPixel;
use core_math::sphere::{Geometry, Reference, CLOSED_F32, FIXED};
use core_math::{Backend, Camera, ImageMotion};

use crate::accuracy::U_F32;

/// The camera of every map (the paper's: f = 0.555 m, A = 13 um).
pub const CAMERA: Camera = Camera {
    focal_m: 0.555,
    pixel_m: 13e-6,
};
/// Earth radius of every map (m).
pub const EARTH_RADIUS_M: f64 = 6_371e3;
/// The fixed backend's relative LSB scale, 2^-25: half the LSB of its coarsest
/// narrowing, the I8F24 velocity bracket, relative to a bracket of one unit
/// (2^-10 rad/s, about the orbital rate); the I7F25 rates have half that.
pub const U_FIXED: f64 = 1.0 / (1u64 << 25) as f64;

/// The inputs the condition number is taken over, in [`Outcome::kappa_parts`] order.
pub const INPUTS: [&str; 8] = [
    "roll",
    "field angle",
    "inclination",
    "arg. of latitude",
    "altitude",
    "Earth radius",
    "Earth rate",
    "orbit rate",
];

/// A line of sight at one instant: the geometry and the pixel's field angle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point {
    pub g: Geometry<f64>,
    pub field_rad: f64,
}

impl Point {
    /// A circular orbit (Omega from the altitude) with R = [`EARTH_RADIUS_M`]; angles in deg.
    pub fn circular(roll_deg: f64, field_deg: f64, i0_deg: f64, g0_deg: f64, h_km: f64) -> Self {
        Point {
            g: Geometry::circular(
                roll_deg.to_radians(),
                i0_deg.to_radians(),
                g0_deg.to_radians(),
                h_km * 1e3,
                EARTH_RADIUS_M,
            ),
            field_rad: field_deg.to_radians(),
        }
    }

    /// The pixel offset whose field angle is `field_rad` (Eq. 2).
    pub fn n_px(&self) -> f64 {
        libm::tan(self.field_rad) * CAMERA.focal_m / CAMERA.pixel_m
    }
}

/// The backends' errors, relative to the reference |v_P| (the `_v1` ones to |v1|). One
/// point's in [`Outcome`]; the maxima over samples in a map cell and over cells in the
/// document's aggregates, so that all three keep and combine the same set.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RelErrors {
    /// f32 at f32-rounded inputs against the reference at the same (widened) inputs:
    /// the algorithm's own error.
    pub f32: f64,
    pub f32_v1: f64,
    /// f32 at f32-rounded inputs against the reference at the unrounded inputs: the
    /// algorithm and the rounding of its inputs, what a user sees.
    pub f32_in: f64,
    /// Fixed at I24F40-rounded inputs against the reference at the same inputs.
    pub fixed: f64,
    pub fixed_v1: f64,
    /// Fixed against the reference at the unrounded inputs.
    pub fixed_in: f64,
}

impl RelErrors {
    /// Field by field maximum with `other` (f64::max: a NaN never displaces a number).
    pub fn max_assign(&mut self, other: &RelErrors) {
        self.f32 = self.f32.max(other.f32);
        self.f32_v1 = self.f32_v1.max(other.f32_v1);
        self.f32_in = self.f32_in.max(other.f32_in);
        self.fixed = self.fixed.max(other.fixed);
        self.fixed_v1 = self.fixed_v1.max(other.fixed_v1);
        self.fixed_in = self.fixed_in.max(other.fixed_in);
    }

    /// The fixed backend's |v_P| error against the reference at its rounded or at the
    /// unrounded inputs, whichever is larger: the one fixed error the document quotes,
    /// maps and bounds.
    pub fn fixed_worst(&self) -> f64 {
        self.fixed.max(self.fixed_in)
    }
}

/// What one point measures.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Outcome {
    pub err: RelErrors,
    /// Relative condition number of |v_P|: the sum of `kappa_parts`.
    pub kappa: f64,
    /// |d ln|v_P| / d ln x_i| for the inputs of [`INPUTS`].
    pub kappa_parts: [f64; 8],
    /// Angular distance from the line of sight to the limb (rad).
    pub margin_rad: f64,
    /// q = cos(incidence at the ground point).
    pub q: f64,
    /// The second term of v1's bracket over the first, c sin(eta) / ((b/c0) cos(theta) den):
    /// positive when they cancel (|v1| = |first term| (1 - t)).
    pub v1_term_ratio: f64,
}

impl Outcome {
    pub fn ratio_f32(&self) -> f64 {
        self.err.f32 / (self.kappa * U_F32)
    }
    pub fn ratio_f32_in(&self) -> f64 {
        self.err.f32_in / (self.kappa * U_F32)
    }
    pub fn ratio_fixed(&self) -> f64 {
        self.err.fixed_worst() / (self.kappa * U_FIXED)
    }
}

/// Why a point has no outcome.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Skip {
    /// The reference refuses the unrounded or the rounded inputs (the line of sight
    /// misses the Earth, or the point is outside the fixed backend's envelope).
    Outside,
    /// The reference accepts but a backend refuses: a defect, counted and reported.
    Refused(&'static str),
}

fn speed(m: &ImageMotion<f64>) -> f64 {
    libm::hypot(m.v1_mps, m.v2_mps)
}

/// Angular distance from the line of sight to the limb (rad): asin(R/(R+H)) - |roll + alpha|.
pub fn margin_rad(g: &Geometry<f64>, field_rad: f64) -> f64 {
    libm::asin(g.earth_radius_m / (g.earth_radius_m + g.altitude_m))
        - (g.roll_rad + field_rad).abs()
}

fn reference(g: &Geometry<f64>, field_rad: f64) -> Option<ImageMotion<f64>> {
    let p = RefPixel {
        field_rad,
        focal_m: CAMERA.focal_m,
    };
    Reference::chain(g, &p).ok().map(|r| r.motion)
}

/// Evaluates the backends and the reference at `pt`.
pub fn evaluate(pt: &Point) -> Result<Outcome, Skip> {
    let n_px = pt.n_px();
    // The field angle exactly as every backend derives it from n_px.
    let alpha = Reference
        .pixel(&CAMERA, n_px)
        .map_err(|_| Skip::Outside)?
        .field_rad;
    let margin = margin_rad(&pt.g, alpha);
    // Not positive, or NaN.
    if margin.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        return Err(Skip::Outside);
    }
    let exact = reference(&pt.g, alpha).ok_or(Skip::Outside)?;
    let v_exact = speed(&exact);

    // f32: the geometry rounded to f32; the pixel constants come from n_px in f64.
    let g32 = pt.g.to::<f32>();
    let gx = g32.to_f64();
    let r32 = reference(&gx, alpha).ok_or(Skip::Outside)?;
    let m32 = CLOSED_F32
        .evaluate(&CAMERA, &g32, n_px)
        .map_err(|_| Skip::Refused("f32"))?;
    let s32 = m32.speed_mps() as f64;
    let v_r32 = speed(&r32);

    // Fixed: the geometry rounded to I24F40 (to nearest), as `eval --backend fixed` does.
    let gq = geometry_from_f64(&pt.g).map_err(|_| Skip::Outside)?;
    let gqx = gq.to_f64();
    let rq = reference(&gqx, alpha).ok_or(Skip::Outside)?;
    let mq = motion_to_f64(
        &FIXED
            .evaluate(&CAMERA, &gq, n_px)
            .map_err(|_| Skip::Refused("fixed"))?,
    );
    let sq = speed(&mq);
    let v_rq = speed(&rq);

    let (kappa, kappa_parts) = condition(&pt.g, alpha, margin, v_exact);
    Ok(Outcome {
        err: RelErrors {
            f32: (s32 - v_r32).abs() / v_r32,
            f32_v1: (m32.v1_mps as f64 - r32.v1_mps).abs() / r32.v1_mps.abs(),
            f32_in: (s32 - v_exact).abs() / v_exact,
            fixed: (sq - v_rq).abs() / v_rq,
            fixed_v1: (mq.v1_mps - rq.v1_mps).abs() / rq.v1_mps.abs(),
            fixed_in: (sq - v_exact).abs() / v_exact,
        },
        kappa,
        kappa_parts,
        margin_rad: margin,
        q: cos_incidence(&pt.g, alpha),
        v1_term_ratio: v1_term_ratio(&pt.g, alpha),
    })
}

/// The geometry with input `i` (in [`INPUTS`] order) scaled by (1 + s), and the field angle.
fn perturbed(g: &Geometry<f64>, alpha: f64, i: usize, s: f64) -> (Geometry<f64>, f64) {
    let mut g = *g;
    let mut alpha = alpha;
    let x = match i {
        0 => &mut g.roll_rad,
        1 => &mut alpha,
        2 => &mut g.inclination_rad,
        3 => &mut g.arg_latitude_rad,
        4 => &mut g.altitude_m,
        5 => &mut g.earth_radius_m,
        6 => &mut g.earth_rate_rad_s,
        _ => &mut g.orbit_rate_rad_s,
    };
    *x *= 1.0 + s;
    (g, alpha)
}

/// The relative condition number of |v_P| with respect to relative perturbations of each
/// input, kappa = sum_i |d ln|v| / d ln x_i|, by central differences of the reference
/// (f64). The relative step starts at 2^-20 and is cut until it moves the limb margin
/// by under 2 % of itself, so that near the limb the difference stays on the smooth side.
/// An input that is exactly 0 has no relative perturbation and contributes 0.
pub fn condition(g: &Geometry<f64>, alpha: f64, margin: f64, v: f64) -> (f64, [f64; 8]) {
    let mut parts = [0.0; 8];
    for (i, part) in parts.iter_mut().enumerate() {
        let mut s = 1.0 / (1u64 << 20) as f64;
        let moved = |s: f64| {
            let (gp, ap) = perturbed(g, alpha, i, s);
            let (gm, am) = perturbed(g, alpha, i, -s);
            (margin_rad(&gp, ap) - margin)
                .abs()
                .max((margin_rad(&gm, am) - margin).abs())
        };
        while moved(s) > 0.02 * margin && s > 1e-15 {
            s *= 0.25;
        }
        let (gp, ap) = perturbed(g, alpha, i, s);
        let (gm, am) = perturbed(g, alpha, i, -s);
        if gp == gm && ap == am {
            continue; // the input is 0
        }
        let (Some(hi), Some(lo)) = (reference(&gp, ap), reference(&gm, am)) else {
            continue;
        };
        *part = ((speed(&hi) - speed(&lo)) / (2.0 * s * v)).abs();
    }
    (parts.iter().sum(), parts)
}

/// cos(e), e the incidence angle at the ground point, in f64 (0 at the limb).
pub fn cos_incidence(g: &Geometry<f64>, alpha: f64) -> f64 {
    let k = 1.0 + g.altitude_m / g.earth_radius_m;
    let s = k * libm::sin(g.roll_rad + alpha);
    libm::sqrt(((1.0 - s) * (1.0 + s)).max(0.0))
}

/// c sin(eta) / ((b/c0) cos(theta) den), the ratio of v1's two terms
/// (docs/derivation.md section 5), in f64.
pub fn v1_term_ratio(g: &Geometry<f64>, alpha: f64) -> f64 {
    let eta = g.roll_rad + alpha;
    let (se, ce) = libm::sincos(eta);
    let h = g.altitude_m / g.earth_radius_m;
    let (k, c0) = (1.0 + h, h * (2.0 + h));
    let q = cos_incidence(g, alpha);
    let den = k * ce + q;
    let cos_theta = q * ce + k * se * se;
    let w = g.earth_rate_rad_s;
    let b = w * libm::cos(g.inclination_rad) - g.orbit_rate_rad_s;
    let c = w * libm::sin(g.inclination_rad) * libm::sin(g.arg_latitude_rad);
    c * se / (b / c0 * cos_theta * den)
}
