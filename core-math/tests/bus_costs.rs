//! What each simplification on the bus side costs (issue 23, point 6), measured with the
//! f64 reference (`EarthReference`: `motion_of`, `motion_on_dem`, `chain`,
//! `chain_on_dem`) over realistic imaging geometries: sun-synchronous circular orbits
//! 500-800 km above the equatorial radius, roll within +-45 deg, pitch within +-30 deg,
//! yaw 0, pixels across a wide swath, WGS 84.
//!
//! Every figure is a difference of two evaluations of the same reference, one with the
//! simplification and one without: a sensitivity, not an accuracy claim. Each test
//! asserts the bound that `docs/earth-model.md` ("Part II: what each simplification on
//! the bus side costs") documents, with margin, and a floor where the effect must show.
//!
//! `cargo test --release -p core-math --test bus_costs -- --nocapture` prints them.

mod dem_tile;
use dem_tile::tile_data;

use core_math::earth::bus::{
    bus_geometry, AttitudeFrame, BusAttitude, BusState, BusTime, StateFrame, IDENTITY_QUATERNION,
};
use core_math::earth::dem::{DemGrid, DemHeight, DemTile};
use core_math::earth::frames::{self, geodetic_from_itrf, itrf_from_geodetic, Mat3, TimeScales};
use core_math::earth::kepler::Kepler;
use core_math::earth::reference::EarthRefPixel;
use core_math::earth::{limb_margin_rad, Attitude, InertialGeometry};
use core_math::sample::{eccentric_state, SplitMix64};
use core_math::vector::{cross, dot, norm};
use core_math::{
    EarthCamera, EarthGeometry, EarthReference, Ellipsoid, ImageMotion, StateVector,
    EARTH_RATE_RAD_S, GM_M3_S2,
};

/// Speed of light (m/s).
const C_MPS: f64 = 299_792_458.0;

/// The default scene's optics: f = 0.555 m, 13 um pixels, the line through the axis.
const CAMERA: EarthCamera = EarthCamera {
    focal_m: 0.555,
    pixel_m: 13e-6,
    p1_m: 0.0,
};

/// Pixels drawn across the swath: within +-12 000 of the array centre (field angle
/// within +-15.7 deg).
const SWATH_PX: f64 = 12_000.0;

/// Lines of sight closer than this to the limb are skipped (and counted).
const MIN_LIMB_MARGIN_DEG: f64 = 1.0;

fn pixel(n_px: f64) -> EarthRefPixel {
    EarthRefPixel {
        p1_m: CAMERA.p1_m,
        p2_m: n_px * CAMERA.pixel_m,
        focal_m: CAMERA.focal_m,
    }
}

/// |dv1| / |v1| (= |dT| / T of the line period) and |d drift| (rad) of `m` against `r`.
fn cost(m: &ImageMotion<f64>, r: &ImageMotion<f64>) -> (f64, f64) {
    let drift = |x: &ImageMotion<f64>| libm::atan(x.v2_mps / x.v1_mps);
    (
        (m.v1_mps - r.v1_mps).abs() / r.v1_mps.abs(),
        (drift(m) - drift(r)).abs(),
    )
}

/// The worst of a set of (period, drift) costs, with the case that gave each.
#[derive(Default)]
struct Worst {
    period: f64,
    drift: f64,
    period_at: String,
    drift_at: String,
    n: usize,
}

impl Worst {
    fn add(&mut self, (p, d): (f64, f64), at: impl Fn() -> String) {
        self.n += 1;
        if p > self.period {
            self.period = p;
            self.period_at = at();
        }
        if d > self.drift {
            self.drift = d;
            self.drift_at = at();
        }
    }

    fn print(&self, what: &str) {
        println!(
            "{what}: {} cases; period |dT|/T worst {:.2e} ({}); drift worst {:.2e} rad ({})",
            self.n, self.period, self.period_at, self.drift, self.drift_at
        );
    }
}

/// A sun-synchronous imaging instant: circular orbit 500-800 km above a, inclination
/// 97.4-98.6 deg, any node and argument of latitude, roll +-45 deg, pitch +-30 deg,
/// yaw 0, the given roll rate, ground height 0 over WGS 84.
fn sso_geometry(rng: &mut SplitMix64, roll_rate_rad_s: f64) -> EarthGeometry<f64> {
    let deg = |x: f64| x.to_radians();
    let radius = Ellipsoid::WGS84.a_m + rng.uniform(500e3, 800e3);
    let incl = deg(rng.uniform(97.4, 98.6));
    let raan = rng.uniform(0.0, core::f64::consts::TAU);
    let arg_lat = rng.uniform(0.0, core::f64::consts::TAU);
    EarthGeometry {
        state: eccentric_state(radius, 0.0, 0.0, incl, raan, arg_lat),
        attitude: Attitude {
            roll_rad: deg(rng.uniform(-45.0, 45.0)),
            pitch_rad: deg(rng.uniform(-30.0, 30.0)),
            roll_rate_rad_s,
            ..Attitude::default()
        },
        ground_h_m: 0.0,
        ellipsoid: Ellipsoid::WGS84,
        earth_rate_rad_s: EARTH_RATE_RAD_S,
    }
}

/// An SSO instant and a pixel across the swath whose line of sight lies at least
/// [`MIN_LIMB_MARGIN_DEG`] inside the limb; `None` (a skip) otherwise.
fn sso_case(rng: &mut SplitMix64, roll_rate_rad_s: f64) -> Option<(EarthGeometry<f64>, f64)> {
    let g = sso_geometry(rng, roll_rate_rad_s);
    let n = rng.uniform(-SWATH_PX, SWATH_PX);
    let margin = limb_margin_rad(&g, &CAMERA, n).ok()?;
    (margin.to_degrees() >= MIN_LIMB_MARGIN_DEG).then_some((g, n))
}

fn describe(g: &EarthGeometry<f64>, n: f64) -> String {
    let r = g.state.position_m;
    let rn = libm::sqrt(r.iter().map(|x| x * x).sum());
    format!(
        "alt {:.0} km, lat {:+.1}, roll {:+.1}, pitch {:+.1}, rate {:+.2} deg/s, n {:+.0}",
        (rn - g.ellipsoid.a_m) / 1e3,
        libm::asin(r[2] / rn).to_degrees(),
        g.attitude.roll_rad.to_degrees(),
        g.attitude.pitch_rad.to_degrees(),
        g.attitude.roll_rate_rad_s.to_degrees(),
        n
    )
}

// ---------------------------------------------------------------------------------
// Small linear algebra.

fn mat_mul(a: &Mat3, b: &Mat3) -> Mat3 {
    core::array::from_fn(|i| core::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
}

fn mat_vec(a: &Mat3, x: [f64; 3]) -> [f64; 3] {
    core::array::from_fn(|i| (0..3).map(|k| a[i][k] * x[k]).sum())
}

fn transpose(a: &Mat3) -> Mat3 {
    core::array::from_fn(|i| core::array::from_fn(|j| a[j][i]))
}

/// exp(\[w\]x t): the rotation by |w| t about w (Rodrigues).
fn rotation(w: [f64; 3], t: f64) -> Mat3 {
    let wn = norm(w);
    let mut m = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    if wn == 0.0 || t == 0.0 {
        return m;
    }
    let k = w.map(|x| x / wn);
    let (s, c) = libm::sincos(wn * t);
    let kx = [[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]];
    for i in 0..3 {
        for j in 0..3 {
            let delta = if i == j { 1.0 } else { 0.0 };
            m[i][j] = delta + s * kx[i][j] + (1.0 - c) * (k[i] * k[j] - delta);
        }
    }
    m
}

/// The geometry with every vector of I (state, camera axes) turned by `m`; the angular
/// velocity, in camera coordinates, unchanged.
fn turned(g: &InertialGeometry<f64>, m: &Mat3) -> InertialGeometry<f64> {
    let mut out = *g;
    out.state = StateVector {
        position_m: mat_vec(m, g.state.position_m),
        velocity_mps: mat_vec(m, g.state.velocity_mps),
    };
    out.attitude.camera_to_inertial = mat_mul(m, &g.attitude.camera_to_inertial);
    out
}

// ---------------------------------------------------------------------------------
// DEM tiles.

/// Nodes per side of the mirrored tile.
const MIRRORED_NODES: usize = 4_096;

/// The golden tile mirrored about its edges into 4 096 x 4 096 nodes at the same
/// spacing (455 km x 370 km from 35 N 100 E): the same heights and slopes, continuous
/// across the mirror lines, large enough for a 6 000-pixel chip's footprint and for
/// where its centre looked a second earlier.
fn mirrored_tile() -> (DemGrid, Vec<i16>) {
    let (g, h) = tile_data();
    let period_r = 2 * (g.nrows - 1);
    let period_c = 2 * (g.ncols - 1);
    let fold = |i: usize, n: usize, period: usize| {
        let p = i % period;
        if p < n {
            p
        } else {
            period - p
        }
    };
    let heights = (0..MIRRORED_NODES)
        .flat_map(|i| {
            let h = &h;
            (0..MIRRORED_NODES).map(move |j| {
                let (a, b) = (fold(i, g.nrows, period_r), fold(j, g.ncols, period_c));
                h[a * g.ncols + b] as i16
            })
        })
        .collect();
    (
        DemGrid {
            nrows: MIRRORED_NODES,
            ncols: MIRRORED_NODES,
            ..g
        },
        heights,
    )
}

/// Geodetic latitude and longitude (rad) and the DEM height there of a point of I
/// (the ITRF at the instant).
fn dem_height_at<H: DemHeight>(tile: &DemTile<'_, H>, x: [f64; 3]) -> Option<f64> {
    let (lat, lon, _) = geodetic_from_itrf(x, &Ellipsoid::WGS84).ok()?;
    tile.height_at(lat, lon)
}

/// An SSO instant whose boresight (pixel 0) looks at the point of the tile at `lat_deg`,
/// `lon_deg` (on its DEM surface) with the given roll and pitch (yaw 0) from `alt_m`
/// above a: the satellite is placed by a fixed-point iteration on the orbital frame,
/// on a circular orbit of inclination 98 deg, ascending or descending.
#[allow(clippy::too_many_arguments)]
fn aimed_geometry<H: DemHeight>(
    tile: &DemTile<'_, H>,
    lat_deg: f64,
    lon_deg: f64,
    alt_m: f64,
    roll: f64,
    pitch: f64,
    ascending: bool,
    roll_rate_rad_s: f64,
) -> EarthGeometry<f64> {
    let e = Ellipsoid::WGS84;
    let (lat, lon) = (lat_deg.to_radians(), lon_deg.to_radians());
    let h = tile.height_at(lat, lon).expect("target in the tile");
    let target = itrf_from_geodetic(lat, lon, h, &e).unwrap();
    // Heading from north (towards east) of a 98 deg orbit at this latitude.
    let sin_az = (98f64.to_radians().cos() / lat.cos()).clamp(-1.0, 1.0);
    let az = if ascending {
        libm::asin(sin_az)
    } else {
        core::f64::consts::PI - libm::asin(sin_az)
    };
    let (sp, cp) = libm::sincos(pitch);
    let (sr, cr) = libm::sincos(roll);
    let d_l = [-sp, sr * cp, -cr * cp];
    let radius = e.a_m + alt_m;
    let tn = norm(target);
    let mut r = target.map(|x| x * radius / tn);
    let mut x_l = [0.0; 3];
    for _ in 0..8 {
        let z_l = r.map(|x| x / norm(r));
        let east = {
            let e = [-z_l[1], z_l[0], 0.0];
            e.map(|x| x / norm(e))
        };
        let north = cross(z_l, east);
        x_l = core::array::from_fn(|k| az.cos() * north[k] + az.sin() * east[k]);
        let y_l = cross(z_l, x_l);
        let d: [f64; 3] =
            core::array::from_fn(|k| x_l[k] * d_l[0] + y_l[k] * d_l[1] + z_l[k] * d_l[2]);
        let td = dot(target, d);
        let s = td + libm::sqrt(td * td + radius * radius - tn * tn);
        r = core::array::from_fn(|k| target[k] - s * d[k]);
    }
    let speed = libm::sqrt(GM_M3_S2 / norm(r));
    EarthGeometry {
        state: StateVector {
            position_m: r,
            velocity_mps: x_l.map(|x| x * speed),
        },
        attitude: Attitude {
            roll_rad: roll,
            pitch_rad: pitch,
            roll_rate_rad_s,
            ..Attitude::default()
        },
        ground_h_m: 0.0,
        ellipsoid: e,
        earth_rate_rad_s: EARTH_RATE_RAD_S,
    }
}

/// A drawn aimed case: altitude 500-800 km, roll +-45 deg, pitch +-30 deg, either pass.
fn draw_aimed<H: DemHeight>(
    rng: &mut SplitMix64,
    tile: &DemTile<'_, H>,
    lat_deg: f64,
    lon_deg: f64,
    roll_rate_rad_s: f64,
) -> EarthGeometry<f64> {
    let alt = rng.uniform(500e3, 800e3);
    let roll = rng.uniform(-45.0, 45.0).to_radians();
    let pitch = rng.uniform(-30.0, 30.0).to_radians();
    let ascending = rng.next_u64() & 1 == 0;
    aimed_geometry(
        tile,
        lat_deg,
        lon_deg,
        alt,
        roll,
        pitch,
        ascending,
        roll_rate_rad_s,
    )
}

fn with_h(g: &EarthGeometry<f64>, h: f64) -> EarthGeometry<f64> {
    EarthGeometry {
        ground_h_m: h,
        ..*g
    }
}

// ---------------------------------------------------------------------------------
// 1. A J2000 (GCRF) state and attitude taken as of date.

/// GPS seconds at `year`.0 (Julian years from J2000, close enough for a draw).
fn gps_s_of_year(year: f64) -> f64 {
    (frames::time::J2000_WHOLE_DAYS_FROM_GPS_EPOCH + (year - 2000.0) * 365.25) * 86_400.0
}

#[test]
fn gcrf_taken_as_of_date() {
    let mut rng = SplitMix64(0xB05_C057_0001);
    let scales = TimeScales::DEFAULT;
    let (mut all, mut in_2026) = (Worst::default(), Worst::default());
    let mut exact = 0f64;
    let mut skipped = 0;
    let mut per_year = Vec::new();
    for year in 2000..=2050 {
        let mut w = Worst::default();
        let mut pole = 0f64;
        for _ in 0..400 {
            let Some((g, n)) = sso_case(&mut rng, 0.0) else {
                skipped += 1;
                continue;
            };
            let y = year as f64
                + if year < 2050 {
                    rng.uniform(0.0, 1.0)
                } else {
                    0.0
                };
            let gps_s = gps_s_of_year(y);
            let c2t = frames::c2t(gps_s, &scales).unwrap();
            pole = pole.max(libm::acos(c2t[2][2].min(1.0)));
            // The truth in I (the ITRF frozen at gps_s), and what the bus delivers: the
            // state and the camera's axes in the GCRF (C2T^T), a quaternion of those axes.
            let truth = g.to_inertial().unwrap();
            let t2c = transpose(&c2t);
            let b_gcrf = mat_mul(&t2c, &truth.attitude.camera_to_inertial);
            let (r_g, v_g) = (
                mat_vec(&t2c, truth.state.position_m),
                mat_vec(&t2c, truth.state.velocity_mps),
            );
            let attitude = |frame| BusAttitude {
                q: core_math::earth::bus::matrix_quaternion(&b_gcrf),
                frame,
                body_rate_rad_s: truth.attitude.omega_rad_s,
                camera_q: IDENTITY_QUATERNION,
            };
            let state = |frame| BusState {
                frame,
                position_m: r_g,
                velocity_mps: v_g,
            };
            let time = BusTime {
                gps_s: Some(gps_s),
                scales,
            };
            let geo = |s, a| {
                bus_geometry(
                    &state(s),
                    &attitude(a),
                    &time,
                    0.0,
                    Ellipsoid::WGS84,
                    EARTH_RATE_RAD_S,
                )
                .unwrap()
            };
            let right = geo(StateFrame::Gcrf, AttitudeFrame::Gcrf);
            let wrong = geo(StateFrame::Inertial, AttitudeFrame::Itrf);
            let p = pixel(n);
            let m_truth = EarthReference::motion_of(&truth, &p).unwrap();
            let m_right = EarthReference::motion_of(&right, &p).unwrap();
            let Ok(m_wrong) = EarthReference::motion_of(&wrong, &p) else {
                skipped += 1;
                continue;
            };
            exact = exact.max(cost(&m_right, &m_truth).0);
            let c = cost(&m_wrong, &m_truth);
            let at = || format!("{y:.2}, {}", describe(&g, n));
            w.add(c, at);
            all.add(c, at);
            if year == 2026 {
                in_2026.add(c, at);
            }
        }
        per_year.push((year, pole, w.period, w.drift));
    }
    println!("J2000 as of date, per year: pole of date from the GCRF pole (rad), worst |dT|/T, worst drift (rad)");
    for (year, pole, p, d) in &per_year {
        if year % 5 == 0 || *year == 2026 {
            println!("  {year}: pole {pole:.2e}, period {p:.2e}, drift {d:.2e}");
        }
    }
    in_2026.print("J2000 as of date, 2026");
    all.print("J2000 as of date, 2000-2050");
    println!("  the C2T route reproduces the truth to {exact:.1e}; {skipped} draws skipped (limb)");
    assert!(exact <= 1e-12, "bus_geometry's GCRF route: {exact:e}");
    // The effect grows with the pole's motion since J2000: tiny in 2000, at its worst by
    // 2050. Bounds as documented, with margin.
    let (_, _, p2000, _) = per_year[0];
    assert!(p2000 <= 2e-5, "2000: {p2000:e}");
    assert!(
        (1.5e-4..=3.5e-4).contains(&in_2026.period) && (1.0e-4..=3.0e-4).contains(&in_2026.drift),
        "2026: {} {}",
        in_2026.period,
        in_2026.drift
    );
    assert!(
        all.period <= 6e-4 && all.drift <= 5e-4,
        "{} {}",
        all.period,
        all.drift
    );
}

// ---------------------------------------------------------------------------------
// 2. No terrain: the DEM ground against the ellipsoid at h = 0.

#[test]
fn no_terrain() {
    let (grid, heights) = tile_data();
    let tile = DemTile::new(grid, &heights).unwrap();
    let mut rng = SplitMix64(0xB05_C057_0002);
    let mut w = Worst::default();
    let (mut skipped, mut worst_h) = (0, 0f64);
    let span = |i0: f64, d: f64, n: usize| (i0, d * (n - 1) as f64);
    let (lat0, dlat) = span(grid.lat0_deg, grid.dlat_deg, grid.nrows);
    let (lon0, dlon) = span(grid.lon0_deg, grid.dlon_deg, grid.ncols);
    for _ in 0..200 {
        let lat = lat0 + rng.uniform(0.1, 0.9) * dlat;
        let lon = lon0 + rng.uniform(0.1, 0.9) * dlon;
        let g = draw_aimed(&mut rng, &tile, lat, lon, 0.0);
        // The boresight and pixels up to 200 either side (2.8 km at nadir).
        for n in [0.0, rng.uniform(-200.0, 200.0)] {
            let p = pixel(n);
            let Ok(chain) = EarthReference::chain_on_dem(&g, &p, &tile) else {
                skipped += 1;
                continue;
            };
            // The chain's motion is motion_on_dem's (which only adds the v1 check).
            let m_dem = chain.motion;
            let m_flat = EarthReference::motion_of(&g, &p).unwrap();
            let h = dem_height_at(&tile, chain.ground_m).unwrap();
            worst_h = worst_h.max(h);
            w.add(cost(&m_flat, &m_dem), || {
                format!("{}, ground {h:.0} m", describe(&g, n))
            });
        }
    }
    w.print("no terrain (golden tile, 1 275-4 310 m, against h = 0)");
    println!("  {skipped} rays left the tile (skipped); highest ground point {worst_h:.0} m");
    assert!(skipped <= 40, "{skipped}");
    // About H / slant: 4.3 km at 500-1 100 km, more at oblique incidence.
    assert!(
        (4e-3..=1.5e-2).contains(&w.period) && w.drift <= 5e-3,
        "{} {}",
        w.period,
        w.drift
    );
}

// ---------------------------------------------------------------------------------
// 3. Per-segment heights at 1 Hz.

/// Pixels of a 6 000-pixel chip of the default scene centred on the boresight:
/// 13 samples from -3 000 to +2 999.
fn chip_samples() -> impl Iterator<Item = f64> {
    (0..13).map(|k| -3_000.0 + 5_999.0 * k as f64 / 12.0)
}

/// The geometry `tau_s` earlier, in the ITRF frozen at that earlier instant: the orbit
/// propagated back (two-body, exact), the roll back by its rate, the state turned by
/// Rz(omega tau) (I at t - tau is I at t turned by -omega tau about z).
fn earlier(g: &EarthGeometry<f64>, tau_s: f64) -> EarthGeometry<f64> {
    let kep = Kepler::new(g.state.position_m, g.state.velocity_mps, GM_M3_S2).unwrap();
    let s = kep.state_at(-tau_s);
    let rz = rotation([0.0, 0.0, g.earth_rate_rad_s], tau_s);
    let mut out = *g;
    out.state = StateVector {
        position_m: mat_vec(&rz, s.position_m),
        velocity_mps: mat_vec(&rz, s.velocity_mps),
    };
    out.attitude.roll_rad -= g.attitude.roll_rate_rad_s * tau_s;
    out
}

#[test]
fn per_segment_heights_at_1_hz() {
    let (grid, heights) = mirrored_tile();
    let tile = DemTile::new(grid, &heights).unwrap();
    let mut rng = SplitMix64(0xB05_C057_0003);
    let (lat_c, lon_c) = (grid.lat_deg(grid.nrows / 2), grid.lon_deg(grid.ncols / 2));
    let side = grid.dlat_deg * (grid.nrows - 1) as f64;
    let mut fresh = Worst::default();
    let mut stale = [Worst::default(), Worst::default()];
    let mut both = [Worst::default(), Worst::default()];
    let mut skipped = 0;
    // The largest distance (km) the chip centre's ground point moved in tau: [no slew, slew].
    let mut moved_most = [0f64; 2];
    for case in 0..120 {
        // Half the cases in a roll slew of 1-2 deg/s (either sense).
        let slew = case % 2;
        let rate = if slew == 1 {
            let r = rng.uniform(1.0, 2.0).to_radians();
            if rng.next_u64() & 1 == 0 {
                r
            } else {
                -r
            }
        } else {
            0.0
        };
        let lat = lat_c + rng.uniform(-0.1, 0.1) * side;
        let lon = lon_c + rng.uniform(-0.1, 0.1) * side;
        let g = draw_aimed(&mut rng, &tile, lat, lon, rate);
        let centre = pixel(0.0);
        let Ok(c0) = EarthReference::chain_on_dem(&g, &centre, &tile) else {
            skipped += 1;
            continue;
        };
        // The height the ground would upload for this instant: the DEM at the chip
        // centre's own ground point.
        let h_centre = dem_height_at(&tile, c0.ground_m).unwrap();
        // Where the centre looked tau earlier (the height a 1 Hz upload may still hold).
        let tau = rng.uniform(0.0, 1.0);
        let Ok(c_old) = EarthReference::chain_on_dem(&earlier(&g, tau), &centre, &tile) else {
            skipped += 1;
            continue;
        };
        let h_old = dem_height_at(&tile, c_old.ground_m).unwrap();
        let moved_km = norm(core::array::from_fn(|k| c0.ground_m[k] - c_old.ground_m[k])) / 1e3;
        moved_most[slew] = moved_most[slew].max(moved_km);
        for n in core::iter::once(0.0).chain(chip_samples()) {
            let p = pixel(n);
            let Ok(m_dem) = EarthReference::motion_on_dem(&g, &p, &tile) else {
                skipped += 1;
                continue;
            };
            let at = || {
                format!(
                    "{}, tau {tau:.2} s, moved {moved_km:.1} km, H {h_centre:.0} -> {h_old:.0} m",
                    describe(&g, n)
                )
            };
            let m_fresh = EarthReference::motion_of(&with_h(&g, h_centre), &p).unwrap();
            let m_old = EarthReference::motion_of(&with_h(&g, h_old), &p).unwrap();
            if n == 0.0 {
                // The chip centre alone: the error is the staleness only.
                stale[slew].add(cost(&m_old, &m_dem), at);
                continue;
            }
            if slew == 0 {
                fresh.add(cost(&m_fresh, &m_dem), at);
            }
            both[slew].add(cost(&m_old, &m_dem), at);
        }
    }
    fresh.print("per-segment height (chip centre's DEM height for 13 samples of a 6 000-px chip)");
    stale[0].print("stale height, up to 1 s, no slew (chip centre)");
    stale[1].print("stale height, up to 1 s, roll slew 1-2 deg/s (chip centre)");
    both[0].print("per-segment height uploaded at 1 Hz, no slew (13 samples of the chip)");
    both[1].print("per-segment height uploaded at 1 Hz, roll slew 1-2 deg/s (13 samples)");
    println!(
        "  {skipped} rays skipped (outside the mirrored tile); the chip centre's ground point \
         moved by up to {:.1} km in tau (no slew), {:.1} km (slew)",
        moved_most[0], moved_most[1]
    );
    assert!(skipped <= 60, "{skipped}");
    assert!(
        (1e-3..=1.5e-2).contains(&fresh.period),
        "fresh {}",
        fresh.period
    );
    assert!(
        (5e-4..=1.5e-2).contains(&stale[0].period) && (5e-4..=1.5e-2).contains(&stale[1].period),
        "stale {} {}",
        stale[0].period,
        stale[1].period
    );
    assert!(
        both[0].period <= 1.5e-2 && both[1].period <= 1.5e-2,
        "{} {}",
        both[0].period,
        both[1].period
    );
    assert!(
        fresh.drift <= 5e-3 && both[0].drift <= 5e-3 && both[1].drift <= 5e-3,
        "{} {} {}",
        fresh.drift,
        both[0].drift,
        both[1].drift
    );
}

// ---------------------------------------------------------------------------------
// 4. Polar motion ignored.

/// Largest polar motion (rad): xp, yp stay within about 1.5e-6 rad (0.3 arcsec).
const POLAR_MOTION_RAD: f64 = 1.5e-6;

/// The four turns of the ITRF by the largest polar motion: +- about x and about y.
fn polar_turns() -> [Mat3; 4] {
    let p = POLAR_MOTION_RAD;
    [
        rotation([p, 0.0, 0.0], 1.0),
        rotation([-p, 0.0, 0.0], 1.0),
        rotation([0.0, p, 0.0], 1.0),
        rotation([0.0, -p, 0.0], 1.0),
    ]
}

#[test]
fn polar_motion_ignored() {
    let mut rng = SplitMix64(0xB05_C057_0004);
    let turns = polar_turns();
    // Over the ellipsoid (h = 0): the state and the camera axes, as the bus delivers
    // them, turned by 1.5e-6 rad against the Earth.
    let mut flat = Worst::default();
    let mut skipped = 0;
    for _ in 0..3_000 {
        let Some((g, n)) = sso_case(&mut rng, 0.0) else {
            skipped += 1;
            continue;
        };
        let gi = g.to_inertial().unwrap();
        let p = pixel(n);
        let m = EarthReference::motion_of(&gi, &p).unwrap();
        for t in &turns {
            let mt = EarthReference::motion_of(&turned(&gi, t), &p).unwrap();
            flat.add(cost(&mt, &m), || describe(&g, n));
        }
    }
    // Over the golden tile: the same turn moves the ground point by ~10 m across
    // terrain.
    let (grid, heights) = tile_data();
    let tile = DemTile::new(grid, &heights).unwrap();
    let (mut dem, mut dem_near) = (Worst::default(), Worst::default());
    let mut moved = Vec::new();
    let (lat1, lon1) = (grid.lat_deg(grid.nrows - 1), grid.lon_deg(grid.ncols - 1));
    for _ in 0..60 {
        let lat = grid.lat0_deg + rng.uniform(0.1, 0.9) * (lat1 - grid.lat0_deg);
        let lon = grid.lon0_deg + rng.uniform(0.1, 0.9) * (lon1 - grid.lon0_deg);
        let g = draw_aimed(&mut rng, &tile, lat, lon, 0.0);
        let gi = g.to_inertial().unwrap();
        let p = pixel(0.0);
        let Ok(c) = EarthReference::chain_on_dem(&gi, &p, &tile) else {
            skipped += 1;
            continue;
        };
        let m = c.motion;
        for t in &turns {
            let gt = turned(&gi, t);
            let Ok(ct) = EarthReference::chain_on_dem(&gt, &p, &tile) else {
                skipped += 1;
                continue;
            };
            let d_m = norm(core::array::from_fn(|k| ct.ground_m[k] - c.ground_m[k]));
            moved.push(d_m);
            let mt = ct.motion;
            dem.add(cost(&mt, &m), || describe(&g, 0.0));
            if d_m <= 50.0 {
                dem_near.add(cost(&mt, &m), || describe(&g, 0.0));
            }
        }
    }
    flat.print("polar motion 1.5e-6 rad ignored, ellipsoid");
    dem.print("polar motion 1.5e-6 rad ignored, golden DEM tile");
    dem_near.print("  the same where the ground point moved by 50 m at most");
    moved.sort_by(f64::total_cmp);
    let median = moved[moved.len() / 2];
    let jumps = moved.iter().filter(|m| **m > 50.0).count();
    println!(
        "  ground point moved by {:.1} m (least), {median:.1} m (median), {:.1} m (most: {jumps} of {} \
         rays reach another slope, beyond 50 m); {skipped} skipped",
        moved[0],
        moved[moved.len() - 1],
        moved.len()
    );
    assert!(
        flat.period <= 3e-7 && flat.drift <= 3e-7,
        "{} {}",
        flat.period,
        flat.drift
    );
    assert!(flat.period >= 1e-8, "the turn must show: {}", flat.period);
    assert!((5.0..=15.0).contains(&median), "{median}");
    assert!(dem_near.period <= 1e-4, "{}", dem_near.period);
    assert!(
        dem.period <= 1.5e-3 && dem.drift <= 1e-4,
        "{} {}",
        dem.period,
        dem.drift
    );
}

// ---------------------------------------------------------------------------------
// 5. Light time and aberration.

/// The first intersection of r + s d with the ellipsoid (a + h, a + h, b + h).
fn ellipsoid_hit(e: &Ellipsoid, h: f64, r: [f64; 3], d: [f64; 3]) -> Option<[f64; 3]> {
    let (ia2, ib2) = (1.0 / (e.a_m + h).powi(2), 1.0 / (e.b_m() + h).powi(2));
    let qa = (d[0] * d[0] + d[1] * d[1]) * ia2 + d[2] * d[2] * ib2;
    let qb = 2.0 * ((r[0] * d[0] + r[1] * d[1]) * ia2 + r[2] * d[2] * ib2);
    let qc = (r[0] * r[0] + r[1] * r[1]) * ia2 + r[2] * r[2] * ib2 - 1.0;
    let disc = qb * qb - 4.0 * qa * qc;
    if !(disc >= 0.0 && qb < 0.0) {
        return None;
    }
    // The near root without cancellation: 2c / (-b + sqrt(disc)).
    let s = 2.0 * qc / (-qb + libm::sqrt(disc));
    Some(core::array::from_fn(|k| r[k] + s * d[k]))
}

/// What the camera sees of an Earth-fixed point: its image (P1, P2) at time t, the
/// point at `g0` in I at t = 0 (without light time), the satellite on its two-body
/// orbit, B(t) = B0 exp(\[Omega\]x t); with `light` the point as it was when the light
/// left it (t - |G - r| / c, iterated twice), with `aberration` its apparent direction
/// (the unit vector to it plus v / c, v the satellite's inertial velocity).
struct Seen<'a> {
    g: &'a InertialGeometry<f64>,
    kep: Kepler,
    g0: [f64; 3],
    light: bool,
    aberration: bool,
}

impl Seen<'_> {
    fn image(&self, t: f64) -> [f64; 2] {
        let s = self.kep.state_at(t);
        let (r, v) = (s.position_m, s.velocity_mps);
        let b = mat_mul(
            &self.g.attitude.camera_to_inertial,
            &rotation(self.g.attitude.omega_rad_s, t),
        );
        let w = [0.0, 0.0, self.g.earth_rate_rad_s];
        let at = |te: f64| mat_vec(&rotation(w, te), self.g0);
        let mut gt = at(t);
        if self.light {
            for _ in 0..2 {
                let tau = norm(core::array::from_fn(|k| gt[k] - r[k])) / C_MPS;
                gt = at(t - tau);
            }
        }
        let mut u: [f64; 3] = core::array::from_fn(|k| gt[k] - r[k]);
        if self.aberration {
            let un = norm(u);
            u = core::array::from_fn(|k| u[k] / un + v[k] / C_MPS);
        }
        let c = mat_vec(&transpose(&b), u);
        let f = -CAMERA.focal_m;
        [f * c[0] / c[2], f * c[1] / c[2]]
    }

    /// (v1, v2) by the fourth-order central difference, h = 0.01 s.
    fn motion(&self) -> ImageMotion<f64> {
        let h = 0.01;
        let (p1, m1, p2, m2) = (
            self.image(h),
            self.image(-h),
            self.image(2.0 * h),
            self.image(-2.0 * h),
        );
        let d = |k: usize| (8.0 * (p1[k] - m1[k]) - (p2[k] - m2[k])) / (12.0 * h);
        ImageMotion {
            v1_mps: d(0),
            v2_mps: d(1),
        }
    }
}

#[test]
fn light_time_and_aberration() {
    let mut rng = SplitMix64(0xB05_C057_0005);
    let e = Ellipsoid::WGS84;
    let (mut fd_check, mut skipped) = (0f64, 0);
    // Each figure twice: [no rates, roll slew up to 2 deg/s].
    let pair = || [Worst::default(), Worst::default()];
    let (mut earlier_w, mut light_w, mut aber_static, mut aber_w, mut both_w) =
        (pair(), pair(), pair(), pair(), pair());
    let mut tau_max = 0f64;
    for case in 0..1_500 {
        // Half the cases in a roll slew of up to 2 deg/s.
        let slew = case % 2;
        let rate = if slew == 1 {
            rng.uniform(-2.0, 2.0).to_radians()
        } else {
            0.0
        };
        let Some((g, n)) = sso_case(&mut rng, rate) else {
            skipped += 1;
            continue;
        };
        let p = pixel(n);
        let chain = EarthReference::chain(&g, &p).unwrap();
        let m_ref = chain.motion;
        let at = || describe(&g, n);
        // The brief's bound: the whole geometry r / c earlier.
        let tau = chain.slant_m / C_MPS;
        tau_max = tau_max.max(tau);
        let Ok(m_early) = EarthReference::motion_of(&earlier(&g, tau), &p) else {
            skipped += 1;
            continue;
        };
        earlier_w[slew].add(cost(&m_early, &m_ref), at);

        let gi = g.to_inertial().unwrap();
        let kep = Kepler::new(gi.state.position_m, gi.state.velocity_mps, GM_M3_S2).unwrap();
        let rz = |t: f64| rotation([0.0, 0.0, gi.earth_rate_rad_s], t);
        let plain = Seen {
            g: &gi,
            kep,
            g0: chain.ground_m,
            light: false,
            aberration: false,
        };
        let m_fd = plain.motion();
        fd_check = fd_check.max(cost(&m_fd, &m_ref).0);
        // Light time: the point whose light, sent tau earlier, arrives along the pixel's
        // line of sight (the ellipsoid is symmetric about z, so it lies where the ray
        // meets it, and at t = 0 it has turned on by omega tau).
        let lit = Seen {
            g0: mat_vec(&rz(tau), chain.ground_m),
            light: true,
            ..plain
        };
        light_w[slew].add(cost(&lit.motion(), &m_fd), at);
        // Aberration: the pixel sees the point whose apparent direction (u + v/c) lies
        // along its line of sight, i.e. the ray along d_hat - v/c.
        let d = EarthReference::line_of_sight(&gi, p.p1_m, p.p2_m, p.focal_m);
        let dn = norm(d);
        let v = gi.state.velocity_mps;
        let d_true: [f64; 3] = core::array::from_fn(|k| d[k] / dn - v[k] / C_MPS);
        let Some(g_ab) = ellipsoid_hit(&e, 0.0, gi.state.position_m, d_true) else {
            skipped += 1;
            continue;
        };
        let shifted = Seen { g0: g_ab, ..plain };
        aber_static[slew].add(cost(&shifted.motion(), &m_fd), at);
        let ab = Seen {
            aberration: true,
            ..shifted
        };
        // The apparent image of that point is the pixel's (to first order in v/c).
        let pa = ab.image(0.0);
        assert!(
            (pa[0] - p.p1_m).abs() < 1e-9 && (pa[1] - p.p2_m).abs() < 1e-9,
            "{pa:?} {p:?}"
        );
        aber_w[slew].add(cost(&ab.motion(), &m_fd), at);
        let both = Seen {
            g0: mat_vec(&rz(tau), g_ab),
            light: true,
            aberration: true,
            ..plain
        };
        both_w[slew].add(cost(&both.motion(), &m_fd), at);
    }
    println!("light time and aberration: the finite-difference model reproduces the reference to {fd_check:.1e}; light time up to {:.2} ms; {skipped} skipped", tau_max * 1e3);
    for (k, what) in ["no rates", "roll slew up to 2 deg/s"].iter().enumerate() {
        println!("{what}:");
        earlier_w[k].print("  whole geometry r/c earlier (bound)");
        light_w[k].print("  light time (the Earth's rotation during r/c)");
        aber_static[k].print("  aberration, static: the line of sight turned by v/c");
        aber_w[k].print("  aberration, apparent direction u + v/c");
        both_w[k].print("  light time and aberration together");
    }
    assert!(fd_check <= 1e-9, "{fd_check}");
    // Bounds as documented, with margin: [no rates, roll slew].
    let bounds = [
        (&earlier_w, [(2e-6, 2e-6), (2e-3, 3e-4)]),
        (&light_w, [(2e-6, 2e-6), (5e-6, 3e-6)]),
        (&aber_static, [(1.5e-4, 5e-5), (6e-4, 5e-5)]),
        (&aber_w, [(1.5e-4, 5e-5), (3e-4, 5e-5)]),
        (&both_w, [(1.5e-4, 5e-5), (3e-4, 5e-5)]),
    ];
    for (w, b) in bounds {
        for k in 0..2 {
            assert!(
                w[k].period <= b[k].0 && w[k].drift <= b[k].1,
                "{k}: {} {} against {:?}",
                w[k].period,
                w[k].drift,
                b[k]
            );
        }
    }
    assert!(
        aber_w[0].period >= 1e-5,
        "aberration must show: {}",
        aber_w[0].period
    );
}

// ---------------------------------------------------------------------------------
// 6. The geodetic-height surface against Part I's raised ellipsoid.

/// Height of the flat tile (the DEM's largest).
const FLAT_H_M: f64 = 9_000.0;

#[test]
fn geodetic_height_against_raised_ellipsoid() {
    // A flat tile at 9 000 m over latitudes -85 .. 85 deg and every longitude: on it the
    // ground is the surface of geodetic height exactly H; Part I's is (a + H, b + H).
    let grid = DemGrid {
        lat0_deg: -85.0,
        lon0_deg: -180.0,
        dlat_deg: 170.0,
        dlon_deg: 359.999,
        nrows: 2,
        ncols: 2,
    };
    let heights = [FLAT_H_M; 4];
    let tile = DemTile::new(grid, &heights).unwrap();
    let mut rng = SplitMix64(0xB05_C057_0006);
    let mut w = Worst::default();
    let (mut skipped, mut gap) = (0, 0f64);
    for _ in 0..1_500 {
        let Some((g, n)) = sso_case(&mut rng, 0.0) else {
            skipped += 1;
            continue;
        };
        let g = with_h(&g, FLAT_H_M);
        let p = pixel(n);
        let Ok(c_dem) = EarthReference::chain_on_dem(&g, &p, &tile) else {
            skipped += 1;
            continue;
        };
        let c_ell = EarthReference::chain(&g, &p).unwrap();
        gap = gap.max(norm(core::array::from_fn(|k| {
            c_dem.ground_m[k] - c_ell.ground_m[k]
        })));
        let (m_dem, m_ell) = (c_dem.motion, c_ell.motion);
        w.add(cost(&m_ell, &m_dem), || describe(&g, n));
    }
    w.print("raised ellipsoid (a + H, b + H) against geodetic height H = 9 000 m");
    println!("  ground points up to {gap:.3} m apart; {skipped} skipped (limb or beyond 85 deg)");
    assert!(gap <= 0.15, "{gap}");
    assert!(
        w.period <= 1e-7 && w.drift <= 1e-7,
        "{} {}",
        w.period,
        w.drift
    );
}
