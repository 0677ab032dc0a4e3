//! The ground from a DEM tile (Part II of `shared/EARTH-MODEL.md`): the tile's checks,
//! the search for the first crossing, and the image motion at the ground point it finds,
//! on every backend.
//!
//! - The independent goldens of `tools/goldens/dem_crossing.py` (`tests/data/dem_tile.csv`,
//!   `tests/data/dem_cases.csv`: ERFA's geodetic conversion, brute-force sampling every
//!   0.2 m and bisection, mpmath's motion): the outcome, the ground point and (v1, v2) of
//!   the reference, the general f64 and the general f32 forms;
//! - the same search against a dense scan in this file over five hundred seeded rays
//!   (steep, oblique, grazing, from outside the tile);
//! - the bound that lets the search skip the sky: a point of the ellipsoid raised by H
//!   has geodetic height within 2e-6 |H| of H;
//! - the tile's refusals.
//!
//! `cargo test --release -p core-math --test dem -- --nocapture` prints the measured
//! maxima quoted in `docs/earth-model.md`.

mod dem_tile;
use dem_tile::tile_data;

use core_math::earth::bus::{
    bus_geometry, dps_to_rad_s, AttitudeFrame, BusAttitude, BusState, BusTime, StateFrame,
};
use core_math::earth::dem::{DemGrid, DemTile, MAX_DEM_HEIGHT_M, MIN_DEM_HEIGHT_M};
use core_math::earth::frames::{geodetic_from_itrf, itrf_from_geodetic, TimeScales};
use core_math::earth::reference::EarthRefPixel;
use core_math::earth::InertialGeometry;
use core_math::sample::SplitMix64;
use core_math::{Backend, Earth};
use core_math::{
    EarthCamera, EarthReference, Ellipsoid, ImageMotion, ModelError, Param, GENERAL_F32,
    GENERAL_F64,
};

const CASES_CSV: &str = include_str!("data/dem_cases.csv");

/// Golden tolerances: the ground point (m, f64 backends), the motion relative to |v|
/// (f64 backends; f32 with a DEM, the contract's 5e-6), and the f32 ground point (m; its
/// search stops within 0.5 m of the surface, and the geodetic height carries 0.6 m of
/// rounding).
const GROUND_F64_M: f64 = 0.01;
const MOTION_F64_REL: f64 = 1.0e-9;
const MOTION_F32_REL: f64 = 5.0e-6;
const GROUND_F32_M: f64 = 10.0;

struct Case {
    case: u32,
    kind: String,
    geometry: InertialGeometry<f64>,
    camera: EarthCamera,
    n_px: f64,
    error: String,
    ground_m: [f64; 3],
    motion: ImageMotion<f64>,
}

fn cases() -> Vec<Case> {
    let mut lines = CASES_CSV.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    lines
        .map(|line| {
            let fields: Vec<&str> = line.split(',').collect();
            let s = |name: &str| fields[head.iter().position(|h| *h == name).expect(name)];
            let f = |name: &str| s(name).parse::<f64>().unwrap_or(f64::NAN);
            let v3 = |a: &str, b: &str, c: &str| [f(a), f(b), f(c)];
            assert_eq!((s("frame"), s("attitude_frame")), ("itrf", "itrf"));
            let ellipsoid = Ellipsoid {
                a_m: f("a_m"),
                flattening: f("flattening"),
            };
            let geometry = bus_geometry(
                &BusState {
                    frame: StateFrame::Itrf,
                    position_m: v3("x_m", "y_m", "z_m"),
                    velocity_mps: v3("vx_mps", "vy_mps", "vz_mps"),
                },
                &BusAttitude {
                    q: [f("qw"), f("qx"), f("qy"), f("qz")],
                    frame: AttitudeFrame::Itrf,
                    body_rate_rad_s: dps_to_rad_s(v3("wx_dps", "wy_dps", "wz_dps")),
                    camera_q: [f("cam_qw"), f("cam_qx"), f("cam_qy"), f("cam_qz")],
                },
                &BusTime {
                    gps_s: Some(f("gps_s")),
                    scales: TimeScales {
                        gps_utc_s: f("gps_utc_s"),
                        dut1_s: f("dut1_s"),
                    },
                },
                0.0,
                ellipsoid,
                f("earth_rate_rad_s"),
            )
            .unwrap();
            Case {
                case: f("case") as u32,
                kind: s("kind").to_string(),
                geometry,
                camera: EarthCamera {
                    focal_m: f("f_m"),
                    pixel_m: f("pixel_m"),
                    p1_m: f("p1_m"),
                },
                n_px: f("n_px"),
                error: s("error").to_string(),
                ground_m: v3("ground_x_m", "ground_y_m", "ground_z_m"),
                motion: ImageMotion {
                    v1_mps: f("v1_mps"),
                    v2_mps: f("v2_mps"),
                },
            }
        })
        .collect()
}

fn rel(m: &ImageMotion<f64>, r: &ImageMotion<f64>) -> f64 {
    libm::hypot(m.v1_mps - r.v1_mps, m.v2_mps - r.v2_mps) / libm::hypot(r.v1_mps, r.v2_mps)
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    libm::sqrt((0..3).map(|i| (a[i] - b[i]) * (a[i] - b[i])).sum())
}

fn outcome<T>(r: &Result<T, ModelError>) -> &'static str {
    match r {
        Ok(_) => "",
        Err(e) => e.name(),
    }
}

/// The three backends on one golden case: (outcome, ground point, motion) each.
type Found = (&'static str, Option<[f64; 3]>, Option<ImageMotion<f64>>);

fn backends(c: &Case, tile: &DemTile<'_, f64>) -> [Found; 3] {
    let g = &c.geometry;
    let r = g.state.position_m;
    let (p1_m, p2_m) = c.camera.focal_plane_m(c.n_px).unwrap();
    let px = EarthRefPixel {
        p1_m,
        p2_m,
        focal_m: c.camera.focal_m,
    };
    let reference = EarthReference::chain_on_dem(g, &px, tile);
    let reference: Found = (
        outcome(&reference),
        reference.as_ref().ok().map(|ch| ch.ground_m),
        reference.as_ref().ok().map(|ch| ch.motion),
    );
    let general_f64: Found = {
        let up = GENERAL_F64.update_inertial(g).unwrap();
        let pix = <_ as Backend<Earth>>::pixel(&GENERAL_F64, &c.camera, c.n_px).unwrap();
        let inv_s = GENERAL_F64.dem_inv_range(g, &pix, tile);
        match inv_s {
            Err(e) => (e.name(), None, None),
            Ok(inv_s) => {
                let m = &g.attitude.camera_to_inertial;
                let d: [f64; 3] =
                    core::array::from_fn(|i| (0..3).map(|j| m[i][j] * pix.u_m[j]).sum());
                let ground = core::array::from_fn(|i| r[i] + d[i] / inv_s);
                let motion = GENERAL_F64.motion_at_inv_range(&up, &pix, inv_s).unwrap();
                ("", Some(ground), Some(motion))
            }
        }
    };
    let general_f32: Found = {
        let g32 = g.to::<f32>();
        let up = GENERAL_F32.update_inertial(&g32).unwrap();
        let pix = <_ as Backend<Earth>>::pixel(&GENERAL_F32, &c.camera, c.n_px).unwrap();
        match GENERAL_F32.dem_inv_range(&g32, &pix, tile) {
            Err(e) => (e.name(), None, None),
            Ok(inv_s) => {
                let m = &g32.attitude.camera_to_inertial;
                let d: [f64; 3] =
                    core::array::from_fn(|i| (0..3).map(|j| (m[i][j] * pix.u_m[j]) as f64).sum());
                let s = 1.0 / inv_s as f64;
                let ground = core::array::from_fn(|i| r[i] + d[i] * s);
                let m = GENERAL_F32.motion_at_inv_range(&up, &pix, inv_s).unwrap();
                let motion = ImageMotion {
                    v1_mps: m.v1_mps as f64,
                    v2_mps: m.v2_mps as f64,
                };
                ("", Some(ground), Some(motion))
            }
        }
    };
    [reference, general_f64, general_f32]
}

/// Every golden case on every backend: the same outcome, the ground point within
/// 0.01 m (f64) or 5 m (f32), the motion within 1e-9 (f64) or 5e-6 (f32).
#[test]
fn backends_match_the_independent_goldens() {
    let (grid, heights) = tile_data();
    let tile = DemTile::new(grid, &heights).unwrap();
    let cases = cases();
    assert!(cases.len() >= 50);
    let mut worst = [(0f64, 0f64); 3];
    let mut hits = 0;
    for c in &cases {
        for (k, (name, ground, motion)) in backends(c, &tile).into_iter().enumerate() {
            assert_eq!(name, c.error, "case {} ({}) backend {k}", c.case, c.kind);
            let (Some(ground), Some(motion)) = (ground, motion) else {
                continue;
            };
            let (dg, dm) = (dist(ground, c.ground_m), rel(&motion, &c.motion));
            let (g_tol, m_tol) = if k < 2 {
                (GROUND_F64_M, MOTION_F64_REL)
            } else {
                (GROUND_F32_M, MOTION_F32_REL)
            };
            assert!(
                dg <= g_tol && dm <= m_tol,
                "case {} ({}) backend {k}: ground off by {dg:.3e} m, motion by {dm:.3e}",
                c.case,
                c.kind
            );
            worst[k] = (worst[k].0.max(dg), worst[k].1.max(dm));
            hits += usize::from(k == 0);
        }
    }
    assert!(hits >= 40, "{hits} hits");
    for (k, name) in ["reference", "general f64", "general f32"]
        .iter()
        .enumerate()
    {
        println!(
            "dem goldens, {name}: {hits} hits of {}; ground point within {:.2e} m, motion within {:.2e}",
            cases.len(),
            worst[k].0,
            worst[k].1
        );
    }
}

/// The grazing cases do what they were built for: 3 m over the ridge's crest the line
/// of sight goes on to the slopes behind it, 3 m under it stops on the ridge.
#[test]
fn grazing_rays_pass_over_or_stop_at_the_ridge() {
    let (grid, heights) = tile_data();
    let tile = DemTile::new(grid, &heights).unwrap();
    // The ridge is the highest row of the tile's middle: rows 90-91 (dem_crossing.py).
    let ridge_lat_deg = grid.lat_deg(90);
    let mut seen = (0, 0);
    for c in cases() {
        let over = c.kind == "grazing_over";
        if !(over || c.kind == "grazing_clip") {
            continue;
        }
        let [(_, Some(ground), _), _, _] = backends(&c, &tile) else {
            panic!("case {} found no ground", c.case)
        };
        let (lat, _, _) = geodetic_from_itrf(ground, &c.geometry.ellipsoid).unwrap();
        let from_ridge_deg = lat.to_degrees() - ridge_lat_deg;
        if over {
            assert!(
                from_ridge_deg < -grid.dlat_deg,
                "case {}: {from_ridge_deg}",
                c.case
            );
            seen.0 += 1;
        } else {
            assert!(
                from_ridge_deg.abs() < 0.5 * grid.dlat_deg,
                "case {}: {from_ridge_deg}",
                c.case
            );
            seen.1 += 1;
        }
    }
    assert!(seen.0 >= 2 && seen.1 >= 2, "{seen:?}");
}

/// The first passage from above to on or below the surface inside the box, by scanning
/// f = h - H every `step_m` of path and bisecting: the search's definition, evaluated
/// without its Lipschitz steps. `None` where the scan finds no passage.
fn scan(
    tile: &DemTile<'_, f64>,
    e: &Ellipsoid,
    r: [f64; 3],
    d: [f64; 3],
    step_m: f64,
) -> Option<f64> {
    let dn = libm::sqrt(d.iter().map(|x| x * x).sum());
    let f = |s: f64| -> Option<f64> {
        let x = core::array::from_fn(|i| r[i] + s * d[i]);
        let (lat, lon, h) = geodetic_from_itrf(x, e).ok()?;
        tile.height_at(lat, lon).map(|hh| h - hh)
    };
    // From 12 km above the ellipsoid along the ray to 2 km below it.
    let range = |h: f64| -> Option<(f64, f64)> {
        let (a, b) = (e.a_m + h, e.b_m() + h);
        let qa = (d[0] * d[0] + d[1] * d[1]) / (a * a) + d[2] * d[2] / (b * b);
        let qb = (r[0] * d[0] + r[1] * d[1]) / (a * a) + r[2] * d[2] / (b * b);
        let qc = (r[0] * r[0] + r[1] * r[1]) / (a * a) + r[2] * r[2] / (b * b) - 1.0;
        let disc = qb * qb - qa * qc;
        (disc >= 0.0).then(|| ((-qb - disc.sqrt()) / qa, (-qb + disc.sqrt()) / qa))
    };
    let (s0, top_out) = range(12_000.0)?;
    let s1 = range(-2_000.0).map_or(top_out, |(near, _)| near);
    let n = ((s1 - s0) * dn / step_m) as usize + 2;
    let mut prev: Option<(f64, f64)> = None;
    for k in 0..n {
        let s = s0 + (s1 - s0) * k as f64 / (n - 1) as f64;
        let fs = f(s);
        if let (Some((sp, fp)), Some(fs)) = (prev, fs) {
            if fp > 0.0 && fs <= 0.0 {
                let (mut lo, mut hi) = (sp, s);
                while (hi - lo) * dn > 1e-6 {
                    let mid = 0.5 * (lo + hi);
                    match f(mid) {
                        Some(fm) if fm > 0.0 => lo = mid,
                        _ => hi = mid,
                    }
                }
                return Some(hi);
            }
        }
        prev = fs.map(|fs| (s, fs));
    }
    None
}

/// Five hundred seeded rays at the golden tile from 400-800 km up, at incidences from
/// nadir to 80 degrees and any azimuth, aimed at points in and around the tile: the
/// search finds the scan's crossing (within 0.01 m) or, where the scan finds none,
/// refuses; where the scan's 0.5 m step could have missed a passage the two may differ
/// only if the search's point lies within its tolerance of the surface.
#[test]
fn search_agrees_with_a_dense_scan() {
    let (grid, heights) = tile_data();
    let tile = DemTile::new(grid, &heights).unwrap();
    let e = Ellipsoid::WGS84;
    let mut rng = SplitMix64(0xDE3_2026_1126);
    let (mut hits, mut worst_m, mut refused) = (0, 0f64, 0);
    let lat1 = grid.lat_deg(grid.nrows - 1);
    let lon1 = grid.lon_deg(grid.ncols - 1);
    for i in 0..500 {
        let tlat = grid.lat0_deg + rng.uniform(-0.05, 1.05) * (lat1 - grid.lat0_deg);
        let tlon = grid.lon0_deg + rng.uniform(-0.05, 1.05) * (lon1 - grid.lon0_deg);
        let th = rng.uniform(1_000.0, 7_500.0);
        let target = itrf_from_geodetic(tlat.to_radians(), tlon.to_radians(), th, &e).unwrap();
        let alt = rng.uniform(400e3, 800e3);
        // Satellite: up from the target by alt, then off along a random horizontal
        // direction by alt tan(incidence).
        let up = {
            let (la, lo) = (tlat.to_radians(), tlon.to_radians());
            [la.cos() * lo.cos(), la.cos() * lo.sin(), la.sin()]
        };
        let az = rng.uniform(0.0, core::f64::consts::TAU);
        let east = [-up[1], up[0], 0.0];
        let en = libm::sqrt(east[0] * east[0] + east[1] * east[1]);
        let east = east.map(|x| x / en);
        let north = [
            up[1] * east[2] - up[2] * east[1],
            up[2] * east[0] - up[0] * east[2],
            up[0] * east[1] - up[1] * east[0],
        ];
        let inc = rng.uniform(0.0, 80f64.to_radians());
        let off = alt * inc.tan();
        let r: [f64; 3] = core::array::from_fn(|k| {
            target[k] + alt * up[k] + off * (az.cos() * north[k] + az.sin() * east[k])
        });
        let d: [f64; 3] = core::array::from_fn(|k| target[k] - r[k]);
        let found = tile.first_crossing(&e, r, d);
        let scanned = scan(&tile, &e, r, d, 0.5);
        match (found, scanned) {
            (Ok(s), Some(s_scan)) => {
                let dn = libm::sqrt(d.iter().map(|x| x * x).sum());
                let off_m = (s - s_scan).abs() * dn;
                assert!(
                    off_m <= 0.01,
                    "ray {i}: search {s}, scan {s_scan}, {off_m:.3e} m"
                );
                worst_m = worst_m.max(off_m);
                hits += 1;
            }
            (Err(err), None) => {
                assert!(
                    matches!(
                        err,
                        ModelError::OutsideDem | ModelError::LineOfSightMissesEarth
                    ),
                    "ray {i}: {err:?}"
                );
                refused += 1;
            }
            (Ok(s), None) => {
                // The scan stepped over a passage the search saw: it must lie on the
                // surface within the search's tolerance.
                let x = core::array::from_fn(|k| r[k] + s * d[k]);
                let (lat, lon, h) = geodetic_from_itrf(x, &e).unwrap();
                let f = h - tile.height_at(lat, lon).unwrap();
                assert!(
                    f.abs() <= 1e-3,
                    "ray {i}: search found a point {f} m off the surface"
                );
            }
            (Err(err), Some(s_scan)) => panic!("ray {i}: search {err:?}, scan found {s_scan}"),
        }
    }
    assert!(
        hits >= 250 && refused >= 50,
        "{hits} hits, {refused} refused"
    );
    println!("dem scan: {hits} hits within {worst_m:.2e} m of the scan; {refused} refused alike");
}

/// A point of the ellipsoid raised by H (semi-axes a + H, b + H) has geodetic height
/// within 2e-6 |H| of H, over every latitude and the heights a tile may hold, with
/// margin: the bound that lets the search skip the sky and the deep in closed form.
#[test]
fn raised_ellipsoid_is_within_2e6_of_the_geodetic_height() {
    let e = Ellipsoid::WGS84;
    let mut worst = 0f64;
    for h in [
        MIN_DEM_HEIGHT_M - 1.0,
        -1.0,
        0.0,
        1.0,
        4_500.0,
        MAX_DEM_HEIGHT_M + 1.0,
        20_000.0,
    ] {
        let (a, b) = (e.a_m + h, e.b_m() + h);
        for k in 0..=20_000 {
            let t = core::f64::consts::FRAC_PI_2 * k as f64 / 20_000.0;
            let x = [a * t.cos(), 0.0, b * t.sin()];
            let (_, _, hg) = geodetic_from_itrf(x, &e).unwrap();
            let off = (hg - h).abs();
            assert!(off <= 2e-6 * h.abs() + 1e-8, "H {h}: {off}");
            if h != 0.0 {
                worst = worst.max(off / h.abs());
            }
        }
    }
    println!("raised ellipsoid: geodetic height within {worst:.2e} |H| of H");
}

#[test]
fn tile_refusals() {
    let grid = DemGrid {
        lat0_deg: 10.0,
        lon0_deg: 20.0,
        dlat_deg: 0.01,
        dlon_deg: 0.01,
        nrows: 3,
        ncols: 4,
    };
    let flat = [100.0f64; 12];
    assert!(DemTile::new(grid, &flat).is_ok());
    let check = |g: DemGrid, h: &[f64], want: ModelError| {
        assert_eq!(DemTile::new(g, h).err(), Some(want), "{g:?}");
    };
    let bad_grid = ModelError::InvalidInput(Param::DemGrid);
    check(DemGrid { nrows: 1, ..grid }, &flat[..4], bad_grid);
    check(grid, &flat[..11], bad_grid);
    check(
        DemGrid {
            dlat_deg: 0.0,
            ..grid
        },
        &flat,
        bad_grid,
    );
    check(
        DemGrid {
            dlon_deg: -0.01,
            ..grid
        },
        &flat,
        bad_grid,
    );
    check(
        DemGrid {
            lat0_deg: f64::NAN,
            ..grid
        },
        &flat,
        ModelError::NonFinite(Param::DemGrid),
    );
    let domain = ModelError::OutOfDomain(Param::DemGrid);
    // Across the antimeridian, reaching a pole, starting west of -180.
    check(
        DemGrid {
            lon0_deg: 179.98,
            ..grid
        },
        &flat,
        domain,
    );
    check(
        DemGrid {
            lat0_deg: 87.99,
            ..grid
        },
        &flat,
        domain,
    );
    check(
        DemGrid {
            lon0_deg: -180.5,
            ..grid
        },
        &flat,
        domain,
    );
    let mut h = flat;
    h[5] = f64::INFINITY;
    check(grid, &h, ModelError::NonFinite(Param::DemHeight));
    h[5] = MAX_DEM_HEIGHT_M + 1.0;
    check(grid, &h, ModelError::OutOfDomain(Param::DemHeight));
    h[5] = MIN_DEM_HEIGHT_M - 1.0;
    check(grid, &h, ModelError::OutOfDomain(Param::DemHeight));
    // int16 nodes, as the protocol uploads them.
    let nodes = [100i16; 12];
    assert_eq!(
        DemTile::new(grid, &nodes).unwrap().height_range_m(),
        (100.0, 100.0)
    );
}

/// A tile made from known bounds (`DemTile::with_bounds`, what a controller that
/// checked each node as it arrived does) is the tile `DemTile::new` makes: the same
/// bounds, the same heights, the same crossings; its refusals are the grid's and the
/// bounds' range.
#[test]
fn a_tile_from_its_bounds_is_the_same_tile() {
    let grid = DemGrid {
        lat0_deg: 10.0,
        lon0_deg: 20.0,
        dlat_deg: 0.01,
        dlon_deg: 0.02,
        nrows: 3,
        ncols: 4,
    };
    // Steps by hand: along a column at most |1500 - 20| = 1480, along a row at most
    // |-200 - 1500| = 1700.
    let nodes: [i16; 12] = [0, 10, 20, 30, 700, -200, 1500, 30, 0, 10, 20, 30];
    let tile = DemTile::new(grid, &nodes).unwrap();
    let b = tile.bounds();
    assert_eq!((b.min_m, b.max_m), (-200.0, 1500.0));
    assert!((b.step_lat_m - 1480.0).abs() < 1e-9, "{b:?}");
    assert!((b.step_lon_m - 1700.0).abs() < 1e-9, "{b:?}");
    let again = DemTile::with_bounds(grid, &nodes, b).unwrap();
    assert_eq!(again.bounds(), b);
    for (lat, lon) in [(10.005, 20.01), (10.013, 20.05), (10.02, 20.06)] {
        let (lat, lon) = (f64::to_radians(lat), f64::to_radians(lon));
        assert_eq!(again.height_at(lat, lon), tile.height_at(lat, lon));
    }
    let bad =
        |g: DemGrid, b: core_math::earth::dem::DemBounds| DemTile::with_bounds(g, &nodes, b).err();
    assert_eq!(
        bad(
            DemGrid {
                lon0_deg: 179.99,
                ..grid
            },
            b
        ),
        Some(ModelError::OutOfDomain(Param::DemGrid))
    );
    assert_eq!(
        bad(DemGrid { ncols: 3, ..grid }, b),
        Some(ModelError::InvalidInput(Param::DemGrid))
    );
    assert_eq!(
        bad(
            grid,
            core_math::earth::dem::DemBounds { max_m: 9001.0, ..b }
        ),
        Some(ModelError::OutOfDomain(Param::DemHeight))
    );
    assert_eq!(
        bad(
            grid,
            core_math::earth::dem::DemBounds {
                step_lat_m: -1.0,
                ..b
            }
        ),
        Some(ModelError::InvalidInput(Param::DemGrid))
    );
}

/// The search's cost on the golden rays, in points of the ray evaluated (each a
/// geodetic conversion and, inside the tile, a bilinear height): printed for
/// `docs/earth-model.md`, and bounded so that a change that slows it shows.
#[test]
fn search_cost_on_the_golden_rays() {
    let (grid, heights) = tile_data();
    let tile = DemTile::new(grid, &heights).unwrap();
    let (mut n, mut sum, mut max) = (0u32, [0u32; 2], [0u32; 2]);
    for c in cases().iter().filter(|c| c.error.is_empty()) {
        let g = &c.geometry;
        let pix = <_ as Backend<Earth>>::pixel(&GENERAL_F64, &c.camera, c.n_px).unwrap();
        let m = &g.attitude.camera_to_inertial;
        let d: [f64; 3] = core::array::from_fn(|i| (0..3).map(|j| m[i][j] * pix.u_m[j]).sum());
        let r = g.state.position_m;
        let (found, s64) = tile.first_crossing_counted(&g.ellipsoid, r, d);
        assert!(found.is_ok());
        let (found, s32) =
            tile.first_crossing_counted(&g.ellipsoid, r.map(|x| x as f32), d.map(|x| x as f32));
        assert!(found.is_ok());
        for (k, s) in [s64, s32].into_iter().enumerate() {
            sum[k] += s;
            max[k] = max[k].max(s);
        }
        n += 1;
    }
    println!(
        "dem search cost over {n} golden hits: f64 mean {:.0}, max {} points; f32 mean {:.0}, max {}",
        sum[0] as f64 / n as f64,
        max[0],
        sum[1] as f64 / n as f64,
        max[1]
    );
    assert!(max[0] <= 5_000 && max[1] <= 5_000, "{max:?}");
}

/// A smooth tile of 128 x 128 nodes at 0.005 deg (555 m x 455 m cells) at 35 N 100 E:
/// rolling relief 1 300..3 700 m, slopes up to about 0.3, as a 15 arc-second DEM of
/// mountains shows them.
fn smooth_tile() -> (DemGrid, Vec<f64>) {
    let grid = DemGrid {
        lat0_deg: 35.0,
        lon0_deg: 100.0,
        dlat_deg: 0.005,
        dlon_deg: 0.005,
        nrows: 128,
        ncols: 128,
    };
    let tau = core::f64::consts::TAU;
    let heights = (0..128 * 128)
        .map(|k| {
            let (i, j) = ((k / 128) as f64, (k % 128) as f64);
            (2_500.0
                + 900.0 * (tau * i / 128.0).sin() * (tau * j / 100.0).cos()
                + 300.0 * (tau * (i + j) / 60.0).sin())
            .round()
        })
        .collect();
    (grid, heights)
}

/// A seeded ray from `alt` above a point of the tile at `inc` from its vertical.
fn ray_at(
    grid: &DemGrid,
    rng: &mut SplitMix64,
    inc_max_rad: f64,
    inner: f64,
) -> ([f64; 3], [f64; 3]) {
    let e = Ellipsoid::WGS84;
    let lat1 = grid.lat_deg(grid.nrows - 1);
    let lon1 = grid.lon_deg(grid.ncols - 1);
    let tlat = grid.lat0_deg + rng.uniform(inner, 1.0 - inner) * (lat1 - grid.lat0_deg);
    let tlon = grid.lon0_deg + rng.uniform(inner, 1.0 - inner) * (lon1 - grid.lon0_deg);
    let target = itrf_from_geodetic(tlat.to_radians(), tlon.to_radians(), 2_500.0, &e).unwrap();
    let (la, lo) = (tlat.to_radians(), tlon.to_radians());
    let up = [la.cos() * lo.cos(), la.cos() * lo.sin(), la.sin()];
    let east = [-lo.sin(), lo.cos(), 0.0];
    let north = [
        up[1] * east[2] - up[2] * east[1],
        up[2] * east[0] - up[0] * east[2],
        up[0] * east[1] - up[1] * east[0],
    ];
    let alt = rng.uniform(500e3, 800e3);
    let az = rng.uniform(0.0, core::f64::consts::TAU);
    let off = alt * rng.uniform(0.0, inc_max_rad).tan();
    let r: [f64; 3] = core::array::from_fn(|k| {
        target[k] + alt * up[k] + off * (az.cos() * north[k] + az.sin() * east[k])
    });
    (r, core::array::from_fn(|k| target[k] - r[k]))
}

/// The height search against the march on a smooth tile, rays up to 40 deg from the
/// vertical well inside the tile: the same ground point (f64 within its certified
/// bound and 0.01 m; f32 within 2 m of height), cold and warm started, with the
/// evaluations it took; on the knife-edge golden tile it declines (`Steep`) instead.
#[test]
fn height_search_agrees_with_the_march_where_it_applies() {
    use core_math::earth::dem::HeightRefusal;
    let (grid, heights) = smooth_tile();
    let tile = DemTile::new(grid, &heights).unwrap();
    let e = Ellipsoid::WGS84;
    let mut rng = SplitMix64(0x4E16_2026_1126);
    let (mut n, mut steep, mut worst64, mut worst32) = (0, 0, 0f64, 0f64);
    let (mut cold, mut warm, mut cold32, mut warm32, mut max_warm32) = (0, 0, 0, 0, 0);
    for _ in 0..400 {
        let (r, d) = ray_at(&grid, &mut rng, 40f64.to_radians(), 0.3);
        let exact = tile.first_crossing(&e, r, d).unwrap();
        let dn = libm::sqrt(d.iter().map(|x| x * x).sum());
        let g = core::array::from_fn(|k| r[k] + exact * d[k]);
        let (_, _, h_exact) = geodetic_from_itrf(g, &e).unwrap();
        let found = match tile.crossing_by_height(&e, r, d, None, 1e-3) {
            Err(HeightRefusal::Steep) => {
                steep += 1;
                continue;
            }
            other => other.unwrap(),
        };
        let off_m = (found.s - exact).abs() * dn;
        assert!(found.error_bound_m <= 1e-3, "{found:?}");
        assert!(
            off_m <= 0.01,
            "height search {off_m} m from the march: {found:?}"
        );
        worst64 = worst64.max(off_m);
        cold += found.evaluations;
        // Warm: the hint is the height 300 m off the answer, as after an update's motion
        // over terrain of slope 0.3 (700 m along the ground at 10 Hz, say).
        let warm64 = tile
            .crossing_by_height(
                &e,
                r,
                d,
                Some(h_exact + 300.0 * rng.uniform(-1.0, 1.0)),
                1e-3,
            )
            .unwrap();
        warm += warm64.evaluations;
        let (r32, d32) = (r.map(|x| x as f32), d.map(|x| x as f32));
        for (hint, tally) in [
            (None, &mut cold32),
            (Some(h_exact as f32 + 200.0), &mut warm32),
        ] {
            let f = tile.crossing_by_height(&e, r32, d32, hint, 0.5f32).unwrap();
            let dh = (f.h_m as f64 - h_exact).abs();
            assert!(dh <= 2.0, "f32 height {dh} m off: {f:?}");
            worst32 = worst32.max(dh);
            *tally += f.evaluations;
            if hint.is_some() {
                max_warm32 = max_warm32.max(f.evaluations);
            }
        }
        n += 1;
    }
    assert!(n >= 300, "{n} rays taken, {steep} steep");
    let mean = |x: u32| x as f64 / n as f64;
    println!(
        "height search, smooth tile, {n} rays (of 400; {steep} declined as steep): f64 within \
         {worst64:.1e} m of the march, {:.2} evaluations cold, {:.2} warm (300 m hint); f32 \
         heights within {worst32:.2} m, {:.2} cold, {:.2} warm (200 m hint, at most {max_warm32})",
        mean(cold),
        mean(warm),
        mean(cold32),
        mean(warm32)
    );
    // The knife-edge tile: a slope of 18 makes every oblique ray steep.
    let (grid, heights) = tile_data();
    let ridge = DemTile::new(grid, &heights).unwrap();
    let mut declined = 0;
    for _ in 0..50 {
        let (r, d) = ray_at(&grid, &mut rng, 40f64.to_radians(), 0.3);
        if let Err(HeightRefusal::Steep) = ridge.crossing_by_height(&e, r, d, None, 1e-3) {
            declined += 1;
        }
    }
    assert!(
        declined >= 45,
        "{declined} of 50 declined on the knife-edge tile"
    );
}

/// The height search's latitude and longitude about the tile's centre (series, the
/// raised ellipsoid's normal) against the exact geodetic coordinates: points of the
/// smooth tile at heights across the band, in f64 and f32, in grid cells.
#[test]
fn height_search_grid_coordinates_match_geodetic() {
    let (grid, heights) = smooth_tile();
    let tile = DemTile::new(grid, &heights).unwrap();
    let e = Ellipsoid::WGS84;
    let s64 = tile.height_search::<f64>(&e);
    let s32 = tile.height_search::<f32>(&e);
    let mut rng = SplitMix64(0x9E0_2026_1126);
    let (mut worst64, mut worst32) = (0f64, 0f64);
    let lat1 = grid.lat_deg(grid.nrows - 1);
    let lon1 = grid.lon_deg(grid.ncols - 1);
    for _ in 0..20_000 {
        // A hundredth of a cell inside the edges, which rounding may otherwise cross.
        let lat = rng.uniform(grid.lat0_deg + 5e-5, lat1 - 5e-5);
        let lon = rng.uniform(grid.lon0_deg + 5e-5, lon1 - 5e-5);
        let h = rng.uniform(-500.0, 9_000.0);
        let x = itrf_from_geodetic(lat.to_radians(), lon.to_radians(), h, &e).unwrap();
        let want = (
            (lat - grid.lat0_deg) / grid.dlat_deg,
            (lon - grid.lon0_deg) / grid.dlon_deg,
        );
        // x lies at geodetic height h; the search's points lie on the raised ellipsoid,
        // within 1.41e-6 |h| of it, so give it the height it has.
        let (r, c) = s64.grid_at(h, x).unwrap();
        worst64 = worst64.max((r - want.0).abs().max((c - want.1).abs()));
        let (r, c) = s32.grid_at(h as f32, x.map(|v| v as f32)).unwrap();
        worst32 = worst32.max((r as f64 - want.0).abs().max((c as f64 - want.1).abs()));
    }
    // In metres: a cell is 455-555 m.
    println!(
        "height search grid coordinates: f64 within {worst64:.1e} cells, f32 within {worst32:.1e} cells"
    );
    // f64: the raised ellipsoid's normal, about 1e-8 rad from the geodetic one at 9 000 m
    // (a few centimetres); f32: the rounding of ITRF coordinates (0.5 m at 6 400 km).
    assert!(
        worst64 <= 1e-4 && worst32 <= 3e-3,
        "{worst64:e} {worst32:e}"
    );
    // Outside the tile: none.
    let far = itrf_from_geodetic(40f64.to_radians(), 100.2f64.to_radians(), 0.0, &e).unwrap();
    assert_eq!(s64.grid_at(0.0, far), None);
}
