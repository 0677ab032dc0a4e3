//! splitmix64: a seeded, dependency-free generator, so that a sample of the envelope
//! (the error report's, the tests') is the same on any machine.

use crate::earth::{Attitude, EarthCamera, EarthGeometry, Ellipsoid};
use crate::orbit::StateVector;
#[cfg(feature = "sphere")]
use crate::{model::Camera, sphere::Geometry};

pub struct SplitMix64(pub u64);

impl SplitMix64 {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [lo, hi).
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
    }
}

#[cfg(feature = "sphere")]
impl SplitMix64 {
    /// A circular-orbit geometry drawn uniformly over the envelope the error report and
    /// the tests share: roll within +/-45 deg, inclination 0-180 deg, argument of
    /// latitude 0-360 deg, altitude 200-2000 km, R = 6 371 km; rounded to f32 and
    /// widened back, so that f32, fixed point and the reference all see the same values.
    pub fn envelope_geometry(&mut self) -> Geometry<f64> {
        Geometry::circular(
            self.uniform(-45.0, 45.0).to_radians(),
            self.uniform(0.0, 180.0).to_radians(),
            self.uniform(0.0, 360.0).to_radians(),
            self.uniform(200e3, 2000e3),
            6_371e3,
        )
        .to::<f32>()
        .to_f64()
    }

    /// A pixel of `camera` for geometry `g`: three draws in four with the field angle
    /// uniform in +/-40 deg, one in four with the line of sight log-uniformly 1e-5 to
    /// 1 deg short of either limb (so that the near-limb cases are populated); `None`
    /// when that puts the field angle beyond 40 deg.
    pub fn envelope_pixel(&mut self, g: &Geometry<f64>, camera: &Camera) -> Option<f64> {
        let limb = libm::asin(g.earth_radius_m / (g.earth_radius_m + g.altitude_m));
        let alpha = if self.next_u64() & 3 == 0 {
            let margin = libm::pow(10.0, self.uniform(-5.0, 0.0)).to_radians();
            let side = if self.next_u64() & 1 == 0 { 1.0 } else { -1.0 };
            side * (limb - margin) - g.roll_rad
        } else {
            self.uniform(-40.0, 40.0).to_radians()
        };
        if alpha.abs() > 40f64.to_radians() {
            return None;
        }
        Some(libm::tan(alpha) * camera.focal_m / camera.pixel_m)
    }
}

/// One case of the real-Earth model: optics, instant and pixel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EarthCase {
    pub camera: EarthCamera,
    pub geometry: EarthGeometry<f64>,
    pub n_px: f64,
}

impl SplitMix64 {
    /// A real-Earth case drawn over the envelope of the general model (issue 11): WGS 84,
    /// altitude 200-2000 km above the equatorial radius, eccentricity 0-0.05 with any
    /// argument of latitude and true anomaly, inclination 0-180 deg (equatorial, polar,
    /// retrograde), roll and pitch within +/-45 deg, any yaw, angle rates within
    /// +/-2 deg/s, ground height -500 to 9 000 m, focal length 0.3-1.5 m, pixel 5-20 um,
    /// p1 within +/-0.05 m, field angle within +/-40 deg. One draw in four then moves the
    /// roll so that the line of sight lies log-uniformly 0.001-3 deg inside the limb (and
    /// one in twenty of those as far outside it), which populates the near-limb bands;
    /// `None` when that needs a roll beyond 45 deg.
    pub fn earth_case(&mut self) -> Option<EarthCase> {
        let camera = EarthCamera {
            focal_m: self.uniform(0.3, 1.5),
            pixel_m: self.uniform(5e-6, 20e-6),
            p1_m: self.uniform(-0.05, 0.05),
        };
        let radius_m = Ellipsoid::WGS84.a_m + self.uniform(200e3, 2000e3);
        let e = self.uniform(0.0, 0.05);
        let true_anomaly = self.uniform(0.0, core::f64::consts::TAU);
        let incl = self.uniform(0.0, core::f64::consts::PI);
        let raan = self.uniform(0.0, core::f64::consts::TAU);
        let arg_lat = self.uniform(0.0, core::f64::consts::TAU);
        let state = eccentric_state(radius_m, e, true_anomaly, incl, raan, arg_lat);
        let deg = |x: f64| x.to_radians();
        let geometry = EarthGeometry {
            state,
            attitude: self.earth_attitude(),
            ground_h_m: self.uniform(-500.0, 9000.0),
            ellipsoid: Ellipsoid::WGS84,
            earth_rate_rad_s: crate::EARTH_RATE_RAD_S,
        };
        let alpha = deg(self.uniform(-40.0, 40.0));
        let mut case = EarthCase {
            camera,
            geometry,
            n_px: libm::tan(alpha) * camera.focal_m / camera.pixel_m,
        };
        if self.next_u64() & 3 == 0 {
            let mut margin = libm::pow(10.0, self.uniform(-3.0, libm::log10(3.0))).to_radians();
            if self.next_u64().is_multiple_of(20) {
                margin = -margin;
            }
            let side = if self.next_u64() & 1 == 0 { 1.0 } else { -1.0 };
            case.geometry.attitude.roll_rad = roll_at_limb_margin(&case, margin, side)?;
        }
        Some(case)
    }
}

impl SplitMix64 {
    /// One draw of the general model's envelope (issue 11) as `cargo xtask ellipsoid` and
    /// the two-route test sample it: WGS 84, altitude 200-2000 km above the ellipsoid's
    /// geocentric radius under the satellite, eccentricity 0-0.05 at any true anomaly (so
    /// any argument of perigee), inclination 0-180 deg with one draw in eight each exactly
    /// equatorial, polar and retrograde equatorial (and one polar draw in four exactly
    /// over a pole), the attitude of [`SplitMix64::earth_attitude`], ground height -500 to
    /// 9000 m, focal length 0.3-1.5 m, pixel 5-20 um, p1 within +/-0.05 m, field angle
    /// within +/-40 deg. Unlike [`SplitMix64::earth_case`] it never moves a case toward
    /// the limb.
    pub fn envelope_case(&mut self) -> EarthCase {
        let camera = EarthCamera {
            focal_m: self.uniform(0.3, 1.5),
            pixel_m: self.uniform(5e-6, 20e-6),
            p1_m: self.uniform(-0.05, 0.05),
        };
        let deg = f64::to_radians;
        let incl = match self.next_u64() % 8 {
            0 => 0.0,
            1 => 90.0,
            2 => 180.0,
            _ => self.uniform(0.0, 180.0),
        };
        let mut arg_lat = self.uniform(0.0, 360.0);
        if incl == 90.0 && self.next_u64().is_multiple_of(4) {
            arg_lat = if self.next_u64().is_multiple_of(2) {
                90.0
            } else {
                270.0
            };
        }
        let (incl, arg_lat) = (deg(incl), deg(arg_lat));
        let raan = deg(self.uniform(0.0, 360.0));
        let e = self.uniform(0.0, 0.05);
        let nu = deg(self.uniform(0.0, 360.0));
        let lat = libm::asin(libm::sin(incl) * libm::sin(arg_lat));
        let r = Ellipsoid::WGS84.geocentric_radius_m(lat) + self.uniform(200e3, 2000e3);
        let state = eccentric_state(r, e, nu, incl, raan, arg_lat);
        let attitude = self.earth_attitude();
        let geometry = EarthGeometry {
            state,
            attitude,
            ground_h_m: self.uniform(-500.0, 9000.0),
            ellipsoid: Ellipsoid::WGS84,
            earth_rate_rad_s: crate::EARTH_RATE_RAD_S,
        };
        let n_px = libm::tan(deg(self.uniform(-40.0, 40.0))) * camera.focal_m / camera.pixel_m;
        EarthCase {
            camera,
            geometry,
            n_px,
        }
    }

    /// An attitude of the real-Earth envelope: roll and pitch within +/-45 deg, any yaw,
    /// each rate within +/-2 deg/s (drawn in that order).
    pub fn earth_attitude(&mut self) -> Attitude<f64> {
        let deg = |x: f64| x.to_radians();
        Attitude {
            roll_rad: deg(self.uniform(-45.0, 45.0)),
            pitch_rad: deg(self.uniform(-45.0, 45.0)),
            yaw_rad: deg(self.uniform(-180.0, 180.0)),
            roll_rate_rad_s: deg(self.uniform(-2.0, 2.0)),
            pitch_rate_rad_s: deg(self.uniform(-2.0, 2.0)),
            yaw_rate_rad_s: deg(self.uniform(-2.0, 2.0)),
        }
    }
}

/// The roll, between 0 and `side` x 45 deg, at which the case's line of sight lies
/// `margin_rad` inside the limb (negative: outside), by bisection on
/// [`crate::earth::limb_margin_rad`]; `None` if no such roll is bracketed.
pub fn roll_at_limb_margin(case: &EarthCase, margin_rad: f64, side: f64) -> Option<f64> {
    let at = |roll: f64| {
        let mut g = case.geometry;
        g.attitude.roll_rad = roll;
        crate::earth::limb_margin_rad(&g, &case.camera, case.n_px).ok()
    };
    let (mut lo, mut hi) = (0.0, side * 45f64.to_radians());
    if !(at(lo)? > margin_rad && at(hi)? < margin_rad) {
        return None;
    }
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if at(mid)? > margin_rad {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Some(0.5 * (lo + hi))
}

/// The inertial state at radius `radius_m` on a two-body orbit of eccentricity `e` at
/// true anomaly `true_anomaly_rad`, inclination, node and argument of latitude as named
/// (the perigee is wherever the true anomaly puts it).
pub fn eccentric_state(
    radius_m: f64,
    e: f64,
    true_anomaly_rad: f64,
    inclination_rad: f64,
    raan_rad: f64,
    arg_latitude_rad: f64,
) -> StateVector {
    let gm = crate::GM_M3_S2;
    let (sn, cn) = libm::sincos(true_anomaly_rad);
    // r = p / (1 + e cos nu): the semi-latus rectum p and the angular momentum sqrt(GM p).
    let h = libm::sqrt(gm * radius_m * (1.0 + e * cn));
    let v_radial = gm / h * e * sn;
    let v_transverse = h / radius_m;
    let (si, ci) = libm::sincos(inclination_rad);
    let (so, co) = libm::sincos(raan_rad);
    let p = [co, so, 0.0];
    let q = [-so * ci, co * ci, si];
    let (su, cu) = libm::sincos(arg_latitude_rad);
    let up: [f64; 3] = core::array::from_fn(|k| cu * p[k] + su * q[k]);
    let fwd: [f64; 3] = core::array::from_fn(|k| -su * p[k] + cu * q[k]);
    StateVector {
        position_m: up.map(|x| x * radius_m),
        velocity_mps: core::array::from_fn(|k| v_radial * up[k] + v_transverse * fwd[k]),
    }
}
