//! The independent f64 reference: the paper's own route, transcribed literally.
//!
//! Ground point from Eqs. 1-6 (law of sines, asin, geocentric angle), then the nine
//! homogeneous transforms of Eqs. 7-12, P(t) = M9 M8 M7 M6(t) M5 M4(t) M3 M2 M1 G,
//! evaluated on dual numbers so that dP/dt at t = 0 (Eq. 13) is exact. It shares no
//! formula with [`crate::sphere::closed_form`]; agreement between the two is the proof of the
//! derivation. It is slow (hundreds of flops and four libm calls per pixel) and meant
//! for the host, golden values and tests, though it builds for the target too.
//!
//! Two misprints of the paper are mended here, both evident from the matrices' role:
//! M5 lacks its third row (it is M3 with -i0) and M7 repeats its second row (it is a
//! translation by -(R + H) along axis 3).

use crate::dual::Dual;
use crate::error::ModelError;
use crate::model::{Backend, Camera, ImageMotion};
use crate::sphere::{Geometry, Sphere};

type Vec4 = [Dual; 4];
type Mat4 = [[Dual; 4]; 4];

const PI: f64 = core::f64::consts::PI;

/// The reference chain backend (f64, dual numbers).
#[derive(Clone, Copy, Debug, Default)]
pub struct Reference;

/// A field point of the reference: its field angle (Eq. 2) and the focal length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RefPixel {
    pub field_rad: f64,
    pub focal_m: f64,
}

/// Where the chain puts a ground point at t = 0 and how fast it moves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChainResult {
    /// P1, P2 at t = 0 (m on the focal plane).
    pub p1_m: f64,
    pub p2_m: f64,
    pub motion: ImageMotion<f64>,
    /// Ground point in the geographic frame G (Eqs. 4-6), m.
    pub g_m: [f64; 3],
}

fn c(x: f64) -> Dual {
    Dual::constant(x)
}

fn mat(rows: [[Dual; 4]; 4]) -> Mat4 {
    rows
}

fn mul(m: &Mat4, v: &Vec4) -> Vec4 {
    let mut out = [c(0.0); 4];
    for (o, row) in out.iter_mut().zip(m.iter()) {
        *o = row[0] * v[0] + row[1] * v[1] + row[2] * v[2] + row[3] * v[3];
    }
    out
}

impl Reference {
    /// The whole chain for one field point: ground point, focal-plane position at
    /// t = 0 and its exact time derivative.
    pub fn chain(g: &Geometry<f64>, p: &RefPixel) -> Result<ChainResult, ModelError> {
        g.validate()?;
        let (r, h, f) = (g.earth_radius_m, g.altitude_m, p.focal_m);
        let (phi, alpha) = (g.roll_rad, p.field_rad);

        // Eq. 1: R / sin(alpha + phi) = (H + R) / sin(beta), beta obtuse (the near
        // intersection). A ray above the horizontal has no ground point at all.
        if libm::cos(alpha + phi) <= 0.0 {
            return Err(ModelError::LineOfSightMissesEarth);
        }
        let sin_beta = (h + r) * libm::sin(alpha + phi) / r;
        if !(sin_beta.abs() < 1.0) {
            return Err(ModelError::LineOfSightMissesEarth);
        }
        let beta = PI - libm::asin(sin_beta);
        // Eq. 3 and Eqs. 4-6.
        let theta = PI - phi - alpha - beta;
        let g1 = 0.0;
        let g2 = r * libm::sin(theta);
        let g3 = r * (libm::cos(theta) - 1.0);

        // Time is the dual variable: t = 0 + 1 e.
        let t = Dual::new(0.0, 1.0);
        let (zero, one) = (c(0.0), c(1.0));
        let (g0, i0) = (g.arg_latitude_rad, g.inclination_rad);
        let wt = c(g.earth_rate_rad_s) * t;
        let gamma = c(g0) + c(g.orbit_rate_rad_s) * t;

        let m1 = mat([
            [one, zero, zero, zero],
            [zero, one, zero, zero],
            [zero, zero, one, c(r)],
            [zero, zero, zero, one],
        ]);
        let m2 = mat([
            [c(libm::cos(g0)), zero, c(libm::sin(g0)), zero],
            [zero, one, zero, zero],
            [c(-libm::sin(g0)), zero, c(libm::cos(g0)), zero],
            [zero, zero, zero, one],
        ]);
        let m3 = mat([
            [c(libm::cos(i0)), c(-libm::sin(i0)), zero, zero],
            [c(libm::sin(i0)), c(libm::cos(i0)), zero, zero],
            [zero, zero, one, zero],
            [zero, zero, zero, one],
        ]);
        let m4 = mat([
            [wt.cos(), zero, wt.sin(), zero],
            [zero, one, zero, zero],
            [-wt.sin(), zero, wt.cos(), zero],
            [zero, zero, zero, one],
        ]);
        let m5 = mat([
            [c(libm::cos(i0)), c(libm::sin(i0)), zero, zero],
            [c(-libm::sin(i0)), c(libm::cos(i0)), zero, zero],
            [zero, zero, one, zero],
            [zero, zero, zero, one],
        ]);
        let m6 = mat([
            [gamma.cos(), zero, -gamma.sin(), zero],
            [zero, one, zero, zero],
            [gamma.sin(), zero, gamma.cos(), zero],
            [zero, zero, zero, one],
        ]);
        let m7 = mat([
            [one, zero, zero, zero],
            [zero, one, zero, zero],
            [zero, zero, one, c(-(r + h))],
            [zero, zero, zero, one],
        ]);
        let m8 = mat([
            [one, zero, zero, zero],
            [zero, c(libm::cos(phi)), c(libm::sin(phi)), zero],
            [zero, c(-libm::sin(phi)), c(libm::cos(phi)), zero],
            [zero, zero, zero, one],
        ]);

        let ground: Vec4 = [c(g1), c(g2), c(g3), one];
        let mut v = ground;
        for m in [&m1, &m2, &m3, &m4, &m5, &m6, &m7, &m8] {
            v = mul(m, &v);
        }
        // Eq. 11: M9(t) = diag(-f/C3, -f/C3, f/C3, 1), itself a function of t.
        let scale = c(-f) / v[2];
        let m9 = mat([
            [scale, zero, zero, zero],
            [zero, scale, zero, zero],
            [zero, zero, -scale, zero],
            [zero, zero, zero, one],
        ]);
        let pt = mul(&m9, &v);
        Ok(ChainResult {
            p1_m: pt[0].re,
            p2_m: pt[1].re,
            motion: ImageMotion {
                v1_mps: pt[0].du,
                v2_mps: pt[1].du,
            },
            g_m: [g1, g2, g3],
        })
    }
}

impl Backend<Sphere> for Reference {
    type Real = f64;
    type Pixel = RefPixel;
    type Update = Geometry<f64>;

    fn pixel(&self, camera: &Camera, n_px: f64) -> Result<RefPixel, ModelError> {
        // Eq. 2.
        let t = camera.tan_field(n_px)?;
        Ok(RefPixel {
            field_rad: libm::atan(t),
            focal_m: camera.focal_m,
        })
    }

    fn update(&self, g: &Geometry<f64>) -> Result<Geometry<f64>, ModelError> {
        g.validate()?;
        Ok(*g)
    }

    fn motion(&self, g: &Geometry<f64>, p: &RefPixel) -> Result<ImageMotion<f64>, ModelError> {
        Reference::chain(g, p).map(|r| r.motion)
    }
}
