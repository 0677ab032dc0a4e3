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
//! `core_math::sphere::Reference` (README, "Conventions"). The round-Earth figures of
//! `cargo xtask ellipsoid` use it on a circular orbit with roll only ([`roll_only`]).
//! Its error budget and what the tests below measure: docs/earth-model.md.

use core_math::earth::Attitude;
use core_math::sample::{eccentric_state, SplitMix64};
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
    #[cfg(test)]
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

/// One seeded draw of the general model's envelope (issue 11): WGS 84, altitude
/// 200-2000 km above the ellipsoid's geocentric radius under the satellite,
/// eccentricity 0-0.05 at any true anomaly (so any argument of perigee), inclination
/// 0-180 deg with one draw in eight each exactly equatorial, polar and retrograde
/// equatorial (and one polar draw in four exactly over a pole), roll and pitch within
/// +-45 deg, any yaw, angle rates within +-2 deg/s, ground height -500 to 9000 m,
/// focal length 0.3-1.5 m, pixel 5-20 um, p1 within +-0.05 m, field angle within
/// +-40 deg.
pub fn envelope_draw(rng: &mut SplitMix64) -> (EarthGeometry<f64>, EarthCamera, f64) {
    let camera = EarthCamera {
        focal_m: rng.uniform(0.3, 1.5),
        pixel_m: rng.uniform(5e-6, 20e-6),
        p1_m: rng.uniform(-0.05, 0.05),
    };
    let deg = f64::to_radians;
    let incl = match rng.next_u64() % 8 {
        0 => 0.0,
        1 => 90.0,
        2 => 180.0,
        _ => rng.uniform(0.0, 180.0),
    };
    let mut arg_lat = rng.uniform(0.0, 360.0);
    if incl == 90.0 && rng.next_u64().is_multiple_of(4) {
        arg_lat = if rng.next_u64().is_multiple_of(2) {
            90.0
        } else {
            270.0
        };
    }
    let (incl, arg_lat) = (deg(incl), deg(arg_lat));
    let raan = deg(rng.uniform(0.0, 360.0));
    let e = rng.uniform(0.0, 0.05);
    let nu = deg(rng.uniform(0.0, 360.0));
    let lat = (incl.sin() * arg_lat.sin()).asin();
    let r = Spheroid::WGS84.geocentric_radius_m(lat) + rng.uniform(200e3, 2000e3);
    let state = eccentric_state(r, e, nu, incl, raan, arg_lat);
    let attitude = rng.earth_attitude();
    let g = EarthGeometry {
        state,
        attitude,
        ground_h_m: rng.uniform(-500.0, 9000.0),
        ellipsoid: Ellipsoid::WGS84,
        earth_rate_rad_s: EARTH_RATE_RAD_S,
    };
    let n_px = deg(rng.uniform(-40.0, 40.0)).tan() * camera.focal_m / camera.pixel_m;
    (g, camera, n_px)
}

#[cfg(test)]
mod tests {
    use super::*;
    use core_math::earth::limb_margin_rad;
    use core_math::sample::{roll_at_limb_margin, EarthCase};
    use core_math::sphere::{Geometry, Reference};
    use core_math::{Backend, Camera, EarthReference, ModelError};

    const CAMERA: Camera = Camera {
        focal_m: 0.555,
        pixel_m: 13e-6,
    };

    /// Worst |component difference| / |v_P| (reference's |v_P|).
    fn rel_diff(a: &ImageMotion<f64>, b: &ImageMotion<f64>) -> f64 {
        let d = (a.v1_mps - b.v1_mps).abs().max((a.v2_mps - b.v2_mps).abs());
        d / b.speed_mps()
    }

    /// The general model over `ellipsoid`, camera `CAMERA`, circular orbit, roll only.
    fn circular(
        orbit: &Orbit,
        u_rad: f64,
        roll_rad: f64,
        ellipsoid: Ellipsoid,
        n: f64,
    ) -> Result<Numerical, Failure> {
        let g = circular_roll(orbit, u_rad, roll_rad, ellipsoid);
        let cam = EarthCamera {
            focal_m: CAMERA.focal_m,
            pixel_m: CAMERA.pixel_m,
            p1_m: 0.0,
        };
        general_motion(&g, &cam, n)
    }

    /// On a sphere of radius R the numerical model must reproduce the reference chain
    /// (the paper's Eqs. 1-13 on dual numbers) over a grid of roll, field angle,
    /// inclination, argument of latitude, altitude and radius, node arbitrary.
    ///
    /// Tolerance 1e-9 of |v_P| per component, the bound of the two-route test below
    /// (the numerical error budget, [`general_motion_step`], is ~1e-11 of |v|). Any
    /// modelling difference is far larger: the Earth-rotation terms are ~7 % of |v_P|
    /// (omega / Omega), the paper's doubled Eq. 14 cross term up to 1.5 %, a wrong orbit
    /// rate or radius at the 1e-3 level. The worst is printed with --nocapture
    /// (docs/earth-model.md).
    #[test]
    fn sphere_agrees_with_reference() {
        let mut worst: f64 = 0.0;
        let (mut compared, mut missed) = (0, 0);
        for &(r_m, h_m) in &[(6_371e3, 645e3), (6_370e3, 300e3), (6_371e3, 1_500e3)] {
            let sphere = Ellipsoid {
                a_m: r_m,
                flattening: 0.0,
            };
            for &i0 in &[0.0, 45.0, 97.98, 135.0, 180.0] {
                let orbit = Orbit::circular(r_m + h_m, f64::to_radians(i0), 0.7);
                for &g0 in &[0.0, 37.0, 90.0, 180.0, 251.0, 315.0] {
                    for &phi in &[-40.0, -25.0, 0.0, 10.0, 25.0, 40.0] {
                        for &n in &[-30_000.0, -12_345.0, 0.0, 20_000.0, 29_999.0] {
                            let g = Geometry::circular(
                                f64::to_radians(phi),
                                f64::to_radians(i0),
                                f64::to_radians(g0),
                                h_m,
                                r_m,
                            );
                            let num = circular(&orbit, g.arg_latitude_rad, g.roll_rad, sphere, n);
                            match (Reference.evaluate(&CAMERA, &g, n), num) {
                                (Ok(r), Ok(x)) => {
                                    let e = rel_diff(&x.motion, &r);
                                    assert!(
                                        e < 1e-9,
                                        "R {r_m} H {h_m} i0 {i0} g0 {g0} phi {phi} n {n}: \
                                         {e:e} ({:?} vs {r:?})",
                                        x.motion
                                    );
                                    // The ground point projects back onto pixel n.
                                    let pa = n * CAMERA.pixel_m;
                                    assert!(
                                        x.p0_m[0].abs() < 1e-12 && (x.p0_m[1] - pa).abs() < 1e-12
                                    );
                                    worst = worst.max(e);
                                    compared += 1;
                                }
                                (Err(ModelError::LineOfSightMissesEarth), Err(Failure::Miss)) => {
                                    missed += 1
                                }
                                (r, x) => panic!("disagree on a miss: {r:?} / {x:?}"),
                            }
                        }
                    }
                }
            }
        }
        println!(
            "numerical sphere vs Reference: {compared} cases, {missed} misses, worst {worst:.2e}"
        );
        assert!(compared > 1_000 && missed > 0);
    }

    /// The node does not matter (the spheroid is symmetric about z).
    #[test]
    fn node_is_irrelevant() {
        let at = |raan: f64| {
            let orbit = Orbit::circular(7_016e3, 97.98f64.to_radians(), raan);
            circular(&orbit, 1.1, 0.3, Ellipsoid::WGS84, 25_000.0)
                .unwrap()
                .motion
        };
        let (a, b) = (at(0.0), at(2.5));
        assert!(rel_diff(&a, &b) < 1e-11, "{a:?} {b:?}");
    }

    /// The spheroid's ground point is on its surface, and the image motion over WGS 84
    /// is the reference's over the round Earth through that very point (R = |G|,
    /// H = |S| - |G|): the motion of a point depends on where it is, not on the shape of
    /// the surface around it. This ties the ellipsoid path to the golden reference.
    #[test]
    fn ellipsoid_equals_sphere_through_the_ground_point() {
        let mut worst: f64 = 0.0;
        let orbit = Orbit::circular(7_016e3, 97.98f64.to_radians(), 0.2);
        for &g0 in &[0.0, 30.0, 80.0, 135.0, 200.0, 290.0] {
            for &phi in &[-25.0, 0.0, 25.0] {
                for &n in &[-30_000.0, 0.0, 29_999.0] {
                    let (u, roll) = (f64::to_radians(g0), f64::to_radians(phi));
                    let x = circular(&orbit, u, roll, Ellipsoid::WGS84, n).unwrap();
                    assert!(Spheroid::WGS84.residual(x.ground_m).abs() < 1e-14);
                    let r_g = norm(x.ground_m);
                    let g = Geometry {
                        roll_rad: roll,
                        inclination_rad: orbit.inclination_rad,
                        arg_latitude_rad: u,
                        altitude_m: orbit.radius_m - r_g,
                        earth_radius_m: r_g,
                        earth_rate_rad_s: EARTH_RATE_RAD_S,
                        orbit_rate_rad_s: orbit.rate_rad_s,
                    };
                    let r = Reference.evaluate(&CAMERA, &g, n).unwrap();
                    let e = rel_diff(&x.motion, &r);
                    assert!(e < 1e-9, "g0 {g0} phi {phi} n {n}: {e:e}");
                    worst = worst.max(e);
                }
            }
        }
        println!("WGS 84 vs sphere through the ground point: worst {worst:.2e}");
    }

    /// |dv| / |v|: hypot of the component differences over the reference's hypot.
    fn rel_hypot(x: &ImageMotion<f64>, r: &ImageMotion<f64>) -> f64 {
        (x.v1_mps - r.v1_mps).hypot(x.v2_mps - r.v2_mps) / r.v1_mps.hypot(r.v2_mps)
    }

    /// Limb band (rad): a line of sight closer than this to the limb is excluded from
    /// the 1e-9 bound (either may report hit or miss there).
    const LIMB_BAND_RAD: f64 = 0.5 * std::f64::consts::PI / 180.0;

    /// What one run of the two-route comparison found.
    #[derive(Debug, Default)]
    struct TwoRoute {
        /// Clear hits compared, by limb margin: 0.5-2 deg, 2-10 deg, over 10 deg.
        hits: [usize; 3],
        misses: usize,
        /// Within 0.5 deg of the limb: how many, how many of them one route calls a hit
        /// and the other a miss, and the worst difference where both hit.
        near: usize,
        near_split: usize,
        near_worst: f64,
        worst: f64,
        worst_at: String,
        /// Largest distance from (p1, p2) of the ground point's projection at t = 0 (m).
        worst_p0_m: f64,
    }

    /// The two routes over `cases` seeded draws ([`envelope_draw`], one in four moved to
    /// 0.01-5 deg of the limb, a quarter of those outside it), the numerical model with
    /// stencil unit `step_s`. Panics when the two disagree on a clear hit or miss, or a
    /// ground point does not project back onto its pixel.
    fn two_route(cases: usize, step_s: f64) -> TwoRoute {
        let mut rng = SplitMix64(0x11_EA27_0001);
        let mut o = TwoRoute::default();
        let deg = f64::to_degrees;
        for case in 0..cases {
            let (mut g, cam, n) = envelope_draw(&mut rng);
            if rng.next_u64().is_multiple_of(4) {
                let m = 10f64.powf(rng.uniform(-2.0, 5f64.log10())).to_radians();
                let m = if rng.next_u64().is_multiple_of(4) {
                    -m
                } else {
                    m
                };
                let side = if rng.next_u64().is_multiple_of(2) {
                    1.0
                } else {
                    -1.0
                };
                let case = EarthCase {
                    camera: cam,
                    geometry: g,
                    n_px: n,
                };
                if let Some(roll) = roll_at_limb_margin(&case, m, side) {
                    g.attitude.roll_rad = roll;
                }
            }
            let margin = limb_margin_rad(&g, &cam, n).unwrap();
            let r = EarthReference.evaluate(&cam, &g, n);
            let x = general_motion_step(&g, &cam, n, step_s);
            if margin.abs() < LIMB_BAND_RAD {
                o.near += 1;
                match (&r, &x) {
                    (Ok(r), Ok(x)) => o.near_worst = o.near_worst.max(rel_hypot(&x.motion, r)),
                    (Err(ModelError::LineOfSightMissesEarth), Err(Failure::Miss)) => {}
                    _ => o.near_split += 1,
                }
                continue;
            }
            if margin < 0.0 {
                assert!(
                    matches!(r, Err(ModelError::LineOfSightMissesEarth)) && x == Err(Failure::Miss),
                    "case {case}: a clear miss ({:.3} deg): {r:?} / {x:?}",
                    deg(margin)
                );
                o.misses += 1;
                continue;
            }
            let (r, x) = match (r, x) {
                (Ok(r), Ok(x)) => (r, x),
                (r, x) => panic!("case {case}: a clear hit: {r:?} / {x:?}"),
            };
            let p0 = (x.p0_m[0] - cam.p1_m).hypot(x.p0_m[1] - n * cam.pixel_m);
            assert!(p0 < 1e-12, "case {case}: projects to {:?}", x.p0_m);
            o.worst_p0_m = o.worst_p0_m.max(p0);
            let band = if deg(margin) < 2.0 {
                0
            } else if deg(margin) < 10.0 {
                1
            } else {
                2
            };
            o.hits[band] += 1;
            let e = rel_hypot(&x.motion, &r);
            if e > o.worst {
                let a = g.attitude;
                let rn = norm(g.state.position_m);
                let ecc = Kepler::new(g.state.position_m, g.state.velocity_mps, GM_M3_S2)
                    .map_or(f64::NAN, |k| k.eccentricity());
                o.worst = e;
                o.worst_at = format!(
                    "case {case}: |r| {:.0} km, e {ecc:.4}, lat {:+.1} deg, roll {:+.1} pitch \
                     {:+.1} yaw {:+.1} deg, rates {:+.2} {:+.2} {:+.2} deg/s, h {:.0} m, \
                     f {:.3} m, p1 {:+.4} m, n {n:.0} (field {:+.1} deg), limb margin \
                     {:.2} deg, |v| {:.3e} m/s (v1 {:.3e}, v2 {:.3e})",
                    rn / 1e3,
                    deg((g.state.position_m[2] / rn).asin()),
                    deg(a.roll_rad),
                    deg(a.pitch_rad),
                    deg(a.yaw_rad),
                    deg(a.roll_rate_rad_s),
                    deg(a.pitch_rate_rad_s),
                    deg(a.yaw_rate_rad_s),
                    g.ground_h_m,
                    cam.focal_m,
                    cam.p1_m,
                    deg((n * cam.pixel_m / cam.focal_m).atan()),
                    deg(margin),
                    r.speed_mps(),
                    r.v1_mps,
                    r.v2_mps,
                );
            }
        }
        o
    }

    /// The two-route test: `core_math::EarthReference` (the construction on dual
    /// numbers, the golden source) against this module's general model (Kepler
    /// propagation, nine-point finite difference), |dv| / |v| <= 1e-9 over 20 000 seeded
    /// draws of the envelope ([`envelope_draw`], a quarter of them moved near the limb). A clear
    /// miss (0.5 deg or more outside the limb, `core_math::earth::limb_margin_rad`) must
    /// be a miss for both routes, a clear hit a hit for both; within 0.5 deg of the limb
    /// the cases are counted and excluded from the bound. The ground point must project
    /// back onto (p1, p2) within 1e-12 m. What it finds (`cargo test -p xtask
    /// general_agrees -- --nocapture`): docs/earth-model.md.
    #[test]
    fn general_agrees_with_earth_reference() {
        let o = two_route(20_000, GENERAL_STEP_S);
        println!(
            "general numerical model vs EarthReference: {} hits compared (limb margin \
             0.5-2 deg {}, 2-10 deg {}, over 10 deg {}), worst |dv|/|v| {:.2e} ({}); {} \
             clear misses agreed; {} within 0.5 deg of the limb excluded ({} disagree on \
             hit/miss, worst |dv|/|v| where both hit {:.2e}); ground points project back \
             within {:.1e} m",
            o.hits.iter().sum::<usize>(),
            o.hits[0],
            o.hits[1],
            o.hits[2],
            o.worst,
            o.worst_at,
            o.misses,
            o.near,
            o.near_split,
            o.near_worst,
            o.worst_p0_m,
        );
        assert!(o.worst <= 1e-9, "{:e} at {}", o.worst, o.worst_at);
        assert!(o.hits.iter().all(|&k| k > 500) && o.misses > 500 && o.near > 100);
    }

    /// The budget's shape: the worst difference against the stencil unit h (rounding
    /// falls as 1/h, truncation rises as h^8). Run with
    /// `cargo test -p xtask general_step_sweep -- --ignored --nocapture`; the figures:
    /// docs/earth-model.md.
    #[test]
    #[ignore]
    fn general_step_sweep() {
        for h in [0.003, 0.01, 0.03, 0.1, 0.3, 1.0] {
            let o = two_route(20_000, h);
            println!(
                "h = {h} s: worst |dv|/|v| {:.2e} over {} hits",
                o.worst,
                o.hits.iter().sum::<usize>()
            );
        }
    }

    /// Geocentric radius of WGS 84 at the equator and the pole, and the intersection of
    /// a radial ray.
    #[test]
    fn spheroid_basics() {
        let w = Spheroid::WGS84;
        assert_eq!(w.geocentric_radius_m(0.0), 6_378_137.0);
        assert!(
            (w.geocentric_radius_m(std::f64::consts::FRAC_PI_2) - 6_356_752.314_245).abs() < 1e-3
        );
        let lat = 0.7f64;
        let dir = [-lat.cos(), 0.0, -lat.sin()];
        let s = [8e6 * lat.cos(), 0.0, 8e6 * lat.sin()];
        let g = add(s, scale(w.intersect_range(s, dir).unwrap(), dir));
        assert!((norm(g) - w.geocentric_radius_m(lat)).abs() < 1e-8);
        // Looking away from the Earth: no ground point.
        assert!(w.intersect_range(s, dir.map(|x| -x)).is_none());
    }
}
