//! The general form of the real-Earth image motion, written once for any [`Real`]
//! (derivation and computer-algebra proof: `docs/derivation.md`, "The general model").
//!
//! With M = [x_L y_L z_L] A the camera's axes in I, a ground point G at s u (in B) from
//! the satellite, u = (p1, p2, -f), and c(t) = M(t)^T (G(t) - r(t)):
//!
//! ```text
//! c'/s = -W x u - V / s,      W = w_B - omega n_B   (camera's angular velocity relative
//!                                                    to the Earth, in B; n_B the spin
//!                                                    axis in B)
//!                             V = M^T (v - omega z x r)   (satellite's velocity relative
//!                                                         to the Earth, in B)
//! v1 = g1 + (p1/f) g3,  v2 = g2 + (p2/f) g3,   g = c'/s
//! ```
//!
//! Per update (once per NAV state; three sine/cosine pairs, three divisions: 1/(|h||r|),
//! 1/B^2, 1/C):
//! - in L: n = z in L = (x_L,z, y_L,z, z_L,z), the orbit rate nu = |r x v| / |r|^2 (the
//!   L frame turns about y_L at nu for any central force), V_L = (|h|/|r| - omega |r| n2,
//!   omega |r| n1, r.v/|r|), W_L = (0, nu, 0) - omega n;
//! - the attitude: W_B = A^T W_L + w_A, w_A = roll' (c_psi c_theta, -s_psi c_theta,
//!   s_theta) + pitch' (s_psi, c_psi, 0) + yaw' (0, 0, 1); V_B, n_B = A^T V_L, A^T n;
//! - the ray/ellipsoid quadratic alpha s^2 + 2 beta s + C = 0 in the coordinates where
//!   the ground is the sphere of radius A (z stretched by kappa = A/B):
//!   alpha = |u|^2 + (kappa^2 - 1)(n_B . u)^2, beta = rho_B . u with
//!   rho_B = A^T ((0, 0, |r|) + (kappa^2 - 1) r_z n), C = |K r|^2 - A^2 (from f64).
//!
//! Per pixel (no call, no division): the near root as 1/s = (sqrt(beta^2 - alpha C) -
//! beta) / C (rationalised: no cancellation between -beta and the square root), then g
//! and (v1, v2).

use core::marker::PhantomData;

use crate::earth::dem::{DemHeight, DemTile};
use crate::earth::{
    check_altitude, check_state, Attitude, Earth, EarthCamera, EarthGeometry, Ellipsoid,
    InertialAttitude, InertialGeometry, MIN_V1_MPS,
};
use crate::error::ModelError;
use crate::model::{Backend, ImageMotion};
use crate::orbit::StateVector;
use crate::real::Real;
use crate::vector::dot;

/// The general real-Earth backend in scalar `T` (`f64` or `f32`).
#[derive(Clone, Copy, Debug, Default)]
pub struct General<T>(PhantomData<T>);

impl<T> General<T> {
    pub const fn new() -> Self {
        General(PhantomData)
    }
}

/// Constants of one pixel: its line of sight u = (p1, p2, -f) in B and what follows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GeneralPixel<T> {
    /// (p1, p2, -f) (m).
    pub u_m: [T; 3],
    /// |u|^2 = p1^2 + p2^2 + f^2 (m^2).
    pub uu_m2: T,
    /// p1/f and p2/f.
    pub t1: T,
    pub t2: T,
}

/// Constants of one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GeneralUpdate<T> {
    /// The spin axis z in B.
    pub n_b: [T; 3],
    /// rho_B (m): beta = rho_B . u.
    pub rho_b_m: [T; 3],
    /// kappa^2 - 1.
    pub stretch2_minus_1: T,
    /// C = |K r|^2 - A^2 (m^2) and 1/C.
    pub c_m2: T,
    pub inv_c_per_m2: T,
    /// W_B (rad/s): the camera's angular velocity relative to the Earth, in B.
    pub w_b_rad_s: [T; 3],
    /// V_B (m/s): the satellite's velocity relative to the Earth, in B.
    pub v_b_mps: [T; 3],
}

/// A^T x with A = Rx(roll) Ry(pitch) Rz(yaw) given by its columns.
fn at_mul<T: Real>(cols: &[[T; 3]; 3], x: [T; 3]) -> [T; 3] {
    [dot(cols[0], x), dot(cols[1], x), dot(cols[2], x)]
}

/// The height-independent constants of one instant: what [`GeneralUpdate`] holds before
/// the ground is chosen. One per update; [`General::ground`] then makes the update of
/// each ground height from it (a segment's terrain) for a few operations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GeneralInstant<T> {
    /// The spin axis z in B.
    pub n_b: [T; 3],
    /// |r| A^T z_L (m): rho_B without the ellipsoid's stretch term.
    pub rho0_b_m: [T; 3],
    /// r_z (m), |r|^2 (m^2), and |r|^2 - a^2 (m^2, formed in f64).
    pub r_z_m: T,
    pub r2_m2: T,
    pub r2_minus_a2_m2: T,
    /// W_B (rad/s) and V_B (m/s), as in [`GeneralUpdate`].
    pub w_b_rad_s: [T; 3],
    pub v_b_mps: [T; 3],
}

/// The f64 state rounded to `T`, with |r|^2 - a^2: the one difference of nearly equal
/// terms (a factor up to 16 at 200 km), so it is formed in f64 from the f64 state (soft
/// f64 on the target), then rounded. Everything else is a product or a sum of like signs.
#[inline(always)]
fn state_in<T: Real>(state: &StateVector, ellipsoid: &Ellipsoid) -> ([T; 3], [T; 3], T) {
    let (r64, v64) = (state.position_m, state.velocity_mps);
    let a_m = ellipsoid.a_m;
    let r2_minus_a2 =
        T::from_f64((r64[0] * r64[0] + r64[1] * r64[1] + r64[2] * r64[2]) - a_m * a_m);
    (r64.map(T::from_f64), v64.map(T::from_f64), r2_minus_a2)
}

impl<T: Real> General<T> {
    /// The per-instant half of [`Backend::update`]: the state checks of [`check_state`]
    /// in `T`, the orbital frame, the attitude, W_B and V_B. It makes none of the f64
    /// input checks of [`EarthGeometry::check_inputs`]: a caller that takes this route
    /// (the controller, whose inputs were checked when they arrived) answers for them.
    pub fn instant(
        &self,
        state: &StateVector,
        attitude: &Attitude<T>,
        ellipsoid: &Ellipsoid,
        earth_rate_rad_s: f64,
    ) -> Result<GeneralInstant<T>, ModelError> {
        let (r, v, r2_minus_a2) = state_in(state, ellipsoid);
        self.instant_parts(r, v, r2_minus_a2, attitude, T::from_f64(earth_rate_rad_s))
    }

    /// [`General::instant`] from the state already in `T`: the position and velocity
    /// (m, m/s, ECI) and |r|^2 - a^2 (m^2, a the semi-major axis of the ellipsoid
    /// [`General::ground`] will be given), which the caller forms without cancellation
    /// (the controller: from the NAV frame's f64 value and the propagated increment,
    /// `controller::nav::Propagator`).
    // Out of line: inlined into both the plan build and the update (0.7 KB each on the
    // M4F, 2 KB in soft float), for a call that the update's count does not show
    // (docs/target.md, flash).
    #[inline(never)]
    pub fn instant_parts(
        &self,
        r: [T; 3],
        v: [T; 3],
        r2_minus_a2: T,
        attitude: &Attitude<T>,
        earth_rate_rad_s: T,
    ) -> Result<GeneralInstant<T>, ModelError> {
        #[cfg(all(target_arch = "arm", not(target_abi = "eabihf")))]
        return self.instant_parts_with(r, v, r2_minus_a2, attitude, earth_rate_rad_s, T::sin_cos);
        #[cfg(not(all(target_arch = "arm", not(target_abi = "eabihf"))))]
        self.instant_parts_by(r, v, r2_minus_a2, attitude, earth_rate_rad_s, T::sin_cos)
    }

    /// [`General::instant_parts_by`] with `sin_cos` through a pointer: one copy for
    /// every caller, where the M3 calls it with two (the planner's f32 sines, the
    /// update's integer ones: `trig::sin_cos_int`) and each would otherwise inline it.
    #[inline(never)]
    pub fn instant_parts_with(
        &self,
        r: [T; 3],
        v: [T; 3],
        r2_minus_a2: T,
        attitude: &Attitude<T>,
        earth_rate_rad_s: T,
        sin_cos: fn(T) -> (T, T),
    ) -> Result<GeneralInstant<T>, ModelError> {
        self.instant_parts_by(r, v, r2_minus_a2, attitude, earth_rate_rad_s, sin_cos)
    }

    /// [`General::instant_parts`] with the attitude's sines and cosines by `sin_cos`
    /// (a core without an FPU passes `trig::sin_cos_int`).
    #[inline(always)]
    pub fn instant_parts_by(
        &self,
        r: [T; 3],
        v: [T; 3],
        r2_minus_a2: T,
        attitude: &Attitude<T>,
        earth_rate_rad_s: T,
        sin_cos: impl Fn(T) -> (T, T),
    ) -> Result<GeneralInstant<T>, ModelError> {
        let (r2, h) = check_state(r, v)?;
        let w = earth_rate_rad_s;

        let rn = r2.sqrt();
        // |h| > 0: check_state refused any state with |h|^2 <= 1e-12 |r|^2 |v|^2.
        let hn = dot(h, h).sqrt();
        // n = z in L: x_L,z = (y_L x z_L)_z, y_L,z = h_z/|h|, z_L,z = r_z/|r|.
        let inv_hr = T::ONE / (hn * rn);
        let n_l = [
            (h[0] * r[1] - h[1] * r[0]) * inv_hr,
            h[2] * rn * inv_hr,
            r[2] * hn * inv_hr,
        ];
        let inv_r = hn * inv_hr;
        // Forward speed |h|/|r| and the orbit rate |h|/|r|^2.
        let v_fwd = hn * inv_r;
        let nu = v_fwd * inv_r;
        let rdot = dot(r, v) * inv_r;
        let wr = w * rn;
        let v_l = [v_fwd - wr * n_l[1], wr * n_l[0], rdot];
        let w_l = [-w * n_l[0], nu - w * n_l[1], -w * n_l[2]];

        let at = attitude;
        let (sp, cp) = sin_cos(at.roll_rad);
        let (st, ct) = sin_cos(at.pitch_rad);
        let (sy, cy) = sin_cos(at.yaw_rad);
        // Columns of A = Rx(roll) Ry(pitch) Rz(yaw).
        let cols = [
            [ct * cy, cp * sy + sp * st * cy, sp * sy - cp * st * cy],
            [-ct * sy, cp * cy - sp * st * sy, sp * cy + cp * st * sy],
            [st, -sp * ct, cp * ct],
        ];
        let w_a = [
            at.roll_rate_rad_s * cy * ct + at.pitch_rate_rad_s * sy,
            -at.roll_rate_rad_s * sy * ct + at.pitch_rate_rad_s * cy,
            at.roll_rate_rad_s * st + at.yaw_rate_rad_s,
        ];
        let w_b0 = at_mul(&cols, w_l);
        Ok(GeneralInstant {
            n_b: at_mul(&cols, n_l),
            // A^T (0, 0, |r|): the third row of A, i.e. each column's z, times |r|.
            rho0_b_m: [cols[0][2] * rn, cols[1][2] * rn, cols[2][2] * rn],
            r_z_m: r[2],
            r2_m2: r2,
            r2_minus_a2_m2: r2_minus_a2,
            w_b_rad_s: [w_b0[0] + w_a[0], w_b0[1] + w_a[1], w_b0[2] + w_a[2]],
            v_b_mps: at_mul(&cols, v_l),
        })
    }

    /// [`General::instant`] for an attitude given by the camera's axes B in I and its
    /// angular velocity Omega (Part II, [`InertialAttitude`]), with the same state checks
    /// and |r|^2 - a^2 formed in f64 alike.
    pub fn instant_inertial(
        &self,
        state: &StateVector,
        attitude: &InertialAttitude<T>,
        ellipsoid: &Ellipsoid,
        earth_rate_rad_s: f64,
    ) -> Result<GeneralInstant<T>, ModelError> {
        let (r, v, r2_minus_a2) = state_in(state, ellipsoid);
        self.instant_inertial_parts(r, v, r2_minus_a2, attitude, T::from_f64(earth_rate_rad_s))
    }

    /// [`General::instant_inertial`] from the state already in `T` (as
    /// [`General::instant_parts`]). No orbital frame and no trigonometry: with B the
    /// camera's axes in I, n_B = B^T z (B's third row), rho0_B = B^T r,
    /// W_B = Omega - omega n_B and V_B = B^T (v - omega z x r); 36 multiplications.
    pub fn instant_inertial_parts(
        &self,
        r: [T; 3],
        v: [T; 3],
        r2_minus_a2: T,
        attitude: &InertialAttitude<T>,
        earth_rate_rad_s: T,
    ) -> Result<GeneralInstant<T>, ModelError> {
        let (r2, _) = check_state(r, v)?;
        let w = earth_rate_rad_s;
        let m = &attitude.camera_to_inertial;
        // B^T x: each column of B (an axis of the camera) dotted with x.
        let bt = |x: [T; 3]| -> [T; 3] {
            core::array::from_fn(|j| m[0][j] * x[0] + m[1][j] * x[1] + m[2][j] * x[2])
        };
        let n_b = m[2];
        // v - omega z x r = (v_x + omega r_y, v_y - omega r_x, v_z).
        let v_rel = [v[0] + w * r[1], v[1] - w * r[0], v[2]];
        let om = attitude.omega_rad_s;
        Ok(GeneralInstant {
            n_b,
            rho0_b_m: bt(r),
            r_z_m: r[2],
            r2_m2: r2,
            r2_minus_a2_m2: r2_minus_a2,
            w_b_rad_s: [om[0] - w * n_b[0], om[1] - w * n_b[1], om[2] - w * n_b[2]],
            v_b_mps: bt(v_rel),
        })
    }

    /// [`Backend::update`] for Part II's attitude: the checks of
    /// [`InertialGeometry::check_inputs`], [`General::instant_inertial`], then
    /// [`General::ground`]. The update is Part I's type: [`Backend::motion`] and every
    /// per-pixel path take it unchanged.
    pub fn update_inertial(&self, g: &InertialGeometry<T>) -> Result<GeneralUpdate<T>, ModelError> {
        g.check_inputs()?;
        let inst =
            self.instant_inertial(&g.state, &g.attitude, &g.ellipsoid, g.earth_rate_rad_s)?;
        self.ground(&inst, &g.ellipsoid, T::from_f64(g.ground_h_m))
    }

    /// The update for the ground ellipsoid raised by `ground_h_m` (semi-axes A = a + h,
    /// B = b + h) from the instant's constants: the quadratic's terms, no trigonometry,
    /// two divisions.
    pub fn ground(
        &self,
        inst: &GeneralInstant<T>,
        ellipsoid: &Ellipsoid,
        ground_h_m: T,
    ) -> Result<GeneralUpdate<T>, ModelError> {
        let a = T::from_f64(ellipsoid.a_m);
        let eq = a + ground_h_m;
        let b = T::from_f64(ellipsoid.b_m()) + ground_h_m;
        // kappa^2 - 1 = (A - B)(A + B)/B^2 with A - B = a f.
        let k2m1 = a * T::from_f64(ellipsoid.flattening) * (eq + b) / (b * b);
        // C = (|r|^2 - a^2) - (2a + h) h + (kappa^2 - 1) r_z^2: |r|^2 - A^2 without
        // forming A^2 (C is at least 1e-6 A^2, the terrain term at most 3e-3 A^2).
        let z = inst.r_z_m;
        let c_m2 = inst.r2_minus_a2_m2 - (a + eq) * ground_h_m + k2m1 * z * z;
        check_altitude(c_m2, inst.r2_m2, eq)?;
        let kz = k2m1 * z;
        let (n, rho0) = (inst.n_b, inst.rho0_b_m);
        Ok(GeneralUpdate {
            n_b: n,
            rho_b_m: [
                rho0[0] + kz * n[0],
                rho0[1] + kz * n[1],
                rho0[2] + kz * n[2],
            ],
            stretch2_minus_1: k2m1,
            c_m2,
            inv_c_per_m2: T::ONE / c_m2,
            w_b_rad_s: inst.w_b_rad_s,
            v_b_mps: inst.v_b_mps,
        })
    }
}

impl<T: Real> GeneralUpdate<T> {
    /// The update of the same instant with the camera turned by a further yaw `delta`
    /// (given by its sine and cosine): A becomes A Rz(delta), a turn about the boresight
    /// z_B, so every B-frame vector turns by Rz(delta)^T and nothing else changes (the
    /// attitude rates' part w_A turns with them). Exact; the independent route that
    /// [`General::motion_yawed`], the controller's, is tested against.
    pub fn yawed(&self, sin_delta: T, cos_delta: T) -> GeneralUpdate<T> {
        let turn = |x: [T; 3]| {
            [
                cos_delta * x[0] + sin_delta * x[1],
                cos_delta * x[1] - sin_delta * x[0],
                x[2],
            ]
        };
        GeneralUpdate {
            n_b: turn(self.n_b),
            rho_b_m: turn(self.rho_b_m),
            w_b_rad_s: turn(self.w_b_rad_s),
            v_b_mps: turn(self.v_b_mps),
            ..*self
        }
    }
}

impl<T: Real> Backend<Earth> for General<T> {
    type Real = T;
    type Pixel = GeneralPixel<T>;
    type Update = GeneralUpdate<T>;

    /// Boot-time work in f64, rounded once.
    fn pixel(&self, camera: &EarthCamera, n_px: f64) -> Result<GeneralPixel<T>, ModelError> {
        let (p1, p2) = camera.focal_plane_m(n_px)?;
        let f = camera.focal_m;
        Ok(GeneralPixel {
            u_m: [T::from_f64(p1), T::from_f64(p2), T::from_f64(-f)],
            uu_m2: T::from_f64(p1 * p1 + p2 * p2 + f * f),
            t1: T::from_f64(p1 / f),
            t2: T::from_f64(p2 / f),
        })
    }

    fn update(&self, g: &EarthGeometry<T>) -> Result<GeneralUpdate<T>, ModelError> {
        g.check_inputs()?;
        let inst = self.instant(&g.state, &g.attitude, &g.ellipsoid, g.earth_rate_rad_s)?;
        self.ground(&inst, &g.ellipsoid, T::from_f64(g.ground_h_m))
    }

    #[inline]
    fn motion(
        &self,
        up: &GeneralUpdate<T>,
        px: &GeneralPixel<T>,
    ) -> Result<ImageMotion<T>, ModelError> {
        let g = g_at(up, px.u_m, px.uu_m2)?;
        project(g, px)
    }
}

impl<T: Real> General<T> {
    /// The ground of a pixel on a DEM tile (Part II): 1/s for the first crossing
    /// r + s d of the tile's surface ([`DemTile::first_crossing`], in `T`), d = B u the
    /// pixel's line of sight in I (I is the ITRF at the instant). What
    /// [`General::motion_at_inv_range`] takes in place of the ellipsoid's root.
    pub fn dem_inv_range<H: DemHeight>(
        &self,
        g: &InertialGeometry<T>,
        px: &GeneralPixel<T>,
        tile: &DemTile<'_, H>,
    ) -> Result<T, ModelError> {
        let r = g.state.position_m.map(T::from_f64);
        let m = &g.attitude.camera_to_inertial;
        let d = [dot(m[0], px.u_m), dot(m[1], px.u_m), dot(m[2], px.u_m)];
        let s = tile.first_crossing(&g.ellipsoid, r, d)?;
        Ok(T::ONE / s)
    }

    /// [`Backend::motion`] with the ground point given by its range instead of the
    /// ellipsoid: g = -W x u - V / s at 1/s = `inv_s`, then the projection. The image
    /// motion of an Earth-fixed point depends on the surface only through where the
    /// point is, so a DEM changes nothing else.
    pub fn motion_at_inv_range(
        &self,
        up: &GeneralUpdate<T>,
        px: &GeneralPixel<T>,
        inv_s: T,
    ) -> Result<ImageMotion<T>, ModelError> {
        project(g_of(up, px.u_m, inv_s), px)
    }
}

/// g = c'/s = -W x u - V / s at the pixel u and 1/s.
// Out of line on the Cortex-M3: only its cold and DEM routes take it there.
#[cfg_attr(all(target_arch = "arm", not(target_abi = "eabihf")), inline(never))]
#[cfg_attr(
    not(all(target_arch = "arm", not(target_abi = "eabihf"))),
    inline(always)
)]
fn g_of<T: Real>(up: &GeneralUpdate<T>, u: [T; 3], inv_s: T) -> [T; 3] {
    let (w, v) = (up.w_b_rad_s, up.v_b_mps);
    [
        -(w[1] * u[2] - w[2] * u[1]) - v[0] * inv_s,
        -(w[2] * u[0] - w[0] * u[2]) - v[1] * inv_s,
        -(w[0] * u[1] - w[1] * u[0]) - v[2] * inv_s,
    ]
}

/// g = c'/s at the pixel u (|u|^2 = `uu`): the near root, then -W x u - V / s.
#[inline(always)]
fn g_at<T: Real>(up: &GeneralUpdate<T>, u: [T; 3], uu: T) -> Result<[T; 3], ModelError> {
    let nu = dot(up.n_b, u);
    let beta = dot(up.rho_b_m, u);
    // Both roots share the sign of -beta (C > 0: the satellite is outside).
    if !(beta < T::ZERO) {
        return Err(ModelError::LineOfSightMissesEarth);
    }
    let alpha = uu + up.stretch2_minus_1 * nu * nu;
    let disc = beta * beta - alpha * up.c_m2;
    if !(disc >= T::ZERO) {
        return Err(ModelError::LineOfSightMissesEarth);
    }
    let inv_s = (disc.sqrt() - beta) * up.inv_c_per_m2;
    Ok(g_of(up, u, inv_s))
}

/// (v1, v2) = (g1 + (p1/f) g3, g2 + (p2/f) g3), refused when v1 is too slow to clock.
#[inline(always)]
fn project<T: Real>(g: [T; 3], px: &GeneralPixel<T>) -> Result<ImageMotion<T>, ModelError> {
    let v1 = g[0] + px.t1 * g[2];
    if !(v1.abs() >= T::from_f64(MIN_V1_MPS)) {
        return Err(ModelError::NoAlongTrackMotion);
    }
    Ok(ImageMotion {
        v1_mps: v1,
        v2_mps: g[1] + px.t2 * g[2],
    })
}

impl<T: Real> General<T> {
    /// [`Backend::motion`] on `up.yawed(sin_delta, cos_delta)`, without forming the
    /// turned update. The turn R = Rz(delta)^T acts on every B-frame vector of the
    /// update, so n'.u = n.(R^T u), rho'.u = rho.(R^T u), (R w) x u = R (w x R^T u) and
    /// g'(u) = R g(R^T u): the unturned update's g at the pixel turned back, turned. The
    /// projection onto the focal plane keeps the pixel's own (p1, p2).
    pub fn motion_yawed(
        &self,
        up: &GeneralUpdate<T>,
        px: &GeneralPixel<T>,
        sin_delta: T,
        cos_delta: T,
    ) -> Result<ImageMotion<T>, ModelError> {
        let (s, c, u) = (sin_delta, cos_delta, px.u_m);
        let back = [c * u[0] - s * u[1], s * u[0] + c * u[1], u[2]];
        let g = g_at(up, back, px.uu_m2)?;
        project([c * g[0] + s * g[1], c * g[1] - s * g[0], g[2]], px)
    }

    /// The constants of one row of the focal plane at one update: (v1, v2) at any p2 of
    /// the row for about twenty operations ([`GeneralRowMotion::motion_at`]).
    ///
    /// With u = (p1, p2, -f), the near root's inverse 1/s = (sqrt(disc) - beta) / C and,
    /// on the row, beta = rho.u and disc = beta^2 - C alpha polynomials in p2:
    ///
    /// ```text
    /// n.u   = nu0 + n2 p2,   nu0 = n1 p1 - n3 f
    /// beta  = b0 + rho2 p2,  b0 = rho1 p1 - rho3 f
    /// alpha = (p1^2 + f^2) + p2^2 + (kappa^2 - 1) (n.u)^2
    /// disc  = [b0^2 - C (p1^2 + f^2 + (kappa^2 - 1) nu0^2)]
    ///       + 2 [b0 rho2 - C (kappa^2 - 1) nu0 n2] p2
    ///       + [rho2^2 - C (1 + (kappa^2 - 1) n2^2)] p2^2
    /// v1    = (f + t1 p1) w2 + (w3 - t1 w1) p2 - (V1 + t1 V3) / s
    /// v2    = -(w3 p1 + f w1) + t1 w2 p2 - (w1 / f) p2^2 - (V2 + (V3 / f) p2) / s
    /// ```
    ///
    /// (t1 = p1/f; indices 1..3 are the B axes), the expansion of [`Backend::motion`]'s
    /// g and projection in p2, checked against it (`core-math/tests/earth.rs`). disc's
    /// coefficients are each of the size of beta^2, like the terms `motion` subtracts,
    /// so the expansion adds no cancellation of its own; 1/C is folded into the
    /// coefficients of 1/s. Per pixel that leaves five constants fewer and six
    /// operations fewer than `motion`'s chain restricted to the row.
    pub fn row_motion(&self, up: &GeneralUpdate<T>, row: &GeneralRow<T>) -> GeneralRowMotion<T> {
        let (p1, f, t1) = (row.p1_m, row.focal_m, row.t1);
        let (n, rho, w, v) = (up.n_b, up.rho_b_m, up.w_b_rad_s, up.v_b_mps);
        let (c, k, inv_c) = (up.c_m2, up.stretch2_minus_1, up.inv_c_per_m2);
        let nu0 = n[0] * p1 - n[2] * f;
        let b0 = rho[0] * p1 - rho[2] * f;
        let two = T::ONE + T::ONE;
        GeneralRowMotion {
            beta: [b0, rho[1]],
            disc: [
                b0 * b0 - c * (row.uu0_m2 + k * nu0 * nu0),
                two * (b0 * rho[1] - c * k * nu0 * n[1]),
                rho[1] * rho[1] - c * (T::ONE + k * n[1] * n[1]),
            ],
            v1: [
                (f + t1 * p1) * w[1],
                w[2] - t1 * w[0],
                (v[0] + t1 * v[2]) * inv_c,
            ],
            v2: [
                -(w[2] * p1 + f * w[0]),
                t1 * w[1],
                -(w[0] * row.inv_focal_per_m),
                v[1] * inv_c,
                v[2] * row.inv_focal_per_m * inv_c,
            ],
        }
    }

    /// The row of the focal plane at the camera's p1 (boot-time work in f64, rounded
    /// once), for [`General::row_motion`]. A pixel n of the camera lies on it at
    /// p2 = n x pixel pitch.
    pub fn row(&self, camera: &EarthCamera) -> Result<GeneralRow<T>, ModelError> {
        camera.focal_plane_m(0.0)?;
        let (p1, f) = (camera.p1_m, camera.focal_m);
        Ok(GeneralRow {
            p1_m: T::from_f64(p1),
            focal_m: T::from_f64(f),
            t1: T::from_f64(p1 / f),
            inv_focal_per_m: T::from_f64(1.0 / f),
            uu0_m2: T::from_f64(p1 * p1 + f * f),
        })
    }
}

/// One row of the focal plane: the pixels u = (p1, p2, -f) at one p1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GeneralRow<T> {
    pub p1_m: T,
    pub focal_m: T,
    /// p1/f and 1/f.
    pub t1: T,
    pub inv_focal_per_m: T,
    /// p1^2 + f^2 (m^2).
    pub uu0_m2: T,
}

/// A row's constants at one update ([`General::row_motion`]): each quantity of the
/// per-pixel work as a polynomial in p2, with q = sqrt(disc) - beta = C / s.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GeneralRowMotion<T> {
    /// beta = rho.u = beta\[0\] + beta\[1\] p2 (m^2).
    pub beta: [T; 2],
    /// disc = beta^2 - C alpha = disc\[0\] + disc\[1\] p2 + disc\[2\] p2^2 (m^4).
    pub disc: [T; 3],
    /// v1 = v1\[0\] + v1\[1\] p2 - v1\[2\] q (m/s).
    pub v1: [T; 3],
    /// v2 = v2\[0\] + v2\[1\] p2 + v2\[2\] p2^2 - (v2\[3\] + v2\[4\] p2) q (m/s).
    pub v2: [T; 5],
}

impl<T: Real> GeneralRowMotion<T> {
    /// (v1, v2) at the row's pixel p2 (m): [`Backend::motion`] at u = (p1, p2, -f), with
    /// its checks and errors (a pixel facing away from the ground, a miss, v1 too slow,
    /// in that order), rounded differently.
    // Out of line on the Cortex-M3, where only the DEM route and cold fallbacks take the
    // row form, a soft-float copy at each (docs/target.md, `m3-flash3`).
    #[cfg_attr(all(target_arch = "arm", not(target_abi = "eabihf")), inline(never))]
    #[cfg_attr(
        not(all(target_arch = "arm", not(target_abi = "eabihf"))),
        inline(always)
    )]
    pub fn motion_at(&self, p2_m: T) -> Result<ImageMotion<T>, ModelError> {
        if !self.faces_ground_over(p2_m, p2_m) {
            return Err(ModelError::LineOfSightMissesEarth);
        }
        self.motion_at_facing(p2_m)
    }

    /// Whether every pixel of the row between `p2_a_m` and `p2_b_m` looks towards the
    /// ground (beta < 0, [`GeneralRowMotion::motion_at`]'s first check): beta is affine in
    /// p2, and its rounding, fl(beta0 + fl(beta1 p2)), monotone in p2, so the computed
    /// beta takes its largest value over the interval at one of its ends.
    #[inline(always)]
    pub fn faces_ground_over(&self, p2_a_m: T, p2_b_m: T) -> bool {
        let beta = |p2: T| self.beta[0] + self.beta[1] * p2;
        beta(p2_a_m) < T::ZERO && beta(p2_b_m) < T::ZERO
    }

    /// [`GeneralRowMotion::motion_at`] at a pixel of an interval that
    /// [`GeneralRowMotion::faces_ground_over`] accepted: the same results and the same
    /// errors for one check instead of three. A negative discriminant makes the square
    /// root NaN and v1 with it, which the speed check refuses; only then is the error
    /// told apart (the line of sight misses, or v1 is too slow), as `motion_at` would.
    // Out of line on the Cortex-M3, where only the DEM route and cold fallbacks take the
    // row form, a soft-float copy at each (docs/target.md, `m3-flash3`).
    #[cfg_attr(all(target_arch = "arm", not(target_abi = "eabihf")), inline(never))]
    #[cfg_attr(
        not(all(target_arch = "arm", not(target_abi = "eabihf"))),
        inline(always)
    )]
    pub fn motion_at_facing(&self, p2_m: T) -> Result<ImageMotion<T>, ModelError> {
        let p2 = p2_m;
        let beta = self.beta[0] + self.beta[1] * p2;
        let d = &self.disc;
        let disc = d[0] + p2 * (d[1] + d[2] * p2);
        let q = disc.sqrt() - beta;
        let v1 = self.v1[0] + self.v1[1] * p2 - self.v1[2] * q;
        if !(v1.abs() >= T::from_f64(MIN_V1_MPS)) {
            return Err(refusal(disc));
        }
        let c = &self.v2;
        Ok(ImageMotion {
            v1_mps: v1,
            v2_mps: c[0] + p2 * (c[1] + c[2] * p2) - (c[3] + c[4] * p2) * q,
        })
    }
}

/// Which check of [`GeneralRowMotion::motion_at`] refuses a pixel that faces the ground,
/// given its discriminant.
#[cold]
#[inline(never)]
fn refusal<T: Real>(disc: T) -> ModelError {
    if disc >= T::ZERO {
        ModelError::NoAlongTrackMotion
    } else {
        ModelError::LineOfSightMissesEarth
    }
}
