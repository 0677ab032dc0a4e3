//! Flash footprint of one backend, for the `flash_bytes` column of `cargo xtask report`.
//!
//! Built once per variant with `--cfg footprint="<variant>"` (and once with "none"):
//! the variant's build calls that backend's `pixel`, `update` and `motion` on inputs the
//! optimiser cannot see (`black_box`) and keeps the result; "none" only touches the
//! inputs. Everything else (runtime, logger, exit) is common to both, so the difference
//! of the two images' loadable sections is the code and constant data that backend
//! brings into a binary. Never run; only linked and measured.
#![no_std]
#![no_main]

use core::hint::black_box;

#[allow(unused_imports)]
use core_math::earth::{circular_state, Attitude, EarthCamera, EarthGeometry, Ellipsoid};
use core_math::sphere::{Geometry, Sphere};
#[allow(unused_imports)]
use core_math::{Backend, Camera, Earth};
use cortex_m_rt::entry;
use firmware::platform;

/// 645 km circular orbit, roll 20 deg (values only; they reach the code through
/// `black_box`).
const GEOMETRY: Geometry<f64> = Geometry {
    roll_rad: 0.349_065_850_398_865_9,
    inclination_rad: 1.710_073_105_064_591,
    arg_latitude_rad: 0.5,
    altitude_m: 645e3,
    earth_radius_m: 6_371e3,
    earth_rate_rad_s: core_math::EARTH_RATE_RAD_S,
    orbit_rate_rad_s: 1.077e-3,
};

/// Boot, update and per-pixel work of `backend`, the result kept.
#[allow(dead_code)]
fn exercise<B: Backend<Sphere>>(backend: &B, g: &Geometry<B::Real>) {
    let camera = black_box(Camera {
        focal_m: 0.555,
        pixel_m: 13e-6,
    });
    let n_px = black_box(12_345.0);
    if let (Ok(p), Ok(u)) = (backend.pixel(&camera, n_px), backend.update(black_box(g))) {
        let _kept = black_box(backend.motion(&u, &p));
    }
}

/// The same for a real-Earth backend: the default orbit over WGS 84, an agile attitude.
#[allow(dead_code)]
fn exercise_earth<B: Backend<Earth>>(
    backend: &B,
    to: impl Fn(EarthGeometry<f64>) -> Option<EarthGeometry<B::Real>>,
) {
    let g = black_box(EarthGeometry {
        state: circular_state(7_023_137.0, 1.710_073_105_064_591, 0.5),
        attitude: Attitude {
            roll_rad: 0.35,
            pitch_rad: -0.1,
            yaw_rad: 0.05,
            roll_rate_rad_s: 0.01,
            pitch_rate_rad_s: 0.0,
            yaw_rate_rad_s: 0.0,
        },
        ground_h_m: 1_000.0,
        ellipsoid: Ellipsoid::WGS84,
        earth_rate_rad_s: core_math::EARTH_RATE_RAD_S,
    });
    let camera = black_box(EarthCamera {
        focal_m: 0.555,
        pixel_m: 13e-6,
        p1_m: 0.0,
    });
    let n_px = black_box(12_345.0);
    let Some(g) = to(g) else { return };
    if let (Ok(p), Ok(u)) = (backend.pixel(&camera, n_px), backend.update(&g)) {
        let _kept = black_box(backend.motion(&u, &p));
    }
}

#[entry]
fn main() -> ! {
    #[allow(unused_variables)] // "none" keeps only the input
    let g = black_box(GEOMETRY);
    #[cfg(footprint = "naive-f32")]
    exercise(&core_math::sphere::NaiveF32, &g.to());
    #[cfg(footprint = "reference")]
    exercise(&core_math::sphere::Reference, &g);
    #[cfg(footprint = "f64")]
    exercise(&core_math::sphere::CLOSED_F64, &g);
    #[cfg(footprint = "f32")]
    exercise(&core_math::sphere::CLOSED_F32, &g.to());
    #[cfg(footprint = "f32-micromath")]
    exercise(&core_math::sphere::CLOSED_MICROMATH, &g.to());
    #[cfg(footprint = "fixed")]
    if let Ok(gq) = core_math::sphere::fixed_point::geometry_from_f64(&g) {
        exercise(&core_math::sphere::FIXED, &gq);
    }
    #[cfg(footprint = "earth-reference")]
    exercise_earth(&core_math::EarthReference, Some);
    #[cfg(footprint = "earth-f64")]
    exercise_earth(&core_math::GENERAL_F64, Some);
    #[cfg(footprint = "earth-f32")]
    exercise_earth(&core_math::GENERAL_F32, |g| Some(g.to()));
    #[cfg(footprint = "earth-fixed")]
    exercise_earth(&core_math::EARTH_FIXED, |g| {
        core_math::earth::fixed::geometry_from_f64(&g).ok()
    });
    platform::exit(0)
}
