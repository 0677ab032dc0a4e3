//! Instruction-count benchmark, run by `cargo xtask bench` under QEMU with the
//! `stopwatch` TCG plugin (tools/qemu-stopwatch): the plugin counts the guest
//! instructions between each call of [`bench_start`] and the next of [`bench_stop`].
//!
//! Before each region the firmware logs `BENCH <label>`; the xtask pairs the n-th label
//! with the n-th count. The first region is empty: its count is the markers' own
//! overhead, which the xtask subtracts. Inputs go through `black_box` after the start
//! marker and results through `black_box` before the stop marker, so that nothing is
//! computed outside the region or optimised away.
#![no_std]
#![no_main]

use core::hint::black_box;

use core_math::earth::{circular_state, Attitude, EarthCamera, EarthGeometry, Ellipsoid};
use core_math::sphere::fixed_point::geometry_from_f64;
use core_math::sphere::{
    Geometry, MicroF32, NaiveF32, Reference, CLOSED_F32, CLOSED_F64, CLOSED_MICROMATH, FIXED,
};
use core_math::{Backend, Camera, EarthReference, Model, EARTH_FIXED, GENERAL_F32, GENERAL_F64};
use cortex_m_rt::entry;
use firmware::platform;
use firmware::synthetic::{controller_with_bus, controller_with_nav, NoRegisters, BUS_EPOCH_US};
use firmware::FirmwareError;

use controller::{Config, Controller};

/// Start of a measured region (the plugin watches its first instruction). The
/// `black_box` of a constant of its own is a side effect the optimiser must keep, and
/// makes the two markers differ, so that neither the calls nor the functions are merged
/// or removed.
#[no_mangle]
#[inline(never)]
pub extern "C" fn bench_start() {
    black_box(0x5354_4152_u32);
}

/// End of a measured region.
#[no_mangle]
#[inline(never)]
pub extern "C" fn bench_stop() {
    black_box(0x5354_4f50_u32);
}

/// Runs `f` on `input` between the markers, logging `label` first.
#[inline(always)]
fn region<I, O>(label: &str, input: I, f: impl FnOnce(I) -> O) {
    defmt::info!("BENCH {=str}", label);
    bench_start();
    let out = f(black_box(input));
    black_box(out);
    bench_stop();
}

/// Pixels per loop region: one pixel every 1 935 across the default swath.
const LOOP_PX: usize = 32;

/// `LOOP_PX` pixel constants of `backend`, n = -30 000 ... +30 000.
fn loop_pixels<M: Model, B: Backend<M>>(
    backend: &B,
    camera: &M::Camera,
) -> Result<[B::Pixel; LOOP_PX], FirmwareError>
where
    B::Pixel: Copy,
{
    let first = backend.pixel(camera, -30_000.0)?;
    let mut out = [first; LOOP_PX];
    for (i, p) in out.iter_mut().enumerate() {
        let n_px = -30_000.0 + 60_000.0 * i as f64 / (LOOP_PX - 1) as f64;
        *p = backend.pixel(camera, n_px)?;
    }
    Ok(out)
}

/// `motion` of every pixel in a loop, each result kept (`black_box`): the count divided
/// by `LOOP_PX` is the marginal cost of a pixel inside a loop, the way the controller
/// evaluates its sample points, without the call and return of a one-pixel region.
fn loop_region<M: Model, B: Backend<M>>(
    label: &str,
    backend: &B,
    u: &B::Update,
    pixels: &[B::Pixel; LOOP_PX],
) {
    region(label, (u, pixels), |(u, pixels)| {
        for p in pixels {
            let _kept = black_box(backend.motion(u, p));
        }
    });
}

/// Most sample points of one update (10 segments of at most 9).
const MAX_POINTS: usize = 90;

/// The default scene's planned sample pixels (the controller's plan, the one the
/// firmware evaluates every update), as one backend's pixel constants.
fn plan_pixels<M: Model, B: Backend<M>>(
    backend: &B,
    camera: &M::Camera,
) -> Result<([B::Pixel; MAX_POINTS], usize), FirmwareError>
where
    B::Pixel: Copy,
{
    let plan = controller::plan::Plan::new(&controller::Scene::paper_default(), &Config::default())
        .map_err(|_| FirmwareError::Layout)?;
    let mut out = [backend.pixel(camera, 0.0)?; MAX_POINTS];
    let mut count = 0;
    for seg in plan.active() {
        for n_px in seg.samples.iter().map(|s| s.px) {
            let slot = out.get_mut(count).ok_or(FirmwareError::Layout)?;
            *slot = backend.pixel(camera, f64::from(n_px))?;
            count += 1;
        }
    }
    Ok((out, count))
}

/// One full update of the default scene with `backend`: its `update`, then `motion` at
/// every planned sample point, each result kept. The same work for every backend (the
/// controller's own update adds |v|, period, ticks, the MTF guard and the outputs).
fn full_update_region<M: Model, B: Backend<M>>(
    label: &str,
    backend: &B,
    g: &M::Geometry<B::Real>,
    pixels: &([B::Pixel; MAX_POINTS], usize),
) {
    region(label, (g, pixels), |(g, (pixels, count))| {
        let u = backend.update(g);
        if let Ok(u) = &u {
            for p in pixels.iter().take(*count) {
                let _kept = black_box(backend.motion(u, p));
            }
        }
        black_box(u.is_ok())
    });
}

/// The update every update period: the one after an earlier update, its instant the one
/// scheduled (the first after a start or a gap also divides 64-bit time to find it).
fn steady_update_region(label: &str, c: &mut Controller) -> Result<(), FirmwareError> {
    update_region_at(label, c, 1_000_000, 1_020_000)
}

/// The first update after the NAV frame: the same, plus the update instant found by a
/// 64-bit division.
fn first_update_region(label: &str, c: &mut Controller) -> Result<(), FirmwareError> {
    update_region(label, c, 1_020_000)
}

/// An update at `warm_us` (not measured), then the one at `t_us`.
fn update_region_at(
    label: &str,
    c: &mut Controller,
    warm_us: u64,
    t_us: u64,
) -> Result<(), FirmwareError> {
    if !c.advance(warm_us, &mut NoRegisters) {
        return Err(FirmwareError::Telemetry);
    }
    update_region(label, c, t_us)
}

/// One whole controller update (update constants, every planned segment, outputs).
fn update_region(label: &str, c: &mut Controller, t_us: u64) -> Result<(), FirmwareError> {
    let mut regs = NoRegisters;
    defmt::info!("BENCH {=str}", label);
    bench_start();
    let ran = black_box(c).advance(black_box(t_us), &mut regs);
    bench_stop();
    if ran {
        Ok(())
    } else {
        Err(FirmwareError::Telemetry)
    }
}

/// Instructions per update for each scene kind, planned and evaluate-everything: the
/// whole update of the real-Earth controller (propagation, the general form's update,
/// each segment's ground, samples, centre, MTF, stages, drift, yaw request).
fn scene_kinds() -> Result<(), FirmwareError> {
    let all = controller::Scene::paper_default();
    let mut nadir = all;
    nadir.envelope.max_roll_rad = 0.0;
    nadir.envelope.max_pitch_rad = 0.0;
    let mut one = all;
    for (k, s) in one.segments.iter_mut().enumerate() {
        s.active = k == 9;
    }
    // An agile instant: rolled and pitched, every angle moving (a roll slew, the yaw not
    // steered: drift 0.55 rad at the array centre); `steered` below is the same instant
    // turned by the controller's yaw request.
    let agile = controller::nav::Attitude {
        roll_rad: 20f32.to_radians(),
        pitch_rad: -10f32.to_radians(),
        yaw_rad: 3f32.to_radians(),
        roll_rate_rad_s: 0.5f32.to_radians(),
        pitch_rate_rad_s: -0.2f32.to_radians(),
        yaw_rate_rad_s: 0.05f32.to_radians(),
    };
    let steered = controller::nav::Attitude {
        yaw_rad: 3f32.to_radians() + 0.555,
        ..agile
    };
    let kinds: [(
        &str,
        &str,
        controller::Scene,
        controller::nav::Attitude<f32>,
    ); 4] = [
        (
            "scene roll and pitch up to 25 deg, all segments, yaw steered: planned",
            "scene roll and pitch up to 25 deg, all segments, yaw steered: evaluate everything",
            all,
            steered,
        ),
        (
            "scene nadir only, all segments: planned",
            "scene nadir only, all segments: evaluate everything",
            nadir,
            controller::nav::Attitude::default(),
        ),
        (
            "scene roll and pitch up to 25 deg, all segments: planned",
            "scene roll and pitch up to 25 deg, all segments: evaluate everything",
            all,
            agile,
        ),
        (
            "scene roll and pitch up to 25 deg, one segment active: planned",
            "scene roll and pitch up to 25 deg, one segment active: evaluate everything",
            one,
            agile,
        ),
    ];
    for (planned, everything, scene, attitude) in kinds {
        let mut c = controller_with_nav(scene, false, attitude)?;
        steady_update_region(planned, &mut c)?;
        let mut c = controller_with_nav(scene, true, attitude)?;
        steady_update_region(everything, &mut c)?;
    }
    // The same agile instant from the bus's frames (GNSS in the ITRF, a GCRF
    // quaternion with body rates): the update carries both and turns them into the
    // ITRF of its instant.
    let mut c = controller_with_bus(all, agile)?;
    update_region_at(
        "bus frames (GNSS, ATTITUDE), scene roll and pitch up to 25 deg, all segments: planned",
        &mut c,
        BUS_EPOCH_US + 80_000,
        BUS_EPOCH_US + 100_000,
    )?;
    dem_update_regions(all, agile)?;
    let mut c = controller_with_nav(all, false, agile)?;
    first_update_region(
        "scene roll and pitch up to 25 deg, the first update after NAV, all segments: planned",
        &mut c,
    )?;
    Ok(())
}

/// Nodes along each side of the update bench's DEM tile (128 x 128 int16, the
/// protocol's smallest: 32 KiB of RAM).
const TILE_SIDE: usize = 128;
/// Its spacing (deg): 4.3 km cells, the tile 4.95 deg wide, as wide as the DEM route
/// takes (`controller::dem_ground::MAX_TILE_HALF_DEG`).
const TILE_STEP_DEG: f64 = 0.039;
static mut TILE_HEIGHTS: [i16; TILE_SIDE * TILE_SIDE] = [0; TILE_SIDE * TILE_SIDE];

/// The bus-frame update at the agile instant with a DEM tile in force, centred under
/// the boresight (mountains of 5 200 m range, slopes to about 0.35; the swath's outer
/// segments reach past it): the steady update (two updates before it), and the first
/// after the tile came into force (each sample's search starts from its TERRAIN height).
fn dem_update_regions(
    scene: controller::Scene,
    attitude: controller::nav::Attitude<f32>,
) -> Result<(), FirmwareError> {
    use core_math::earth::dem::{DemGrid, DemTile};
    use core_math::earth::frames::geodetic_from_itrf;
    use core_math::earth::reference::EarthRefPixel;

    let g = EarthGeometry {
        state: firmware::synthetic::orbit(),
        attitude: attitude.to_f64(),
        ground_h_m: 2_500.0,
        ellipsoid: controller::EARTH,
        earth_rate_rad_s: core_math::EARTH_RATE_RAD_S,
    }
    .to_inertial()?;
    let px = EarthRefPixel {
        p1_m: 0.0,
        p2_m: 0.0,
        focal_m: scene.camera.focal_m,
    };
    let chain = EarthReference::chain(&g, &px)?;
    let (lat, lon, _) = geodetic_from_itrf(chain.ground_m, &g.ellipsoid)?;
    let half = 0.5 * (TILE_SIDE - 1) as f64 * TILE_STEP_DEG;
    let grid = DemGrid {
        lat0_deg: lat.to_degrees() - half,
        lon0_deg: lon.to_degrees() - half,
        dlat_deg: TILE_STEP_DEG,
        dlon_deg: TILE_STEP_DEG,
        nrows: TILE_SIDE,
        ncols: TILE_SIDE,
    };
    let tau = core::f64::consts::TAU;
    // SAFETY: the bench is single-threaded and takes no interrupt that reads it; the
    // table is written once here, before any reference to it is taken.
    let heights: &'static [i16] = unsafe {
        let table = &mut *core::ptr::addr_of_mut!(TILE_HEIGHTS);
        for (k, h) in table.iter_mut().enumerate() {
            let (i, j) = ((k / TILE_SIDE) as f64, (k % TILE_SIDE) as f64);
            *h = libm::round(
                2_500.0
                    + 2_000.0 * libm::sin(tau * i / 17.0) * libm::cos(tau * j / 23.0)
                    + 600.0 * libm::sin(tau * (i + j) / 11.0),
            ) as i16;
        }
        &*core::ptr::addr_of!(TILE_HEIGHTS)
    };
    let tile = DemTile::new(grid, heights)?;
    let mut c = controller_with_bus(scene, attitude)?;
    c.set_dem_tile(Some(tile))
        .map_err(|_| FirmwareError::Layout)?;
    for t in [BUS_EPOCH_US + 60_000, BUS_EPOCH_US + 80_000] {
        if !c.advance(t, &mut NoRegisters) {
            return Err(FirmwareError::Telemetry);
        }
    }
    let before = c.dem_stats().unwrap_or_default();
    update_region(
        "bus frames and a 128 x 128 DEM tile, scene roll and pitch up to 25 deg, all segments: planned",
        &mut c,
        BUS_EPOCH_US + 100_000,
    )?;
    let after = c.dem_stats().unwrap_or_default();
    defmt::info!(
        "DEM update: {=u32} samples searched in {=u32} evaluations, {=u32} traced, {=u32} unresolved, {=u32} off the tile, {=u32} settled at its edge",
        after.searched - before.searched,
        after.evaluations - before.evaluations,
        after.traced - before.traced,
        after.unresolved - before.unresolved,
        after.outside - before.outside,
        after.edges - before.edges
    );
    let mut c = controller_with_bus(scene, attitude)?;
    if !c.advance(BUS_EPOCH_US + 80_000, &mut NoRegisters) {
        return Err(FirmwareError::Telemetry);
    }
    c.set_dem_tile(Some(tile))
        .map_err(|_| FirmwareError::Layout)?;
    update_region(
        "bus frames and a 128 x 128 DEM tile, the first update over it: planned",
        &mut c,
        BUS_EPOCH_US + 100_000,
    )?;
    let first = c.dem_stats().unwrap_or_default();
    defmt::info!(
        "DEM first update: {=u32} samples searched in {=u32} evaluations, {=u32} traced, {=u32} unresolved, {=u32} off the tile, {=u32} settled at its edge",
        first.searched,
        first.evaluations,
        first.traced,
        first.unresolved,
        first.outside,
        first.edges
    );
    Ok(())
}

/// The paper's camera and instant: f 0.555 m, pixel 13 um; H 645 km over R 6 370 km,
/// i0 97.98 deg, argument of latitude 0, roll 25 deg (the right edge of the swath is 5 deg
/// from the limb: the near-limb form).
const CAMERA: Camera = Camera {
    focal_m: 0.555,
    pixel_m: 13e-6,
};
/// The line clock of the default scene (Hz).
const LINE_CLOCK_HZ: f32 = 10e6;

fn paper_geometry() -> Geometry<f64> {
    Geometry::circular(
        25f64.to_radians(),
        97.98f64.to_radians(),
        0.0,
        645e3,
        6_370e3,
    )
}

/// The default scene's orbit and camera in the real-Earth model: the same 645 km
/// sun-synchronous orbit (circular, over WGS 84), argument of latitude 30 deg, an agile
/// attitude (roll 25, pitch -10, yaw 3 deg, rates of a slew) over 1 000 m of terrain.
fn earth_geometry() -> EarthGeometry<f64> {
    EarthGeometry {
        state: circular_state(
            Ellipsoid::WGS84.a_m + 645e3,
            97.98f64.to_radians(),
            30f64.to_radians(),
        ),
        attitude: Attitude {
            roll_rad: 25f64.to_radians(),
            pitch_rad: -10f64.to_radians(),
            yaw_rad: 3f64.to_radians(),
            roll_rate_rad_s: 0.5f64.to_radians(),
            pitch_rate_rad_s: -0.2f64.to_radians(),
            yaw_rate_rad_s: 0.05f64.to_radians(),
        },
        ground_h_m: 1_000.0,
        ellipsoid: Ellipsoid::WGS84,
        earth_rate_rad_s: core_math::EARTH_RATE_RAD_S,
    }
}

const EARTH_CAMERA: EarthCamera = EarthCamera {
    focal_m: 0.555,
    pixel_m: 13e-6,
    p1_m: 0.0,
};

/// Nodes along each side of the bench's DEM tile (64 x 64 int16: 8 KiB of RAM).
const DEM_SIDE: usize = 64;
/// Its heights, filled at run time (a smooth relief, as `core-math/tests/dem.rs`'s).
static mut DEM_HEIGHTS: [i16; DEM_SIDE * DEM_SIDE] = [0; DEM_SIDE * DEM_SIDE];

/// The DEM searches' regions: on a 64 x 64 tile at 0.005 deg (555 m x 455 m cells,
/// 1 300..3 700 m, slopes to 0.3) centred under the agile instant's boresight, that
/// line of sight in f32: the height search's per-tile constants, one ray cold and
/// warm, and the march (`DemTile::first_crossing`) for comparison.
fn dem_regions() -> Result<(), FirmwareError> {
    use core_math::earth::dem::{DemGrid, DemTile};
    use core_math::earth::frames::geodetic_from_itrf;
    use core_math::earth::reference::EarthRefPixel;

    let g = earth_geometry().to_inertial()?;
    let px = EarthRefPixel {
        p1_m: 0.0,
        p2_m: 0.0,
        focal_m: EARTH_CAMERA.focal_m,
    };
    let chain = EarthReference::chain(&g, &px)?;
    let (lat, lon, _) = geodetic_from_itrf(chain.ground_m, &g.ellipsoid)?;
    let half = 0.5 * (DEM_SIDE - 1) as f64 * 0.005;
    let grid = DemGrid {
        lat0_deg: lat.to_degrees() - half,
        lon0_deg: lon.to_degrees() - half,
        dlat_deg: 0.005,
        dlon_deg: 0.005,
        nrows: DEM_SIDE,
        ncols: DEM_SIDE,
    };
    let tau = core::f64::consts::TAU;
    // SAFETY: the bench is single-threaded and takes no interrupt that reads it; the
    // table is written once here, before any reference to it is taken.
    let heights = unsafe {
        let table = &mut *core::ptr::addr_of_mut!(DEM_HEIGHTS);
        for (k, h) in table.iter_mut().enumerate() {
            let (i, j) = ((k / DEM_SIDE) as f64, (k % DEM_SIDE) as f64);
            *h = libm::round(
                2_500.0
                    + 900.0 * libm::sin(tau * i / 128.0) * libm::cos(tau * j / 100.0)
                    + 300.0 * libm::sin(tau * (i + j) / 60.0),
            ) as i16;
        }
        &*core::ptr::addr_of!(DEM_HEIGHTS)
    };
    let tile = DemTile::new(grid, heights)?;
    let m = &g.attitude.camera_to_inertial;
    let u = [0.0, 0.0, -EARTH_CAMERA.focal_m];
    let d: [f32; 3] =
        core::array::from_fn(|i| (m[i][0] * u[0] + m[i][1] * u[1] + m[i][2] * u[2]) as f32);
    let r = g.state.position_m.map(|x| x as f32);
    let e = g.ellipsoid;
    region(
        "DEM height search (f32): its constants, once per tile",
        &tile,
        |t| t.height_search::<f32>(&e),
    );
    let search = tile.height_search::<f32>(&e);
    let cold = search.crossing(r, d, None, 0.5);
    let h_found = match cold {
        Ok(c) => {
            defmt::info!(
                "DEM height search: {=u32} evaluations, height {=f32} m, bound {=f32} m",
                c.evaluations,
                c.h_m,
                c.error_bound_m
            );
            c.h_m
        }
        // The height search declining this ray would be a bench set-up error.
        Err(_) => return Err(core_math::ModelError::OutsideDem.into()),
    };
    region(
        "DEM height search (f32), one ray, from mid-band",
        (r, d),
        |(r, d)| search.crossing(r, d, None, 0.5),
    );
    region(
        "DEM height search (f32), one ray, from a hint 200 m off",
        (r, d, h_found + 200.0),
        |(r, d, hint)| search.crossing(r, d, Some(hint), 0.5),
    );
    region("DEM march (f32), one ray", (r, d), |(r, d)| {
        tile.first_crossing(&e, r, d)
    });
    Ok(())
}

/// The real-Earth backends' regions: update, motion in a loop and alone, full update.
fn earth_regions() -> Result<(), FirmwareError> {
    let camera = EARTH_CAMERA;
    let e64 = earth_geometry();
    let e32: EarthGeometry<f32> = e64.to();
    let up32 = GENERAL_F32.update(&e32)?;
    let up64 = GENERAL_F64.update(&e64)?;
    let axis32 = GENERAL_F32.pixel(&camera, 0.0)?;
    let axis_ref = EarthReference.pixel(&camera, 0.0)?;
    let loop32 = loop_pixels(&GENERAL_F32, &camera)?;
    let loop64 = loop_pixels(&GENERAL_F64, &camera)?;
    let loop_ref = loop_pixels(&EarthReference, &camera)?;
    let plan32 = plan_pixels(&GENERAL_F32, &camera)?;
    let plan64 = plan_pixels(&GENERAL_F64, &camera)?;
    let plan_ref = plan_pixels(&EarthReference, &camera)?;
    let efx = core_math::earth::fixed::geometry_from_f64(&e64)?;
    let upfx = EARTH_FIXED.update(&efx)?;
    let axisfx = EARTH_FIXED.pixel(&camera, 0.0)?;
    let loopfx = loop_pixels(&EARTH_FIXED, &camera)?;
    let planfx = plan_pixels(&EARTH_FIXED, &camera)?;
    full_update_region("GENERAL_F32 full update", &GENERAL_F32, &e32, &plan32);
    full_update_region("EARTH_FIXED full update", &EARTH_FIXED, &efx, &planfx);
    full_update_region("GENERAL_F64 full update", &GENERAL_F64, &e64, &plan64);
    full_update_region(
        "EarthReference full update",
        &EarthReference,
        &e64,
        &plan_ref,
    );
    loop_region(
        "GENERAL_F32 motion, 32 pixels in a loop",
        &GENERAL_F32,
        &up32,
        &loop32,
    );
    loop_region(
        "EARTH_FIXED motion, 32 pixels in a loop",
        &EARTH_FIXED,
        &upfx,
        &loopfx,
    );
    loop_region(
        "GENERAL_F64 motion, 32 pixels in a loop",
        &GENERAL_F64,
        &up64,
        &loop64,
    );
    loop_region(
        "EarthReference motion, 32 pixels in a loop",
        &EarthReference,
        &e64,
        &loop_ref,
    );
    region(
        "GENERAL_F32 update (earth model, once per telemetry update)",
        &e32,
        |g| GENERAL_F32.update(g),
    );
    region(
        "EarthGeometry::check_inputs (f32 attitude; part of GENERAL_F32 update)",
        &e32,
        |g| g.check_inputs(),
    );
    region(
        "EarthGeometry::validate (every check in f64: the reference's; not on the f32 path)",
        &e32,
        |g| g.validate(),
    );
    region(
        "EARTH_FIXED update (earth model in soft f64, rounded to integers)",
        &efx,
        |g| EARTH_FIXED.update(g),
    );
    region(
        "EARTH_FIXED motion, 1 pixel (n = 0; integer only)",
        (&upfx, &axisfx),
        |(u, p)| EARTH_FIXED.motion(u, p),
    );
    region("GENERAL_F64 update (earth model)", &e64, |g| {
        GENERAL_F64.update(g)
    });
    region(
        "GENERAL_F32 motion, 1 pixel (n = 0)",
        (&up32, &axis32),
        |(u, p)| GENERAL_F32.motion(u, p),
    );
    region(
        "EarthReference motion (f64 construction on dual numbers), 1 pixel (n = 0)",
        (&e64, &axis_ref),
        |(g, p)| EarthReference.motion(g, p),
    );
    Ok(())
}

fn run() -> Result<(), FirmwareError> {
    let camera = CAMERA;
    let g32: Geometry<f32> = paper_geometry().to();
    let g64: Geometry<f64> = g32.to_f64();
    let update = CLOSED_F32.update(&g32)?;
    let axis = CLOSED_F32.pixel(&camera, 0.0)?;
    let edge = CLOSED_F32.pixel(&camera, 30_000.0)?;
    let axis64 = CLOSED_F64.pixel(&camera, 0.0)?;
    let update64 = CLOSED_F64.update(&g64)?;
    let ref_pixel = Reference.pixel(&camera, 0.0)?;
    let gfx = geometry_from_f64(&g64)?;
    let update_fx = FIXED.update(&gfx)?;
    let axis_fx = FIXED.pixel(&camera, 0.0)?;
    let edge_fx = FIXED.pixel(&camera, 30_000.0)?;
    // Roll 45 deg: pixel 15 735 looks 9.7e-5 rad short of the limb (near-limb form).
    let g45 = Geometry {
        roll_rad: 45f64.to_radians(),
        ..g64
    };
    let update_fx45 = FIXED.update(&geometry_from_f64(&g45)?)?;
    let near_fx = FIXED.pixel(&camera, 15_735.0)?;
    let update_naive = NaiveF32.update(&g32)?;
    let axis_naive = NaiveF32.pixel(&camera, 0.0)?;
    let edge_naive = NaiveF32.pixel(&camera, 30_000.0)?;

    let loop_f32 = loop_pixels(&CLOSED_F32, &camera)?;
    let loop_f64 = loop_pixels(&CLOSED_F64, &camera)?;
    let loop_fx = loop_pixels(&FIXED, &camera)?;
    let loop_naive = loop_pixels(&NaiveF32, &camera)?;
    let loop_ref = loop_pixels(&Reference, &camera)?;

    let plan_f32 = plan_pixels(&CLOSED_F32, &camera)?;
    let plan_f64 = plan_pixels(&CLOSED_F64, &camera)?;
    let plan_fx = plan_pixels(&FIXED, &camera)?;
    let plan_naive = plan_pixels(&NaiveF32, &camera)?;
    let plan_ref = plan_pixels(&Reference, &camera)?;
    let plan_micro = plan_pixels(&CLOSED_MICROMATH, &camera)?;
    let g_micro: Geometry<MicroF32> = g64.to();
    let update_micro = CLOSED_MICROMATH.update(&g_micro)?;
    let loop_micro = loop_pixels(&CLOSED_MICROMATH, &camera)?;
    defmt::info!("full update: {=usize} planned sample points", plan_f32.1);

    region("empty region (marker overhead)", (), |()| ());
    full_update_region("CLOSED_F32 full update", &CLOSED_F32, &g32, &plan_f32);
    full_update_region("CLOSED_F64 full update", &CLOSED_F64, &g64, &plan_f64);
    full_update_region("FIXED full update", &FIXED, &gfx, &plan_fx);
    full_update_region("NaiveF32 full update", &NaiveF32, &g32, &plan_naive);
    full_update_region("Reference full update", &Reference, &g64, &plan_ref);
    full_update_region(
        "CLOSED_MICROMATH full update",
        &CLOSED_MICROMATH,
        &g_micro,
        &plan_micro,
    );
    loop_region(
        "CLOSED_MICROMATH motion, 32 pixels in a loop",
        &CLOSED_MICROMATH,
        &update_micro,
        &loop_micro,
    );
    region("CLOSED_MICROMATH update", &g_micro, |g| {
        CLOSED_MICROMATH.update(g)
    });
    loop_region(
        "CLOSED_F32 motion, 32 pixels in a loop",
        &CLOSED_F32,
        &update,
        &loop_f32,
    );
    loop_region(
        "CLOSED_F64 motion, 32 pixels in a loop",
        &CLOSED_F64,
        &update64,
        &loop_f64,
    );
    loop_region(
        "FIXED motion, 32 pixels in a loop",
        &FIXED,
        &update_fx,
        &loop_fx,
    );
    loop_region(
        "NaiveF32 motion, 32 pixels in a loop",
        &NaiveF32,
        &update_naive,
        &loop_naive,
    );
    loop_region(
        "Reference motion, 32 pixels in a loop",
        &Reference,
        &g64,
        &loop_ref,
    );
    region(
        "CLOSED_F32 motion, 1 pixel (n = 0)",
        (&update, &axis),
        |(u, p)| CLOSED_F32.motion(u, p),
    );
    region(
        "CLOSED_F32 motion, 1 pixel (n = +30000, near-limb form)",
        (&update, &edge),
        |(u, p)| CLOSED_F32.motion(u, p),
    );
    region(
        "CLOSED_F32 motion + |v| + line period + ticks, 1 pixel (n = 0; the firmware's per-point work)",
        (&update, &axis),
        |(u, p)| -> Result<u32, FirmwareError> {
            let speed = CLOSED_F32.motion(u, p)?.speed_mps();
            let period = core_math::sphere::speed_line_period_s(CAMERA.pixel_m as f32, speed)?;
            Ok(core_math::line_period_ticks(period, LINE_CLOCK_HZ)?.ticks)
        },
    );
    region(
        "libm::asin in f64 (soft float): the limb angle, part of CLOSED_F32 update",
        1.0 / (1.0 + 645e3 / 6_370e3),
        libm::asin,
    );
    region(
        "core_math::trig::sin_cos_f32 (one call; CLOSED_F32 update makes four)",
        0.436_332_3_f32,
        core_math::trig::sin_cos_f32,
    );
    region("CLOSED_F32 update (once per telemetry update)", &g32, |g| {
        CLOSED_F32.update(g)
    });
    region(
        "CLOSED_F32 pixel (boot, f64 inside), 1 pixel",
        &camera,
        |c| CLOSED_F32.pixel(c, 12_345.0),
    );
    region(
        "CLOSED_F64 motion, 1 pixel (n = 0)",
        (&update64, &axis64),
        |(u, p)| CLOSED_F64.motion(u, p),
    );
    region("CLOSED_F64 update", &g64, |g| CLOSED_F64.update(g));
    region(
        "Reference motion (f64 chain), 1 pixel (n = 0)",
        (&g64, &ref_pixel),
        |(g, p)| Reference.motion(g, p),
    );
    region(
        "FIXED motion, 1 pixel (n = 0; integer only)",
        (&update_fx, &axis_fx),
        |(u, p)| FIXED.motion(u, p),
    );
    region(
        "FIXED motion, 1 pixel (n = +30000)",
        (&update_fx, &edge_fx),
        |(u, p)| FIXED.motion(u, p),
    );
    region(
        "FIXED motion, 1 pixel (roll 45 deg, n = +15735: 9.7e-5 rad from the limb, near-limb form)",
        (&update_fx45, &near_fx),
        |(u, p)| FIXED.motion(u, p),
    );
    region(
        "FIXED update (once per telemetry update; integer only)",
        &gfx,
        |g| FIXED.update(g),
    );
    scene_kinds()?;
    earth_regions()?;
    dem_regions()?;
    region(
        "NaiveF32 motion, 1 pixel (n = 0)",
        (&update_naive, &axis_naive),
        |(u, p)| NaiveF32.motion(u, p),
    );
    region(
        "NaiveF32 motion, 1 pixel (n = +30000)",
        (&update_naive, &edge_naive),
        |(u, p)| NaiveF32.motion(u, p),
    );
    region(
        "NaiveF32 update (checks and stores the geometry)",
        &g32,
        |g| NaiveF32.update(g),
    );
    region(
        "Reference update (checks and stores the geometry)",
        &g64,
        |g| Reference.update(g),
    );
    Ok(())
}

#[entry]
fn main() -> ! {
    let code = match run() {
        Ok(()) => 0,
        Err(e) => {
            defmt::error!("{}", e);
            1
        }
    };
    platform::exit(code)
}
