//! The DEM ground of every plan sample (issue 23, point 2): the controller flying the
//! bus's frames over a DEM tile, against the f64 reference with the DEM ground
//! (`golden::bus_update_on_dem`: Kepler, the full C2T, the quaternion turned exactly,
//! `DemTile::first_crossing` in f64 and the construction on dual numbers; the
//! segment's TERRAIN height where the tile does not cover a pixel). Synthetic tiles with
//! a relief of more than 4 500 m, smooth and with ridges and cliffs, under roll and
//! pitch slews, with segments partly off the tile.

mod common;

use common::bus::{Bus, SCALES, T0_US};
use common::{feed, frame, Registers, H, I0};
use controller::bus::{encode_time_scales, Gnss, StarAttitude};
use controller::dem::{encode_begin, encode_chunk, heights_crc32, DemStore};
use controller::frame::kind;
use controller::{golden, Config, Controller, Scene};
use core_math::earth::dem::{DemGrid, DemTile};
use core_math::earth::frames::geodetic_from_itrf;
use core_math::earth::reference::EarthRefPixel;
use core_math::earth::{Attitude, EarthGeometry};
use core_math::{EarthReference, EARTH_RATE_RAD_S};

const WGS84: core_math::Ellipsoid = core_math::Ellipsoid::WGS84;
/// The budget on the periods against the DEM truth (relative).
const BUDGET: f64 = 1e-4;
/// The yaw request and each centre's drift against the DEM reference's (rad): the
/// route's height tolerance, `HEIGHT_TOLERANCE_M` (5 m), times their change per metre
/// of ground height in these flights, at most about 4e-6 rad/m (over the TERRAIN
/// heights, up to about 3 km off the DEM, they are off by up to 6.4e-3 and 1.6e-2 rad).
const YAW_BUDGET_RAD: f64 = 2e-5;

/// What the bus sends: a Kepler orbit in I at T0, the camera at `roll`, `pitch` (deg)
/// relative to the orbital frame at T0 and mounted as the body, then turning at the
/// orbit's rate plus `slew_rad_s` (camera axes): a slew.
fn bus(roll_deg: f64, pitch_deg: f64, slew_rad_s: [f64; 3]) -> Bus {
    let g = EarthGeometry {
        state: common::state(I0.to_radians(), 0.9, H + 7_000.0),
        attitude: Attitude {
            roll_rad: roll_deg.to_radians(),
            pitch_rad: pitch_deg.to_radians(),
            yaw_rad: 2f64.to_radians(),
            ..Attitude::default()
        },
        ground_h_m: 0.0,
        ellipsoid: WGS84,
        earth_rate_rad_s: EARTH_RATE_RAD_S,
    }
    .to_inertial()
    .unwrap();
    let identity = core::array::from_fn(|i| core::array::from_fn(|j| f64::from(u8::from(i == j))));
    Bus::new(g, &identity, slew_rad_s, T0_US + 70_000)
}

/// Geodetic latitude and longitude (deg) of the boresight's ground at T0, on the
/// ellipsoid raised by 2 000 m.
fn boresight_ground_deg(bus: &Bus) -> (f64, f64) {
    let mut g = bus.geometry;
    g.ground_h_m = 2_000.0;
    let px = EarthRefPixel {
        p1_m: 0.0,
        p2_m: 0.0,
        focal_m: Scene::paper_default().camera.focal_m,
    };
    let chain = EarthReference::chain(&g, &px).unwrap();
    let (lat, lon, _) = geodetic_from_itrf(chain.ground_m, &g.ellipsoid).unwrap();
    (lat.to_degrees(), lon.to_degrees())
}

/// A tile of `side` x `side` nodes at `step_deg` centred on (lat, lon), heights from
/// `relief(i, j)` (m), leaked: the controller takes a `'static` tile.
fn tile_at(
    (lat, lon): (f64, f64),
    side: usize,
    step_deg: f64,
    relief: impl Fn(f64, f64) -> f64,
) -> DemTile<'static, i16> {
    let half = 0.5 * (side - 1) as f64 * step_deg;
    let grid = DemGrid {
        lat0_deg: lat - half,
        lon0_deg: lon - half,
        dlat_deg: step_deg,
        dlon_deg: step_deg,
        nrows: side,
        ncols: side,
    };
    let heights: Vec<i16> = (0..side * side)
        .map(|k| {
            let (i, j) = ((k / side) as f64, (k % side) as f64);
            relief(i, j).round().clamp(-500.0, 9_000.0) as i16
        })
        .collect();
    DemTile::new(grid, Box::leak(heights.into_boxed_slice())).unwrap()
}

use std::f64::consts::TAU;

/// Mountains of 5 200 m range, slopes to about 0.3 at 2.2 km cells.
fn smooth(i: f64, j: f64) -> f64 {
    2_500.0
        + 2_000.0 * (TAU * i / 37.0).sin() * (TAU * j / 53.0).cos()
        + 600.0 * (TAU * (i + j) / 23.0).sin()
}

/// The same with ridges one node wide every 11 columns (2 500 m over one cell) and
/// cliffs every 13 rows (a 3 000 m step): slopes of several.
fn rugged(i: f64, j: f64) -> f64 {
    let ridge = if (j as i64) % 11 == 5 { 2_500.0 } else { 0.0 };
    let cliff = if (i as i64 / 13) % 2 == 1 {
        3_000.0
    } else {
        0.0
    };
    (1_000.0 + 0.5 * (smooth(i, j) - 2_500.0) + ridge + cliff).max(-400.0)
}

fn scene() -> Scene {
    let mut s = Scene::paper_default();
    for (k, seg) in s.segments.iter_mut().take(10).enumerate() {
        seg.ground_h_m = 200.0 * k as f32;
    }
    s
}

/// How the flight's tile becomes the controller's ground.
#[derive(Clone, Copy)]
enum Ground {
    /// `Controller::set_dem_tile`.
    Given,
    /// Uploaded through DEM_BEGIN and DEM_CHUNK frames into the controller's store.
    Uploaded,
}

/// What one flight over a tile measured.
#[derive(Debug, Default)]
struct Flight {
    updates: usize,
    /// Largest |period - reference| / reference: with the DEM; the same controller
    /// without it (TERRAIN heights) against the same DEM reference.
    worst_dem: f64,
    worst_terrain: f64,
    /// Largest |yaw request - reference| (rad): with the DEM, and without it.
    yaw_dem_rad: f64,
    yaw_terrain_rad: f64,
    /// Largest |drift at a segment's centre - reference| (rad): with the DEM, and
    /// without it.
    drift_dem_rad: f64,
    drift_terrain_rad: f64,
    /// Every tenth update: the segments whose reported worst mismatch falls short of
    /// the programmed period's worst over every 100th pixel on the DEM reference, of
    /// those checked; the largest shortfall (relative mismatch).
    bound_short: usize,
    bound_checked: usize,
    bound_shortfall: f64,
    stats: Option<controller::dem_ground::DemStats>,
}

/// 2 s of bus data over `tile`: GNSS at 1 Hz, attitude at 10 Hz, updates every 20 ms,
/// every update checked against the DEM reference.
fn fly(bus: &Bus, tile: DemTile<'static, i16>, ground: Ground) -> Flight {
    fly_scene(bus, tile, ground, scene())
}

/// [`fly`] with the scene `flown`.
fn fly_scene(bus: &Bus, tile: DemTile<'static, i16>, ground: Ground, flown: Scene) -> Flight {
    // Two controllers fed the same frames (a controller is not `Clone`: it may hold
    // the DEM upload's tile memory).
    let start = || {
        let mut c = Controller::new(Config::default(), Scene::paper_default()).unwrap();
        let mut p = [0u8; 512];
        let n = flown.encode(&mut p).unwrap();
        feed(&mut c, &frame(kind::SCENE, 1, T0_US - 500_000, &p[..n]));
        let n = encode_time_scales(18, 0.125, &mut p).unwrap();
        feed(
            &mut c,
            &frame(kind::TIME_SCALES, 2, T0_US - 400_000, &p[..n]),
        );
        c
    };
    let (mut with, mut without) = (start(), start());
    let mut p = [0u8; 512];
    match ground {
        Ground::Given => with.set_dem_tile(Some(tile)).unwrap(),
        Ground::Uploaded => {
            // Through the uplink, as the ground sends it: DEM_BEGIN, then every chunk.
            with.attach_dem(Box::leak(Box::new(DemStore::new())));
            let (g, h) = (*tile.grid(), tile.heights_m());
            let begin = encode_begin(7, &g, heights_crc32(h));
            let mut t = T0_US - 300_000;
            feed(&mut with, &frame(kind::DEM_BEGIN, 3, t, &begin));
            for index in 0u16.. {
                let Some(n) = encode_chunk(7, index, h, &mut p) else {
                    break;
                };
                t += 1_000;
                feed(&mut with, &frame(kind::DEM_CHUNK, 4 + index, t, &p[..n]));
            }
            assert_eq!(with.dem_status().in_force_id, 7, "{:?}", with.last_fault);
        }
    }
    let (mut r1, mut r2) = (Registers::default(), Registers::default());
    let mut flight = Flight::default();
    let (mut gnss, mut att): (Option<Gnss>, Option<StarAttitude>) = (None, None);
    let mut seq = 10u16;
    for k in 0..100u64 {
        let t = T0_US + 100_000 + k * 20_000;
        // The frames due before this update: a fix each second (tagged 80 ms after),
        // an attitude each 100 ms (tagged 20 ms after its validity).
        let fix = T0_US + (t - T0_US - 80_000) / 1_000_000 * 1_000_000;
        if gnss.map(|g| g.fix_us) != Some(fix) && fix + 80_000 <= t {
            let g = bus.gnss(fix);
            let n = g.encode(&mut p).unwrap();
            let f = frame(kind::GNSS, seq, fix + 80_000, &p[..n]);
            feed(&mut with, &f);
            feed(&mut without, &f);
            seq += 1;
            gnss = Some(g);
        }
        if t >= bus.valid0_us + 20_000 {
            let valid = bus.valid0_us + (t - bus.valid0_us - 20_000) / 100_000 * 100_000;
            if att.map(|a| a.valid_us) != Some(valid) {
                let a = bus.attitude(valid);
                let n = a.encode(&mut p).unwrap();
                let f = frame(kind::ATTITUDE, seq, valid + 20_000, &p[..n]);
                feed(&mut with, &f);
                feed(&mut without, &f);
                seq += 1;
                att = Some(a);
            }
        }
        assert_eq!(with.counters.total(), 0, "{:?}", with.last_fault);
        r1.writes.clear();
        assert!(with.advance(t, &mut r1));
        assert!(without.advance(t, &mut r2));
        let (Some(g), Some(a)) = (gnss, att) else {
            continue;
        };
        // The attitude in force: the quaternion blended with the gyros' propagation.
        let a = with.bus_attitude().map_or(a, |s| s.received);
        let gold = golden::bus_update_on_dem(
            with.scene(),
            with.plan(),
            with.heights_m(),
            &g,
            &a,
            &SCALES,
            t,
            &with.dem_tile_in_force().unwrap(),
        )
        .unwrap();
        assert_eq!(r1.writes.len(), 10, "t {t}: {:?}", with.last_fault);
        let golds = gold.segments.iter().flatten();
        for ((o, o_flat), gs) in with.outputs().zip(without.outputs()).zip(golds) {
            assert_eq!(o.index, gs.index);
            assert!(!o.held);
            let rel = |ticks: u32| (f64::from(ticks) - gs.ticks_exact).abs() / gs.ticks_exact;
            assert!(
                rel(o.ticks) <= BUDGET,
                "t {t}: segment {}: {} ticks vs {:.3} ({:.2e})",
                o.index,
                o.ticks,
                gs.ticks_exact,
                rel(o.ticks)
            );
            flight.worst_dem = flight.worst_dem.max(rel(o.ticks));
            let drift_error =
                |o: &controller::SegmentOutput| (f64::from(o.drift_rad) - gs.drift_rad).abs();
            assert!(
                drift_error(o) <= YAW_BUDGET_RAD,
                "t {t}: segment {}: drift {} vs {}",
                o.index,
                o.drift_rad,
                gs.drift_rad
            );
            flight.drift_dem_rad = flight.drift_dem_rad.max(drift_error(o));
            if k % 10 == 0 {
                let tile = with.dem_tile_in_force().unwrap();
                let scene = with.scene();
                let (lo, hi) = golden::bus_v1_span_on_dem(
                    scene,
                    with.heights_m(),
                    &g,
                    &a,
                    &SCALES,
                    t,
                    &tile,
                    o.index,
                    100.0,
                )
                .unwrap();
                let v_line = scene.camera.pixel_m * scene.line_clock_hz / f64::from(o.ticks);
                let worst = (v_line / lo - 1.0).abs().max((1.0 - v_line / hi).abs());
                let short = worst - f64::from(o.worst_mismatch);
                flight.bound_checked += 1;
                if short > 0.0 {
                    flight.bound_short += 1;
                    flight.bound_shortfall = flight.bound_shortfall.max(short);
                }
            }
            flight.drift_terrain_rad = flight.drift_terrain_rad.max(drift_error(o_flat));
            flight.worst_terrain = flight.worst_terrain.max(rel(o_flat.ticks));
        }
        let yaw_error = |c: &Controller| match (c.yaw_request_rad(), gold.yaw_request_rad) {
            (Some(y), Some(g)) => (f64::from(y) - g).abs(),
            _ => f64::INFINITY,
        };
        assert!(
            yaw_error(&with) <= YAW_BUDGET_RAD,
            "t {t}: yaw request {:?} vs {:?}",
            with.yaw_request_rad(),
            gold.yaw_request_rad
        );
        flight.yaw_dem_rad = flight.yaw_dem_rad.max(yaw_error(&with));
        flight.yaw_terrain_rad = flight.yaw_terrain_rad.max(yaw_error(&without));
        flight.updates += 1;
    }
    flight.stats = with.dem_stats();
    flight
}

fn report(name: &str, f: &Flight) {
    let s = f.stats.unwrap();
    eprintln!(
        "{name}: {} updates, periods vs the DEM reference {:.2e} relative (TERRAIN \
         heights alone {:.2e}); yaw request {:.2e} rad ({:.2e}); drift {:.2e} rad ({:.2e}); \
         samples: {} searched in \
         {} evaluations ({:.2} each), {} traced, {} unresolved, {} off the tile, {} settled \
         at its edge; worst-mismatch bound short in {} of {} segments checked, by up to {:.2e}",
        f.updates,
        f.worst_dem,
        f.worst_terrain,
        f.yaw_dem_rad,
        f.yaw_terrain_rad,
        f.drift_dem_rad,
        f.drift_terrain_rad,
        s.searched,
        s.evaluations,
        s.evaluations as f64 / s.searched.max(1) as f64,
        s.traced,
        s.unresolved,
        s.outside,
        s.edges,
        f.bound_short,
        f.bound_checked,
        f.bound_shortfall
    );
}

/// A roll slew (0.7 deg/s) at 15 deg of roll over smooth mountains of 5 200 m range,
/// the tile 5 deg wide under the boresight: the outer segments partly off it.
#[test]
fn roll_slew_over_mountains_matches_the_dem_reference() {
    let bus = bus(15.0, 0.0, [0.012, -0.002, 0.001]);
    let tile = tile_at(boresight_ground_deg(&bus), 250, 0.02, smooth);
    let f = fly(&bus, tile, Ground::Given);
    report("roll slew, smooth tile", &f);
    let s = f.stats.unwrap();
    assert!(f.updates >= 90);
    assert!(s.searched >= 500 && s.outside > 100, "{s:?}");
    // The test can tell: without the DEM the periods are far off.
    assert!(f.worst_terrain > 10.0 * BUDGET, "{f:?}");
}

/// The yaw request over the DEM where the boresight is no plan sample: every segment's
/// row 2 mm along the track from it, so that its ray is searched in the route's own
/// slot (in the other flights it is a sample, pixel 0 at p1 = 0, found ahead).
#[test]
fn the_yaw_request_is_over_the_dem_where_the_boresight_is_no_sample() {
    let bus = bus(15.0, 0.0, [0.012, -0.002, 0.001]);
    let tile = tile_at(boresight_ground_deg(&bus), 250, 0.02, rugged);
    let mut flown = scene();
    for seg in flown.segments.iter_mut().take(10) {
        seg.p1_m = 2e-3;
    }
    let probe = Controller::new(Config::default(), flown).unwrap();
    assert_eq!(probe.plan().boresight_sample, None);
    let default = Controller::new(Config::default(), scene()).unwrap();
    assert!(default.plan().boresight_sample.is_some());
    let f = fly_scene(&bus, tile, Ground::Given, flown);
    report("roll slew, ridges and cliffs, rows off the boresight", &f);
    assert!(f.updates >= 90);
    // The test can tell: over the TERRAIN heights the request is far off.
    assert!(f.yaw_terrain_rad > 100.0 * YAW_BUDGET_RAD, "{f:?}");
}

/// The stereo pitch (-20 deg, pitching at 0.4 deg/s) with a little roll over the same
/// mountains.
#[test]
fn stereo_pitch_over_mountains_matches_the_dem_reference() {
    let bus = bus(5.0, -20.0, [0.002, 0.007, 0.0]);
    let tile = tile_at(boresight_ground_deg(&bus), 250, 0.02, smooth);
    let f = fly(&bus, tile, Ground::Given);
    report("stereo pitch, smooth tile", &f);
    let s = f.stats.unwrap();
    assert!(s.searched >= 500 && s.outside > 100, "{s:?}");
    assert!(f.worst_terrain > 10.0 * BUDGET, "{f:?}");
}

/// Ridges and cliffs (slopes of several: the search in height cannot certify a single
/// crossing, and the march in height decides) on a tile 5 deg wide, in the roll slew.
#[test]
fn ridges_and_cliffs_go_to_the_march_in_height_and_match_the_dem_reference() {
    let bus = bus(10.0, -5.0, [0.010, 0.003, 0.0]);
    let tile = tile_at(boresight_ground_deg(&bus), 250, 0.02, rugged);
    let (lo, hi) = tile.height_range_m();
    assert!(hi - lo >= 4_500.0, "{lo} {hi}");
    let f = fly(&bus, tile, Ground::Given);
    report("roll slew, ridges and cliffs", &f);
    let s = f.stats.unwrap();
    assert!(s.traced > 100 && s.outside > 100, "{s:?}");
}

/// The same roll slew with a tile of the uploadable size (120 x 120 nodes at 0.02 deg)
/// sent through the uplink: the update takes its ground from the uploaded tile in force
/// and meets the same budget against the DEM reference.
#[test]
fn an_uploaded_tile_is_the_ground_of_the_update() {
    let bus = bus(15.0, 0.0, [0.012, -0.002, 0.001]);
    let tile = tile_at(boresight_ground_deg(&bus), 120, 0.02, smooth);
    let f = fly(&bus, tile, Ground::Uploaded);
    report("roll slew, uploaded tile", &f);
    let s = f.stats.unwrap();
    assert!(f.updates >= 90);
    assert!(s.searched >= 500, "{s:?}");
    // Without the uploaded tile in force the periods would be far off the reference.
    assert!(f.worst_terrain > 10.0 * BUDGET, "{f:?}");
}

/// The roll slew of [`an_uploaded_tile_is_the_ground_of_the_update`] on a tile twice as
/// coarse (120 x 120 nodes at 0.04 deg, 4.76 deg wide). The row's far end looks within
/// a degree of the vertical, at 50 deg of latitude: where the route's incidence once
/// came out below zero and the march stalled (1.85e-3 off, docs/controller.md).
#[test]
fn roll_slew_over_a_wide_tile_matches_the_dem_reference() {
    let bus = bus(15.0, 0.0, [0.012, -0.002, 0.001]);
    let tile = tile_at(boresight_ground_deg(&bus), 120, 0.04, smooth);
    let f = fly(&bus, tile, Ground::Given);
    report("roll slew, wide tile", &f);
    let s = f.stats.unwrap();
    assert!(f.updates >= 90);
    assert!(s.searched >= 500 && s.outside > 100, "{s:?}");
    assert!(f.worst_terrain > 10.0 * BUDGET, "{f:?}");
}

/// The same roll slew over the widest uploadable tile of the bus pass's kind (128 x
/// 128 nodes at 0.039 deg, 4.95 deg wide) sent through the uplink.
#[test]
fn roll_slew_over_a_wide_uploaded_tile_matches_the_dem_reference() {
    let bus = bus(15.0, 0.0, [0.012, -0.002, 0.001]);
    let tile = tile_at(boresight_ground_deg(&bus), 128, 0.039, smooth);
    let f = fly(&bus, tile, Ground::Uploaded);
    report("roll slew, wide uploaded tile", &f);
    let s = f.stats.unwrap();
    assert!(f.updates >= 90);
    assert!(s.searched >= 500, "{s:?}");
    assert!(f.worst_terrain > 10.0 * BUDGET, "{f:?}");
}

/// The stereo pitch of [`stereo_pitch_over_mountains_matches_the_dem_reference`] over
/// the wide tile.
#[test]
fn stereo_pitch_over_a_wide_tile_matches_the_dem_reference() {
    let bus = bus(5.0, -20.0, [0.002, 0.007, 0.0]);
    let tile = tile_at(boresight_ground_deg(&bus), 128, 0.039, smooth);
    let f = fly(&bus, tile, Ground::Given);
    report("stereo pitch, wide tile", &f);
    let s = f.stats.unwrap();
    assert!(s.searched >= 500, "{s:?}");
    assert!(f.worst_terrain > 10.0 * BUDGET, "{f:?}");
}

/// Ridges and cliffs on the wide tile in the roll slew of
/// [`ridges_and_cliffs_go_to_the_march_in_height_and_match_the_dem_reference`].
#[test]
fn ridges_and_cliffs_on_a_wide_tile_match_the_dem_reference() {
    let bus = bus(10.0, -5.0, [0.010, 0.003, 0.0]);
    let tile = tile_at(boresight_ground_deg(&bus), 128, 0.039, rugged);
    let f = fly(&bus, tile, Ground::Given);
    report("roll slew, ridges and cliffs, wide tile", &f);
    let s = f.stats.unwrap();
    // About a hundred samples go to the march in height, as many to the search.
    assert!(s.traced >= 90 && s.searched > 100, "{s:?}");
}
