//! Golden values for the on-target tests, computed here on the host at build time.
//!
//! Every expected number but the MTF's comes from `core-math` itself (a build-dependency),
//! for its round-Earth model (`core_math::sphere`): the f64 `Reference` chain,
//! `line_period_*::<f64>`, and, for the bit-identity tests, the same `CLOSED_F32` path
//! run on the host. Inputs are rounded to f32 first and the references are evaluated at
//! exactly those values widened back to f64, so a comparison measures the algorithm,
//! not the input rounding. Tolerances come from `core_math::sphere::accuracy`. Nothing here is typed by hand but the case list.
//! The MTF's expectation is its definition, |sin(x)/x| with libm's sine, not
//! core-math's `mtf_mismatch` (issue 25: a definition both sides shared went unseen).
//!
//! The controller's cases (`src/controller_cases.rs`, included here and on the target)
//! get theirs from `controller::golden`: the f64 reference of a whole update (Kepler
//! propagation, the attitude at its rates in f64, the dual-number construction of the
//! real-Earth model), independent of the f32 general form the target runs.
//!
//! Output: `$OUT_DIR/golden.rs`, included by `src/lib.rs`; and `$OUT_DIR/memory.x`, the
//! selected board's memory layout.

use std::fmt::Write as _;

use core_math::sphere::accuracy::{f32_rel_tolerance, limb_margin_rad, F32_V2_TOLERANCE};
use core_math::sphere::speed_line_period_s;
use core_math::sphere::{Geometry, Reference, CLOSED_F32};
use core_math::{line_period_ticks, mtf_mismatch, Backend, Camera, ImageMotion, ModelError};

/// The paper's camera and orbit (the firmware's default scene).
const FOCAL_M: f64 = 0.555;
const PIXEL_M: f64 = 13.0e-6;
const ALTITUDE_M: f64 = 645.0e3;
const EARTH_RADIUS_M: f64 = 6_370.0e3;
const INCLINATION_DEG: f64 = 97.98;
const ROLL_DEG: f64 = 25.0;
const LINE_CLOCK_HZ: f64 = 10.0e6;

/// Absolute tolerance of the f32 MTF against the f64 one (MTF is of order 1; the f32
/// sinc polynomial is good to a few ulp of 1, see core-math's mtf.rs).
const MTF_ABS_TOLERANCE: f64 = 1.0e-6;
/// Relative error the f32 line period adds on top of |v|'s: rounding the pixel pitch to
/// f32 and one division (2 x 2^-24), with margin.
const PERIOD_EXTRA_REL: f64 = 2.5e-7;
/// Relative error of rounding period * clock in f32 before taking the nearest tick.
const TICKS_EXTRA_REL: f64 = 1.5e-7;

struct MotionCase {
    group: &'static str,
    name: String,
    camera: Camera,
    geometry: Geometry<f32>,
    n_px: f64,
}

fn paper_camera() -> Camera {
    Camera {
        focal_m: FOCAL_M,
        pixel_m: PIXEL_M,
    }
}

fn geometry(roll_deg: f64, incl_deg: f64, gamma_deg: f64) -> Geometry<f32> {
    Geometry::circular(
        roll_deg.to_radians(),
        incl_deg.to_radians(),
        gamma_deg.to_radians(),
        ALTITUDE_M,
        EARTH_RADIUS_M,
    )
    .to::<f32>()
}

fn motion_cases() -> Vec<MotionCase> {
    let camera = paper_camera();
    let mut cases = Vec::new();
    let mut push = |group: &'static str, name: String, g: Geometry<f32>, n_px: f64| {
        cases.push(MotionCase {
            group,
            name,
            camera,
            geometry: g,
            n_px,
        })
    };
    // The default scene's sample points: every segment's edges and centre.
    let scene = geometry(ROLL_DEG, INCLINATION_DEG, 0.0);
    for j in 0..=20 {
        let n = -30_000 + 3_000 * j;
        push(
            "default",
            format!("default scene n={n}"),
            scene,
            f64::from(n),
        );
    }
    // Near the limb: the roll that puts the axis pixel 1 deg and 0.1 deg inside the
    // limb (left and right), computed from the model's own limb angle.
    let nadir = geometry(0.0, INCLINATION_DEG, 0.0).to_f64();
    let limb_deg = limb_margin_rad(&camera, &nadir, 0.0)
        .map(f64::to_degrees)
        .unwrap_or(f64::NAN);
    for margin in [1.0, 0.1] {
        for sign in [1.0, -1.0] {
            let roll = sign * (limb_deg - margin);
            push(
                "stiff",
                format!("limb {margin} deg inside, roll {roll:.4} deg"),
                geometry(roll, INCLINATION_DEG, 0.0),
                0.0,
            );
        }
    }
    // The edge pixel of the default camera rolled so that it sees 0.5 deg inside the limb.
    let edge_field_deg = (30_000.0 * PIXEL_M / FOCAL_M).atan().to_degrees();
    push(
        "stiff",
        "edge pixel n=30000 0.5 deg inside the limb".into(),
        geometry(limb_deg - 0.5 - edge_field_deg, INCLINATION_DEG, 0.0),
        30_000.0,
    );
    push(
        "stiff",
        "nadir (roll 0, n 0)".into(),
        geometry(0.0, INCLINATION_DEG, 0.0),
        0.0,
    );
    for (incl, label) in [(0.0, "i0 = 0"), (180.0, "i0 = 180 deg")] {
        for n in [0.0, 30_000.0, -30_000.0] {
            push(
                "stiff",
                format!("{label}, n={n}"),
                geometry(ROLL_DEG, incl, 0.0),
                n,
            );
        }
    }
    for n in [0.0, 30_000.0] {
        push(
            "stiff",
            format!("gamma0 = 90 deg, n={n}"),
            geometry(ROLL_DEG, INCLINATION_DEG, 90.0),
            n,
        );
    }
    push(
        "stiff",
        "polar orbit over the equator, gamma0 = 180 deg".into(),
        geometry(-10.0, 90.0, 180.0),
        -12_345.0,
    );
    // Refusals: beyond the limb, above the horizon, a non-finite input.
    push(
        "refused",
        "beyond the limb by 1 deg".into(),
        geometry(limb_deg + 1.0, INCLINATION_DEG, 0.0),
        0.0,
    );
    push(
        "refused",
        "edge pixel beyond the limb (roll 35 deg, n=30000)".into(),
        geometry(35.0, INCLINATION_DEG, 0.0),
        30_000.0,
    );
    push(
        "refused",
        "above the horizon (roll 100 deg)".into(),
        geometry(100.0, INCLINATION_DEG, 0.0),
        0.0,
    );
    let mut nan = geometry(ROLL_DEG, INCLINATION_DEG, 0.0);
    nan.altitude_m = f32::NAN;
    push("refused", "altitude NaN".into(), nan, 0.0);
    cases
}

/// A `ModelError` as Rust source.
fn error_src(e: ModelError) -> String {
    let debug = format!("{e:?}");
    match e.param() {
        Some(p) => {
            let variant = debug.split('(').next().unwrap_or(&debug);
            format!("ModelError::{variant}(Param::{p:?})")
        }
        None => format!("ModelError::{debug}"),
    }
}

fn f64_src(x: f64) -> String {
    format!("f64::from_bits({:#018x}) /* {x:e} */", x.to_bits())
}

fn f32_src(x: f32) -> String {
    format!("f32::from_bits({:#010x}) /* {x:e} */", x.to_bits())
}

fn str_src(s: &str) -> String {
    format!("{s:?}")
}

fn geometry_src(g: &Geometry<f32>) -> String {
    format!(
        "Geometry {{ roll_rad: {}, inclination_rad: {}, arg_latitude_rad: {}, altitude_m: {}, earth_radius_m: {}, earth_rate_rad_s: {}, orbit_rate_rad_s: {} }}",
        f32_src(g.roll_rad),
        f32_src(g.inclination_rad),
        f32_src(g.arg_latitude_rad),
        f32_src(g.altitude_m),
        f32_src(g.earth_radius_m),
        f32_src(g.earth_rate_rad_s),
        f32_src(g.orbit_rate_rad_s),
    )
}

/// The f64 expectation of one motion case.
fn expected_motion(c: &MotionCase) -> String {
    let g64 = c.geometry.to_f64();
    let reference = Reference.evaluate(&c.camera, &g64, c.n_px);
    let tol = f32_rel_tolerance(&c.camera, &g64, c.n_px);
    match (reference, tol) {
        (Ok(m), Ok(rel_tol)) => {
            let speed = m.speed_mps();
            let period = PIXEL_M / speed;
            let period_tol = rel_tol + PERIOD_EXTRA_REL;
            format!(
                "Expected::Motion(RefMotion {{ v1_mps: {}, v2_mps: {}, speed_mps: {}, rel_tol: {}, v2_tol_of_speed: {}, period_s: {}, period_rel_tol: {}, exact_ticks: {}, ticks_rel_tol: {} }})",
                f64_src(m.v1_mps),
                f64_src(m.v2_mps),
                f64_src(speed),
                f64_src(rel_tol),
                f64_src(F32_V2_TOLERANCE),
                f64_src(period),
                f64_src(period_tol),
                f64_src(period * LINE_CLOCK_HZ),
                f64_src(period_tol + TICKS_EXTRA_REL),
            )
        }
        (Err(e), _) | (Ok(_), Err(e)) => format!("Expected::Err({})", error_src(e)),
    }
}

/// The same case through `CLOSED_F32` on the host: v1, v2, |v|, period, ticks.
fn host_f32_motion(c: &MotionCase) -> String {
    let m: Result<ImageMotion<f32>, ModelError> =
        CLOSED_F32.evaluate(&c.camera, &c.geometry, c.n_px);
    match m {
        Ok(m) => {
            let speed = m.speed_mps();
            let period = speed_line_period_s(PIXEL_M as f32, speed);
            let ticks = period.and_then(|p| line_period_ticks(p, LINE_CLOCK_HZ as f32));
            let period_src = match period {
                Ok(p) => format!("Ok({})", f32_src(p)),
                Err(e) => format!("Err({})", error_src(e)),
            };
            let ticks_src = match ticks {
                Ok(t) => format!("Ok({})", t.ticks),
                Err(e) => format!("Err({})", error_src(e)),
            };
            format!(
                "HostF32::Motion {{ v1_mps: {}, v2_mps: {}, speed_mps: {}, period_s: {period_src}, ticks: {ticks_src} }}",
                f32_src(m.v1_mps),
                f32_src(m.v2_mps),
                f32_src(speed),
            )
        }
        Err(e) => format!("HostF32::Err({})", error_src(e)),
    }
}

fn write_motion_cases(out: &mut String) {
    out.push_str("/// Image-motion cases: f32 inputs, f64 reference, host CLOSED_F32 bits.\npub static MOTION_CASES: &[MotionCase] = &[\n");
    for c in motion_cases() {
        let _ = writeln!(
            out,
            "    MotionCase {{\n        group: {},\n        name: {},\n        camera: Camera {{ focal_m: {}, pixel_m: {} }},\n        geometry: {},\n        n_px: {},\n        expected: {},\n        host_f32: {},\n    }},",
            str_src(c.group),
            str_src(&c.name),
            f64_src(c.camera.focal_m),
            f64_src(c.camera.pixel_m),
            geometry_src(&c.geometry),
            f64_src(c.n_px),
            expected_motion(&c),
            host_f32_motion(&c),
        );
    }
    out.push_str("];\n\n");
}

fn write_mtf_cases(out: &mut String) {
    out.push_str("/// MTF_mismatch cases: f32 relative mismatch, f64 expectation, host f32 bits.\npub static MTF_CASES: &[MtfCase] = &[\n");
    for stages in [1_u32, 8, 16, 32, 64, 96, 128] {
        for rel in [
            0.0_f64, 1.0e-4, 1.0e-3, -2.5e-3, 5.0e-3, 0.01, -0.01, 0.02, 0.05,
        ] {
            let rel32 = rel as f32;
            // The MTF's definition, |sin(x)/x| at x = pi/2 M dv/v, in f64 with libm:
            // not the function under test (its f64 form included).
            let x = core::f64::consts::FRAC_PI_2 * f64::from(stages) * f64::from(rel32);
            let expected: Result<f64, ModelError> = Ok(if x == 0.0 {
                1.0
            } else {
                libm::fabs(libm::sin(x) / x)
            });
            let host = mtf_mismatch::<f32>(stages, rel32);
            let expected_src = match expected {
                Ok(v) => format!("Ok({})", f64_src(v)),
                Err(e) => format!("Err({})", error_src(e)),
            };
            let host_src = match host {
                Ok(v) => format!("Ok({})", f32_src(v)),
                Err(e) => format!("Err({})", error_src(e)),
            };
            let _ = writeln!(
                out,
                "    MtfCase {{ stages: {stages}, rel_mismatch: {}, expected: {expected_src}, abs_tol: {}, host_f32: {host_src} }},",
                f32_src(rel32),
                f64_src(MTF_ABS_TOLERANCE),
            );
        }
    }
    out.push_str("];\n\n");
}

fn write_tick_cases(out: &mut String) {
    out.push_str("/// line_period_ticks cases: f32 inputs, f64 expectation, host f32 result.\npub static TICK_CASES: &[TickCase] = &[\n");
    let cases: [(f64, f64); 10] = [
        (1.0e-4, 10.0e6),
        (2.438_378_4e-3, 10.0e6),
        (4.547_139_6e-3, 10.0e6),
        (1.814_648_6e-3, 32.0e6),
        (0.15e-6, 10.0e6),
        (1.0e-8, 10.0e6),
        (1.0e3, 10.0e6),
        (0.0, 10.0e6),
        (-1.0e-3, 10.0e6),
        (1.0e-3, 0.0),
    ];
    for (period, clock) in cases {
        let (p32, c32) = (period as f32, clock as f32);
        let expected = line_period_ticks::<f64>(f64::from(p32), f64::from(c32));
        let host = line_period_ticks::<f32>(p32, c32);
        let expected_src = match expected {
            Ok(_) => format!("Ok({})", f64_src(f64::from(p32) * f64::from(c32))),
            Err(e) => format!("Err({})", error_src(e)),
        };
        let host_src = match host {
            Ok(t) => format!("Ok(({}, {}))", t.ticks, f32_src(t.rounding_error_s)),
            Err(e) => format!("Err({})", error_src(e)),
        };
        let _ = writeln!(
            out,
            "    TickCase {{ period_s: {}, clock_hz: {}, exact_ticks: {expected_src}, rel_tol: {}, host_f32: {host_src} }},",
            f32_src(p32),
            f32_src(c32),
            f64_src(TICKS_EXTRA_REL),
        );
    }
    out.push_str("];\n");
}

#[path = "src/controller_cases.rs"]
mod controller_cases;

/// Each controller case's golden update, from the host's plan of its scene (the target
/// checks that its own plan samples the same pixels).
fn write_controller_cases(out: &mut String) {
    use controller::golden::{update, NavInput};
    use controller::plan::Plan;
    use controller::Config;
    out.push_str("/// The controller cases' golden updates, in the order of `controller_cases::case`.\npub static CONTROLLER_GOLDEN: &[UpdateGolden] = &[\n");
    for k in 0..controller_cases::CASE_COUNT {
        let c = controller_cases::case(k).expect("CASE_COUNT cases");
        let plan = Plan::new(&c.scene, &Config::default())
            .unwrap_or_else(|f| panic!("case {}: scene refused: {f:?}", c.name));
        let heights: Vec<f32> = match c.terrain_m {
            Some(h) => h.to_vec(),
            None => c.scene.segments.iter().map(|s| s.ground_h_m).collect(),
        };
        let nav = NavInput {
            state: c.state,
            attitude: c.attitude,
            time_us: c.nav_time_us,
        };
        let g = update(&c.scene, &plan, &heights, &nav, c.update_time_us)
            .unwrap_or_else(|e| panic!("case {}: no reference: {e:?}", c.name));
        let mut segments = String::new();
        for (s, seg) in g.segments.iter().flatten().zip(plan.active()) {
            assert_eq!(s.index, seg.index);
            let _ = write!(
                segments,
                "SegmentGold {{ index: {}, samples: {}, ticks_exact: {}, drift_rad: {} }}, ",
                s.index,
                seg.samples.len(),
                f64_src(s.ticks_exact),
                f64_src(s.drift_rad),
            );
        }
        let yaw = match g.yaw_request_rad {
            Some(y) => format!("Some({})", f64_src(y)),
            None => "None".into(),
        };
        let _ = writeln!(
            out,
            "    UpdateGolden {{ name: {}, segments: &[{segments}], yaw_request_rad: {yaw} }},",
            str_src(c.name)
        );
    }
    out.push_str("];\n");
}

// The board's memory layout, as the firmware selects it (docs/target.md, "Boards").
include!("../firmware/memory/select.rs");

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=src/controller_cases.rs");
    println!("cargo:rerun-if-changed=../firmware/memory/select.rs");
    select_memory_x(std::path::Path::new("../firmware/memory"));
    let mut out = String::from(
        "// @generated by hil-tests/build.rs from core-math on the host. Do not edit.\n\n",
    );
    let _ = writeln!(
        out,
        "/// The line clock of the default scene (Hz).\npub const LINE_CLOCK_HZ: f32 = {};\n",
        f32_src(LINE_CLOCK_HZ as f32)
    );
    write_motion_cases(&mut out);
    write_mtf_cases(&mut out);
    write_tick_cases(&mut out);
    write_controller_cases(&mut out);
    let dir = std::env::var_os("OUT_DIR").expect("cargo sets OUT_DIR for build scripts");
    let path = std::path::Path::new(&dir).join("golden.rs");
    std::fs::write(&path, out).expect("cannot write golden.rs");
}
