//! Image motion from first principles, in inertial vectors: no formula of the paper and
//! none of `core_math`'s (it reuses only its vector helpers and Kepler propagation).
//!
//! [`general_motion`] builds the definition of `shared/EARTH-MODEL.md` directly: the
//! exact two-body motion through the state vector ([`Kepler`]), the orbit frame at the
//! satellite, the attitude as three rotations moving at their rates, the pixel's line of
//! sight intersected with the ground ellipsoid (raised by the terrain height), and that
//! Earth-fixed point, carried by the Earth's rotation, projected back into the focal plane
//! at t = +-h, ..., +-4h (P = -f (c1, c2) / c3); the image velocity is the nine-point
//! central difference of those projections. Conventions are those of
//! `core_math::sphere::Reference` (README, "Conventions"). The tests of `main.rs`
//! hold it against `core_math::sphere::Reference` and `core_math::EarthReference`; its
//! error budget and what they measure: docs/earth-model.md.

use core_math::earth::Attitude;
use core_math::vector::{add, cross, dot, norm, scale, unit};
use core_math::{EarthCamera, EarthGeometry, ImageMotion, StateVector, GM_M3_S2};
use core_math::{Ellipsoid, EARTH_RATE_RAD_S};

use core_math::earth::kepler::Kepler;

pub type V3 = [f64; 3];

/// `x a + y b + z c`.
fn comb(x: f64, a: V3, y: f64, b: V3, z: f64, c: V3) -> V3 {
    std::array::from_fn(|k| x * a[k] + y * b[k] + z * c[k])
}

/// An Earth shaped as a spheroid about the spin axis z: equatorial radius a, polar b.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Spheroid {
    pub a_m: f64,
    pub b_m: f64,
}

impl Spheroid {
    /// WGS 84: a = 6 378 137 m, f = 1 / 298.257223563.
    pub const WGS84: Spheroid = Spheroid {
        a_m: 6_378_137.0,
        b_m: 6_378_137.0 * (1.0 - 1.0 / 298.257_223_563),
    };

    /// Distance from the centre to the surface along a direction of geocentric latitude
    /// `lat_rad`: a b / sqrt(b^2 cos^2 + a^2 sin^2).
    pub fn geocentric_radius_m(&self, lat_rad: f64) -> f64 {
        let (s, c) = lat_rad.sin_cos();
        let (a, b) = (self.a_m, self.b_m);
        a * b / ((b * c).powi(2) + (a * s).powi(2)).sqrt()
    }

    /// x^2/a^2 + y^2/a^2 + z^2/b^2 - 1 (zero on the surface).
    pub fn residual(&self, p: V3) -> f64 {
        (p[0] * p[0] + p[1] * p[1]) / (self.a_m * self.a_m) + p[2] * p[2] / (self.b_m * self.b_m)
            - 1.0
    }

    /// The smallest rho > 0 at which the ray `s + rho d` meets the surface, or None.
    pub fn intersect_range(&self, s: V3, d: V3) -> Option<f64> {
        // Stretch z by a/b: the spheroid becomes the sphere of radius a.
        let k = self.a_m / self.b_m;
        let s2 = [s[0], s[1], s[2] * k];
        let d2 = [d[0], d[1], d[2] * k];
        let qa = dot(d2, d2);
        let qb = dot(s2, d2);
        let sn = norm(s2);
        // |s'|^2 - a^2 as a product: no cancellation between the two squares.
        let qc = (sn - self.a_m) * (sn + self.a_m);
        let disc = qb * qb - qa * qc;
        if !(qc > 0.0 && qb < 0.0 && disc >= 0.0) {
            return None;
        }
        // Near root (-qb - sqrt(disc)) / qa, rationalised: a sum of positive terms.
        Some(qc / (-qb + disc.sqrt()))
    }
}

/// A circular orbit in ECI (z = spin axis).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orbit {
    pub radius_m: f64,
    pub inclination_rad: f64,
    /// Right ascension of the ascending node (irrelevant over a spheroid about z).
    pub raan_rad: f64,
    /// Mean motion sqrt(GM / r^3) (rad/s).
    pub rate_rad_s: f64,
}

impl Orbit {
    pub fn circular(radius_m: f64, inclination_rad: f64, raan_rad: f64) -> Orbit {
        Orbit {
            radius_m,
            inclination_rad,
            raan_rad,
            rate_rad_s: (GM_M3_S2 / radius_m.powi(3)).sqrt(),
        }
    }

    /// In-plane unit vectors toward the node (p) and 90 deg ahead of it (q), and the
    /// orbit normal n = p x q.
    fn plane(&self) -> (V3, V3, V3) {
        let (si, ci) = self.inclination_rad.sin_cos();
        let (sn, cn) = self.raan_rad.sin_cos();
        (
            [cn, sn, 0.0],
            [-sn * ci, cn * ci, si],
            [sn * si, -cn * si, ci],
        )
    }

    /// Satellite position and the orbit frame (e1 forward, e2 left = normal, e3 up) at
    /// argument of latitude `u_rad`.
    pub fn frame(&self, u_rad: f64) -> (V3, [V3; 3]) {
        let (p, q, n) = self.plane();
        let (su, cu) = u_rad.sin_cos();
        let up = comb(cu, p, su, q, 0.0, n);
        let fwd = comb(-su, p, cu, q, 0.0, n);
        (scale(self.radius_m, up), [fwd, n, up])
    }

    /// ECI state vector at argument of latitude `u_rad` (what NAV would send).
    pub fn state(&self, u_rad: f64) -> StateVector {
        let (pos, e) = self.frame(u_rad);
        let speed = self.rate_rad_s * self.radius_m;
        StateVector {
            position_m: pos,
            velocity_mps: scale(speed, e[0]),
        }
    }
}

/// What the numerical model finds for one pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Numerical {
    pub motion: ImageMotion<f64>,
    /// The ground point (ECI at t = 0, m).
    pub ground_m: V3,
    /// Where the ground point projects at t = 0 (should be (0, n A)).
    pub p0_m: [f64; 2],
}

/// Why the general model has no image motion for a case.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Failure {
    /// The state vector is not on an ellipse (the propagation handles ellipses only).
    NotElliptic,
    /// The satellite is not above the ground ellipsoid.
    NotAboveGround,
    /// The pixel's line of sight has no intersection with the ground ellipsoid.
    Miss,
}

/// Half-width unit of the general model's stencil (s): the nine-point central difference
/// samples P at t = 0, +-h, +-2h, +-3h, +-4h. See [`general_motion`] for the budget.
pub const GENERAL_STEP_S: f64 = 0.1;

/// Weights of the nine-point first-derivative stencil, (P(kh) - P(-kh)) for k = 1..4
/// (Richardson's extrapolation of the central differences at h, 2h, 3h and 4h):
/// truncation h^8 P^(9) / 630.
const STENCIL: [f64; 4] = [4.0 / 5.0, -1.0 / 5.0, 4.0 / 105.0, -1.0 / 280.0];

/// Rotates `v` by `angle` about coordinate axis `k` (0 = x, 1 = y, 2 = z), right-handed:
/// the action of Rx, Ry or Rz of the definition.
fn rotate(k: usize, angle: f64, v: V3) -> V3 {
    let (s, c) = angle.sin_cos();
    let (i, j) = ((k + 1) % 3, (k + 2) % 3);
    let mut w = v;
    w[i] = c * v[i] - s * v[j];
    w[j] = s * v[i] + c * v[j];
    w
}

/// The general instant of `shared/EARTH-MODEL.md`, set up for the finite difference.
struct General {
    orbit: Kepler,
    r0: V3,
    attitude: Attitude<f64>,
    earth_rate_rad_s: f64,
    focal_m: f64,
    /// The ground point at t = 0 (I) and the ray from the satellite to it.
    ground_m: V3,
    to_ground_m: V3,
}

impl General {
    /// The local orbital frame's axes (x_L, y_L, z_L in I) at r, v.
    fn orbital_frame(r: V3, v: V3) -> [V3; 3] {
        let z = unit(r);
        let y = unit(cross(r, v));
        [cross(y, z), y, z]
    }

    /// (roll, pitch, yaw) at `t_s`: each angle moves linearly at its rate.
    fn angles(&self, t_s: f64) -> [f64; 3] {
        let a = &self.attitude;
        [
            a.roll_rad + a.roll_rate_rad_s * t_s,
            a.pitch_rad + a.pitch_rate_rad_s * t_s,
            a.yaw_rad + a.yaw_rate_rad_s * t_s,
        ]
    }

    /// Focal-plane position (P1, P2) at `t_s` of the Earth-fixed ground point.
    fn project(&self, t_s: f64) -> [f64; 2] {
        let (dr, v) = self.orbit.at(t_s);
        let r = add(self.r0, dr);
        let e = Self::orbital_frame(r, v);
        // G(t) - r(t) = (G - r0) + (Rz(omega t) - I) G - (r(t) - r0): every term formed
        // as itself, none as a difference of two positions of Earth-radius size.
        let wt = self.earth_rate_rad_s * t_s;
        let (sw, omc) = (wt.sin(), 2.0 * (0.5 * wt).sin().powi(2));
        let g = self.ground_m;
        let turn = [-omc * g[0] - sw * g[1], sw * g[0] - omc * g[1], 0.0];
        let rel: V3 = std::array::from_fn(|k| self.to_ground_m[k] + turn[k] - dr[k]);
        // L-coordinates, then B = A^T L: Rx(-roll), then Ry(-pitch), then Rz(-yaw).
        let l = [dot(e[0], rel), dot(e[1], rel), dot(e[2], rel)];
        let [roll, pitch, yaw] = self.angles(t_s);
        let c = rotate(2, -yaw, rotate(1, -pitch, rotate(0, -roll, l)));
        [-self.focal_m * c[0] / c[2], -self.focal_m * c[1] / c[2]]
    }
}

/// The image motion of the definition (`shared/EARTH-MODEL.md`) for pixel `n_px`, built
/// as the module doc says, with stencil unit `step_s`. Its error budget (rounding
/// ~1e-15 / h m/s, the relative position formed without cancellation in
/// `General::project`; truncation h^8 |P^(9)| / 630) is worked out in
/// docs/earth-model.md, "The general numerical model".
pub fn general_motion_step(
    g: &EarthGeometry<f64>,
    camera: &EarthCamera,
    n_px: f64,
    step_s: f64,
) -> Result<Numerical, Failure> {
    let (r0, v0) = (g.state.position_m, g.state.velocity_mps);
    let orbit = Kepler::new(r0, v0, GM_M3_S2).ok_or(Failure::NotElliptic)?;
    let b = g.ellipsoid.a_m * (1.0 - g.ellipsoid.flattening);
    let ground = Spheroid {
        a_m: g.ellipsoid.a_m + g.ground_h_m,
        b_m: b + g.ground_h_m,
    };
    let k = ground.a_m / ground.b_m;
    if norm([r0[0], r0[1], r0[2] * k]) <= ground.a_m {
        return Err(Failure::NotAboveGround);
    }
    let e = General::orbital_frame(r0, v0);
    let at = &g.attitude;
    let u = [camera.p1_m, n_px * camera.pixel_m, -camera.focal_m];
    let in_l = rotate(
        0,
        at.roll_rad,
        rotate(1, at.pitch_rad, rotate(2, at.yaw_rad, u)),
    );
    let d = comb(in_l[0], e[0], in_l[1], e[1], in_l[2], e[2]);
    let rho = ground.intersect_range(r0, d).ok_or(Failure::Miss)?;
    let to_ground_m = d.map(|x| rho * x);
    let model = General {
        orbit,
        r0,
        attitude: *at,
        earth_rate_rad_s: g.earth_rate_rad_s,
        focal_m: camera.focal_m,
        ground_m: add(r0, to_ground_m),
        to_ground_m,
    };
    let h = step_s;
    let mut v = [0.0; 2];
    for (j, w) in STENCIL.iter().enumerate() {
        let t = (j + 1) as f64 * h;
        let (p, m) = (model.project(t), model.project(-t));
        for i in 0..2 {
            v[i] += w * (p[i] - m[i]);
        }
    }
    Ok(Numerical {
        motion: ImageMotion {
            v1_mps: v[0] / h,
            v2_mps: v[1] / h,
        },
        ground_m: model.ground_m,
        p0_m: model.project(0.0),
    })
}

/// [`general_motion_step`] with the step [`GENERAL_STEP_S`].
pub fn general_motion(
    g: &EarthGeometry<f64>,
    camera: &EarthCamera,
    n_px: f64,
) -> Result<Numerical, Failure> {
    general_motion_step(g, camera, n_px, GENERAL_STEP_S)
}

/// The circular `orbit` at argument of latitude `u_rad` over `ellipsoid`, the camera
/// rolled by `roll_rad` and held still: the geometry of the round-Earth comparison.
pub fn circular_roll(
    orbit: &Orbit,
    u_rad: f64,
    roll_rad: f64,
    ellipsoid: Ellipsoid,
) -> EarthGeometry<f64> {
    EarthGeometry {
        state: orbit.state(u_rad),
        attitude: Attitude {
            roll_rad,
            ..Attitude::default()
        },
        ground_h_m: 0.0,
        ellipsoid,
        earth_rate_rad_s: EARTH_RATE_RAD_S,
    }
}
