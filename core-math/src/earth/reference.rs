//! The independent f64 reference of the real-Earth model: the construction of
//! `EARTH-MODEL.md` evaluated literally, with time as a dual number.
//!
//! r(t) = r + v t (only first order in t matters at t = 0; the two-body acceleration
//! enters the frame only through r x v, which it leaves constant); the local orbital
//! frame L(t) from r(t) and r x v by normalisation and cross products; A(t) = Rx Ry Rz of the angles at their rates; the
//! pixel's line of sight M(0) (p1, p2, -f), M = [x_L y_L z_L] A; its first intersection
//! with the ground ellipsoid from the textbook quadratic (polished by one Newton step);
//! that Earth-fixed point carried by Rz(omega t); its camera coordinates
//! c(t) = M(t)^T (G(t) - r(t)); P = -f (c1, c2)/c3; dP/dt from the dual parts.
//!
//! Nothing here comes from the general form's derivation (no angular velocity, no
//! closed-form range): agreement between the two is the proof of that derivation.

use crate::dual::Dual;
use crate::earth::dem::{DemHeight, DemTile};
use crate::earth::{
    Attitude, Earth, EarthCamera, EarthGeometry, Ellipsoid, Ground, InertialAttitude,
    InertialGeometry,
};
use crate::error::ModelError;
use crate::model::{Backend, ImageMotion};
use crate::orbit::StateVector;
use crate::vector::{cross, unit};

type V3 = [Dual; 3];
type M3 = [[Dual; 3]; 3];

/// The real-Earth reference backend (f64, dual numbers).
#[derive(Clone, Copy, Debug, Default)]
pub struct EarthReference;

/// A pixel of the reference: its focal-plane position and the focal length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EarthRefPixel {
    pub p1_m: f64,
    pub p2_m: f64,
    pub focal_m: f64,
}

/// What the construction gives for one pixel at t = 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EarthChain {
    /// Where the ground point projects at t = 0 (must be the pixel's (p1, p2)), m.
    pub p_m: [f64; 2],
    pub motion: ImageMotion<f64>,
    /// The ground point in I at t = 0 (m).
    pub ground_m: [f64; 3],
    /// Distance from the satellite to the ground point (m).
    pub slant_m: f64,
}

fn c(x: f64) -> Dual {
    Dual::constant(x)
}

fn mat_mul(a: &M3, b: &M3) -> M3 {
    core::array::from_fn(|i| {
        core::array::from_fn(|j| a[i][0] * b[0][j] + a[i][1] * b[1][j] + a[i][2] * b[2][j])
    })
}

fn rot_x(t: Dual) -> M3 {
    let (s, k, o, z) = (t.sin(), t.cos(), c(1.0), c(0.0));
    [[o, z, z], [z, k, -s], [z, s, k]]
}

fn rot_y(t: Dual) -> M3 {
    let (s, k, o, z) = (t.sin(), t.cos(), c(1.0), c(0.0));
    [[k, z, s], [z, o, z], [-s, z, k]]
}

fn rot_z(t: Dual) -> M3 {
    let (s, k, o, z) = (t.sin(), t.cos(), c(1.0), c(0.0));
    [[k, -s, z], [s, k, z], [z, z, o]]
}

/// An attitude the reference can evaluate: the camera's axes in I as a function of a
/// dual-number time.
pub trait ReferenceAttitude {
    /// M(t): the columns are B's axes in I at time t.
    fn axes(&self, state: &StateVector, t: Dual) -> M3;
}

/// A geometry the reference can evaluate: Part I's [`EarthGeometry`] or Part II's
/// [`InertialGeometry`] (f64).
pub trait ReferenceGeometry {
    /// The geometry's own checks (`validate`) and its ground ellipsoid.
    fn ground(&self) -> Result<Ground, ModelError>;
    fn state(&self) -> &StateVector;
    fn earth_rate_rad_s(&self) -> f64;
    /// The ellipsoid the ground (or a DEM's heights) is above.
    fn ellipsoid(&self) -> Ellipsoid;
    /// M(t), the camera's axes in I at time t.
    fn axes(&self, t: Dual) -> M3;
}

impl ReferenceGeometry for EarthGeometry<f64> {
    fn ground(&self) -> Result<Ground, ModelError> {
        self.validate()
    }
    fn state(&self) -> &StateVector {
        &self.state
    }
    fn earth_rate_rad_s(&self) -> f64 {
        self.earth_rate_rad_s
    }
    fn ellipsoid(&self) -> Ellipsoid {
        self.ellipsoid
    }
    fn axes(&self, t: Dual) -> M3 {
        self.attitude.axes(&self.state, t)
    }
}

impl ReferenceGeometry for InertialGeometry<f64> {
    fn ground(&self) -> Result<Ground, ModelError> {
        self.validate()
    }
    fn state(&self) -> &StateVector {
        &self.state
    }
    fn earth_rate_rad_s(&self) -> f64 {
        self.earth_rate_rad_s
    }
    fn ellipsoid(&self) -> Ellipsoid {
        self.ellipsoid
    }
    fn axes(&self, t: Dual) -> M3 {
        self.attitude.axes(&self.state, t)
    }
}

impl ReferenceAttitude for Attitude<f64> {
    /// M(t) = [x_L y_L z_L] A(t): the columns are B's axes in I, with r(t) = r + v t and
    /// the angles moving at their rates. The orbit normal y_L is r x v, constant on a
    /// two-body orbit (the contract says so), so it is taken at t = 0 and carries no
    /// derivative: formed from r(t) x v(t) with v(t) = v - GM r/|r|^3 t, its derivative
    /// r x a is zero only up to the rounding of a, ~1e-16 |r| |a|, and divided by |r x v|
    /// that turned the frame at 1e77 rad/s for a velocity of 1e-92 m/s (finding F9,
    /// docs/fuzzing.md).
    fn axes(&self, state: &StateVector, t: Dual) -> M3 {
        let (r0, v0) = (state.position_m, state.velocity_mps);
        let r: V3 = core::array::from_fn(|i| c(r0[i]) + c(v0[i]) * t);
        // Local orbital frame; E's columns are x_L, y_L, z_L in I.
        let z_l = unit(r);
        let y_l = unit(cross(r0, v0)).map(c);
        let x_l = cross(y_l, z_l);
        let e: M3 = core::array::from_fn(|i| [x_l[i], y_l[i], z_l[i]]);
        let at = self;
        let angle = |x: f64, rate: f64| c(x) + c(rate) * t;
        let a = mat_mul(
            &mat_mul(
                &rot_x(angle(at.roll_rad, at.roll_rate_rad_s)),
                &rot_y(angle(at.pitch_rad, at.pitch_rate_rad_s)),
            ),
            &rot_z(angle(at.yaw_rad, at.yaw_rate_rad_s)),
        );
        mat_mul(&e, &a)
    }
}

impl ReferenceAttitude for InertialAttitude<f64> {
    /// M(t) = B0 exp(\[Omega\]x t), literally: the rotation by the angle |Omega| t about
    /// Omega (Rodrigues' formula on dual numbers), applied in B. The state plays no part.
    fn axes(&self, _state: &StateVector, t: Dual) -> M3 {
        let w = self.omega_rad_s;
        let wn = libm::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
        let b0: M3 = self.camera_to_inertial.map(|row| row.map(c));
        if wn == 0.0 {
            return b0;
        }
        let k = w.map(|x| x / wn);
        let angle = c(wn) * t;
        let (s, one_minus_cos) = (angle.sin(), c(1.0) - angle.cos());
        // exp([k]x angle) = 1 + sin [k]x + (1 - cos) [k]x^2, [k]x^2 = k k^T - 1.
        let kx = [[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]];
        let rot: M3 = core::array::from_fn(|i| {
            core::array::from_fn(|j| {
                let delta = if i == j { 1.0 } else { 0.0 };
                c(delta) + s * c(kx[i][j]) + one_minus_cos * c(k[i] * k[j] - delta)
            })
        });
        mat_mul(&b0, &rot)
    }
}

impl EarthReference {
    /// The line of sight (p1, p2, -f) of a pixel in I at t = 0 (not normalised): the
    /// camera axes from the state vector and the attitude, in plain f64.
    pub fn line_of_sight<G: ReferenceGeometry>(
        g: &G,
        p1_m: f64,
        p2_m: f64,
        focal_m: f64,
    ) -> [f64; 3] {
        let m = g.axes(Dual::constant(0.0));
        let u = [p1_m, p2_m, -focal_m];
        core::array::from_fn(|i| m[i][0].re * u[0] + m[i][1].re * u[1] + m[i][2].re * u[2])
    }

    /// The whole construction for the pixel at (p1, p2) on the focal plane, the ground
    /// the geometry's ellipsoid raised by its `ground_h_m`.
    pub fn chain<G: ReferenceGeometry>(g: &G, p: &EarthRefPixel) -> Result<EarthChain, ModelError> {
        let ground = g.ground()?;
        EarthReference::chain_with(g, p, |r0, d| ellipsoid_root(&ground, r0, d))
    }

    /// [`EarthReference::chain`] with the ground a DEM tile (Part II): the ground point
    /// is the tile's [`DemTile::first_crossing`] (whose independent check is
    /// `tools/goldens/dem_crossing.py`); the construction from it on is the same.
    pub fn chain_on_dem<G: ReferenceGeometry, H: DemHeight>(
        g: &G,
        p: &EarthRefPixel,
        tile: &DemTile<'_, H>,
    ) -> Result<EarthChain, ModelError> {
        g.ground()?;
        let ellipsoid = g.ellipsoid();
        EarthReference::chain_with(g, p, |r0, d| tile.first_crossing(&ellipsoid, r0, d))
    }

    /// The construction with the ground point r0 + s d, s from `ground_s(r0, d)`.
    fn chain_with<G: ReferenceGeometry>(
        g: &G,
        p: &EarthRefPixel,
        ground_s: impl FnOnce([f64; 3], [f64; 3]) -> Result<f64, ModelError>,
    ) -> Result<EarthChain, ModelError> {
        let t = Dual::new(0.0, 1.0);
        let (r0, v0) = (g.state().position_m, g.state().velocity_mps);
        let r: V3 = core::array::from_fn(|i| c(r0[i]) + c(v0[i]) * t);
        let m = g.axes(t);

        // Line of sight in I at t = 0.
        let u = [p.p1_m, p.p2_m, -p.focal_m];
        let d: [f64; 3] =
            core::array::from_fn(|i| m[i][0].re * u[0] + m[i][1].re * u[1] + m[i][2].re * u[2]);
        let s = ground_s(r0, d)?;
        let g0: [f64; 3] = core::array::from_fn(|i| r0[i] + s * d[i]);

        // The ground point is fixed to the Earth, which turns about z.
        let gt = {
            let wt = c(g.earth_rate_rad_s()) * t;
            let (sw, cw) = (wt.sin(), wt.cos());
            [
                cw * c(g0[0]) - sw * c(g0[1]),
                sw * c(g0[0]) + cw * c(g0[1]),
                c(g0[2]),
            ]
        };
        let rel: V3 = core::array::from_fn(|i| gt[i] - r[i]);
        // Camera coordinates: B's axes (the columns of M) dotted with the relative position.
        let cam: V3 =
            core::array::from_fn(|j| m[0][j] * rel[0] + m[1][j] * rel[1] + m[2][j] * rel[2]);
        let f = c(-p.focal_m);
        let p1 = f * cam[0] / cam[2];
        let p2 = f * cam[1] / cam[2];
        let dn = libm::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        Ok(EarthChain {
            p_m: [p1.re, p2.re],
            motion: ImageMotion {
                v1_mps: p1.du,
                v2_mps: p2.du,
            },
            ground_m: g0,
            slant_m: s * dn,
        })
    }
}

impl Backend<Earth> for EarthReference {
    type Real = f64;
    type Pixel = EarthRefPixel;
    type Update = EarthGeometry<f64>;

    fn pixel(&self, camera: &EarthCamera, n_px: f64) -> Result<EarthRefPixel, ModelError> {
        let (p1_m, p2_m) = camera.focal_plane_m(n_px)?;
        Ok(EarthRefPixel {
            p1_m,
            p2_m,
            focal_m: camera.focal_m,
        })
    }

    fn update(&self, g: &EarthGeometry<f64>) -> Result<EarthGeometry<f64>, ModelError> {
        g.validate()?;
        Ok(*g)
    }

    fn motion(
        &self,
        g: &EarthGeometry<f64>,
        p: &EarthRefPixel,
    ) -> Result<ImageMotion<f64>, ModelError> {
        EarthReference::motion_of(g, p)
    }
}

impl EarthReference {
    /// [`Backend::motion`] for either geometry: Part II's attitude
    /// ([`InertialGeometry`]) as well as Part I's.
    pub fn motion_of<G: ReferenceGeometry>(
        g: &G,
        p: &EarthRefPixel,
    ) -> Result<ImageMotion<f64>, ModelError> {
        along_track(EarthReference::chain(g, p)?)
    }

    /// [`EarthReference::motion_of`] with the ground a DEM tile
    /// ([`EarthReference::chain_on_dem`]).
    pub fn motion_on_dem<G: ReferenceGeometry, H: DemHeight>(
        g: &G,
        p: &EarthRefPixel,
        tile: &DemTile<'_, H>,
    ) -> Result<ImageMotion<f64>, ModelError> {
        along_track(EarthReference::chain_on_dem(g, p, tile)?)
    }
}

/// The chain's motion, refused when v1 is too slow to clock (as the general form).
fn along_track(chain: EarthChain) -> Result<ImageMotion<f64>, ModelError> {
    if !(chain.motion.v1_mps.abs() >= super::MIN_V1_MPS) {
        return Err(ModelError::NoAlongTrackMotion);
    }
    Ok(chain.motion)
}

/// The first intersection s of r0 + s d with the ground ellipsoid
/// (x^2 + y^2)/A^2 + z^2/B^2 = 1.
fn ellipsoid_root(ground: &Ground, r0: [f64; 3], d: [f64; 3]) -> Result<f64, ModelError> {
    // First intersection of r0 + s d with (x^2 + y^2)/A^2 + z^2/B^2 = 1.
    let (ia2, ib2) = (
        1.0 / (ground.eq_m * ground.eq_m),
        1.0 / (ground.polar_m * ground.polar_m),
    );
    let qa = (d[0] * d[0] + d[1] * d[1]) * ia2 + d[2] * d[2] * ib2;
    let qb = 2.0 * ((r0[0] * d[0] + r0[1] * d[1]) * ia2 + r0[2] * d[2] * ib2);
    let qc = (r0[0] * r0[0] + r0[1] * r0[1]) * ia2 + r0[2] * r0[2] * ib2 - 1.0;
    let disc = qb * qb - 4.0 * qa * qc;
    // The satellite is outside (qc > 0, checked by validate): both roots have the sign
    // of -qb, so the ray meets the ellipsoid ahead only if qb < 0.
    if !(disc >= 0.0 && qb < 0.0) {
        return Err(ModelError::LineOfSightMissesEarth);
    }
    let mut s = (-qb - libm::sqrt(disc)) / (2.0 * qa);
    // The textbook near root loses digits to cancellation when the far root is much
    // larger (a low satellite); one Newton step on the quadratic restores them.
    let slope = 2.0 * qa * s + qb;
    if slope != 0.0 {
        let step = (qa * s * s + qb * s + qc) / slope;
        if step.is_finite() {
            s -= step;
        }
    }
    if !(s > 0.0) {
        return Err(ModelError::LineOfSightMissesEarth);
    }
    Ok(s)
}
