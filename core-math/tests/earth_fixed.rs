//! The real-Earth fixed-point backend (`EARTH_FIXED`) against the construction on dual
//! numbers (`EarthReference`, the golden source): per hit within the error bound argued
//! in `docs/fixed-point.md` ("The real-Earth backend"), within the targets by
//! distance to the limb, and the same refusals as the general form.
//!
//! The reference is evaluated at the backend's own inputs (the attitude rounded to
//! I24F40, widened back), as for the round Earth's fixed backend; the pixel is not
//! rounded for the reference, so the bound counts the rounding of t = p/f.
//!
//! `cargo test` builds core-math with overflow checks and debug assertions: every draw
//! below also checks the range analysis (any wrap panics).

use core_math::accuracy::{earth_kappa, EARTH_F32_KAPPA_LIMIT};
use core_math::earth::fixed::{geometry_from_f64, motion_to_f64};
use core_math::earth::{limb_margin_rad, Attitude, EarthCamera, EarthGeometry};
use core_math::sample::{EarthCase, SplitMix64};
use core_math::{
    Backend, EarthReference, Ellipsoid, ImageMotion, ModelError, Param, EARTH_FIXED, GENERAL_F64,
};

/// Within this margin of the limb (deg) a backend may report a hit or a miss
/// (EARTH-MODEL.md).
const EITHER_DEG: f64 = 1e-4;

/// The targets: relative error of |v| from 1 deg inside the limb outward, and
/// from 0.01 deg, where the problem's condition number is at most
/// `EARTH_F32_KAPPA_LIMIT` (30; as for the f32 form, `core_math::accuracy`): beyond it
/// the problem amplifies the roundings of any finite format (rates cancelling most of
/// the image motion), and the per-hit bound is what holds.
const FAR_TARGET: f64 = 2e-6;
const NEAR_TARGET: f64 = 2e-5;

/// The target of a hit at `margin_deg`, if any.
fn target(margin_deg: f64) -> Option<f64> {
    if margin_deg >= 1.0 {
        Some(FAR_TARGET)
    } else if margin_deg >= 0.01 {
        Some(NEAR_TARGET)
    } else {
        None
    }
}

/// Asserts the target of a hit with error `e`: met, or the case is ill-conditioned
/// (kappa computed only then: it costs 36 reference evaluations).
fn assert_target(c: &EarthCase, margin_deg: f64, e: f64) {
    if let Some(t) = target(margin_deg) {
        if e > t {
            let kappa = earth_kappa(&c.camera, &c.geometry, c.n_px).unwrap();
            assert!(
                kappa > EARTH_F32_KAPPA_LIMIT,
                "{e:e} at {margin_deg} deg, kappa {kappa}: {c:?}"
            );
        }
    }
}

/// The reference's own error against the exact value (the general f64 form and the
/// reference agree within 1e-12: `tests/earth.rs`).
const REFERENCE_SLACK: f64 = 1e-11;

fn sci(x: &[f64]) -> String {
    x.iter()
        .map(|v| format!("{v:.2e}"))
        .collect::<Vec<_>>()
        .join(" ")
}

fn p2(n: i32) -> f64 {
    2f64.powi(n)
}

fn margin_deg(c: &EarthCase) -> f64 {
    limb_margin_rad(&c.geometry, &c.camera, c.n_px)
        .unwrap()
        .to_degrees()
}

/// |dv| / |v_ref|.
fn rel(m: &ImageMotion<f64>, r: &ImageMotion<f64>) -> f64 {
    libm::hypot(m.v1_mps - r.v1_mps, m.v2_mps - r.v2_mps) / libm::hypot(r.v1_mps, r.v2_mps)
}

/// The bound of `docs/fixed-point.md` on |dv| / |v| for one hit, from the exact (f64)
/// per-update quantities of the general form: each rounding of the formats times what
/// multiplies it, the discriminant's error through the square root, the focal length's
/// mantissa and the output's last bit.
fn bound(c: &EarthCase, g: &EarthGeometry<f64>, v_ref: &ImageMotion<f64>) -> f64 {
    let up = GENERAL_F64.update(g).unwrap();
    let p = g.state.position_m;
    let r = libm::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    let (p1, p2m) = c.camera.focal_plane_m(c.n_px).unwrap();
    let f = c.camera.focal_m;
    let t = [p1 / f, p2m / f, -1.0];
    let rho = up.rho_b_m.map(|x| x / r);
    let n = up.n_b;
    let cc = up.c_m2 / (r * r);
    let k = up.stretch2_minus_1;
    let w = up.w_b_rad_s;
    let v = up.v_b_mps.map(|x| x / r);
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let beta = dot(rho, t);
    let nu = dot(n, t);
    let alpha = 1.0 + t[0] * t[0] + t[1] * t[1] + k * nu * nu;
    let disc = (beta * beta - alpha * cc).max(0.0);
    let num = disc.sqrt() - beta;
    let inv_s = num / cc;

    // Inputs of beta: Q30 roundings of rho (per component) and t; |beta| to Q31.
    let sum_t = t[0].abs() + t[1].abs() + 1.0;
    let d_beta = sum_t * p2(-31) + (rho[0].abs() + rho[1].abs()) * p2(-31) + p2(-32);
    // m.u' (m = sqrt(k) n): m's Q33 roundings, t's, the rounding to Q31.
    let m = n.map(|x| libm::sqrt(k) * x);
    let s = dot(m, t);
    let d_s = sum_t * p2(-34) + (m[0].abs() + m[1].abs()) * p2(-31) + p2(-32);
    // alpha: |u'|^2 rounded, the square of m.u' floored to Q30.
    let d_alpha = p2(-31) + p2(-30) + 2.0 * s.abs() * d_s + d_s * d_s;
    let d_disc = 2.0 * beta.abs() * d_beta + d_beta * d_beta + cc * d_alpha + alpha * p2(-33);
    let d_root = (d_disc / disc.sqrt()).min(d_disc.sqrt()) + 2.0 * p2(-31);
    let d_num = d_root + d_beta + p2(-30);
    // 1/sigma: num x (|r|^2 / C, Q27), rounded to Q24.
    let d_inv_s = d_num / cc + num * p2(-28) + p2(-25);
    // V_k + t_k V3 (V in Q40, t in Q30) rounded to Q39, times 1/sigma exactly.
    let d_v = |k: usize| {
        let p = v[k] + t[k] * v[2];
        let d_p = (1.0 + t[k].abs()) * p2(-41) + v[2].abs() * p2(-31) + p2(-40);
        p.abs() * d_inv_s + inv_s * d_p + d_p * d_inv_s
    };
    let sum_w = w[0].abs() + w[1].abs() + w[2].abs();
    let d_w_terms = 4.0 * p2(-34) + sum_w * p2(-31);
    let (d1, d2) = (d_w_terms + d_v(0), d_w_terms + d_v(1));
    let speed = libm::hypot(v_ref.v1_mps, v_ref.v2_mps);
    // f (d1 + d2), the mantissa of f (2^-32 relative), two floors of 2^-40 m/s each.
    (f * (d1 + d2) + 2.0 * p2(-40) * 2.0) / speed + p2(-32)
}

/// One comparison: the fixed backend and the reference at its inputs.
struct Outcome {
    margin_deg: f64,
    fixed: Result<ImageMotion<f64>, ModelError>,
    reference: Result<ImageMotion<f64>, ModelError>,
    general: Result<ImageMotion<f64>, ModelError>,
    /// (error, bound) where both hit.
    err: Option<(f64, f64)>,
}

fn compare(c: &EarthCase) -> Outcome {
    let g = geometry_from_f64(&c.geometry).unwrap();
    let gw = g.to_f64();
    let fixed = EARTH_FIXED
        .evaluate(&c.camera, &g, c.n_px)
        .map(|m| motion_to_f64(&m));
    let reference = EarthReference.evaluate(&c.camera, &gw, c.n_px);
    let general = GENERAL_F64.evaluate(&c.camera, &gw, c.n_px);
    let err = match (&fixed, &reference) {
        (Ok(x), Ok(r)) => {
            let case = EarthCase { geometry: gw, ..*c };
            Some((rel(x, r), bound(&case, &gw, r) + REFERENCE_SLACK))
        }
        _ => None,
    };
    Outcome {
        margin_deg: margin_deg(c),
        fixed,
        reference,
        general,
        err,
    }
}

/// Limb bands (deg, lower edges) of the tables in docs/fixed-point.md.
const BANDS_DEG: [f64; 7] = [1.0, 0.1, 0.01, 1e-3, 1e-4, 1e-5, 0.0];

fn band(margin_deg: f64) -> usize {
    BANDS_DEG
        .iter()
        .position(|&b| margin_deg >= b)
        .unwrap_or(BANDS_DEG.len() - 1)
}

/// Random draws over the real-Earth envelope (`SplitMix64::earth_case`: 200-2 000 km,
/// eccentric, roll and pitch to 45 deg, any yaw, rates to 2 deg/s, terrain, one draw in
/// four 0.001-3 deg from a limb): every hit within its bound and the targets, every
/// refusal the general form's (a hit/miss disagreement only within 1e-4 deg of the
/// limb), nothing refused for the envelope.
#[test]
fn fixed_matches_the_reference_over_the_envelope() {
    let mut rng = SplitMix64(0x0EA7_2026_1126_0F1C);
    let (mut hits, mut misses, mut worst_ratio) = (0, 0, 0f64);
    let mut worst = [0f64; BANDS_DEG.len()];
    for _ in 0..30_000 {
        let Some(c) = rng.earth_case() else { continue };
        let o = compare(&c);
        let m = o.margin_deg;
        match (&o.fixed, &o.reference) {
            (Ok(_), Ok(r)) => {
                let (e, b) = o.err.unwrap();
                assert!(e <= b, "{e:e} > bound {b:e} at {m} deg: {c:?}");
                // Part II's entry (the same instant as the camera's axes in I) within the
                // same bound: its update differs from Part I's by f64 roundings only.
                let gw = geometry_from_f64(&c.geometry).unwrap().to_f64();
                let up = EARTH_FIXED.update_inertial(&gw.to_inertial().unwrap());
                let px = EARTH_FIXED.pixel(&c.camera, c.n_px).unwrap();
                let x2 = motion_to_f64(&EARTH_FIXED.motion(&up.unwrap(), &px).unwrap());
                let e2 = rel(&x2, r);
                assert!(e2 <= b, "Part II: {e2:e} > bound {b:e} at {m} deg: {c:?}");
                assert_target(&c, m, e);
                worst[band(m)] = worst[band(m)].max(e);
                worst_ratio = worst_ratio.max(e / b);
                hits += 1;
            }
            (Err(x), Err(_)) => {
                assert_eq!(Err(*x), o.general.map(|_| ()), "at {m} deg: {c:?}");
                misses += 1;
            }
            (x, r) => assert!(m.abs() < EITHER_DEG, "{x:?} / {r:?} at {m} deg: {c:?}"),
        }
    }
    println!(
        "fixed vs reference: {hits} hits, {misses} refused; worst by band {}; worst err/bound {worst_ratio:.2}",
        sci(&worst)
    );
    assert!(hits > 15_000 && misses > 300, "{hits} {misses}");
}

/// The table of docs/fixed-point.md ("The real-Earth backend", measured error):
/// `cargo test --release -p core-math --test earth_fixed -- --ignored --nocapture survey`.
/// The same draws as above, more of them, by limb band: cases, max and 99th percentile
/// of the relative error of |v|, the largest error over its bound.
#[test]
#[ignore]
fn survey() {
    let mut rng = SplitMix64(0x0EA7_2026_1126_5E7F);
    let mut errs: Vec<Vec<f64>> = vec![Vec::new(); BANDS_DEG.len()];
    let mut ratio = [0f64; BANDS_DEG.len()];
    let mut conditioned = [0f64; BANDS_DEG.len()];
    for _ in 0..400_000 {
        let Some(c) = rng.earth_case() else { continue };
        let o = compare(&c);
        if let Some((e, b)) = o.err {
            let k = band(o.margin_deg);
            errs[k].push(e);
            ratio[k] = ratio[k].max(e / b);
            // kappa only where it could change the column's maximum.
            if e > conditioned[k]
                && earth_kappa(&c.camera, &c.geometry, c.n_px).unwrap() <= EARTH_F32_KAPPA_LIMIT
            {
                conditioned[k] = e;
            }
        }
    }
    println!(
        "| limb margin (deg) | hits | max rel err \\|v\\| | max, kappa <= 30 | p99 | max err / bound |"
    );
    println!("|---|---|---|---|---|---|");
    for (k, v) in errs.iter_mut().enumerate() {
        v.sort_by(f64::total_cmp);
        let (max, p99) = match v.len() {
            0 => (0.0, 0.0),
            n => (v[n - 1], v[(n - 1) * 99 / 100]),
        };
        let hi = if k == 0 {
            "".to_string()
        } else {
            format!(" - {}", BANDS_DEG[k - 1])
        };
        println!(
            "| >= {}{hi} | {} | {max:.2e} | {:.2e} | {p99:.2e} | {:.2} |",
            BANDS_DEG[k],
            v.len(),
            conditioned[k],
            ratio[k]
        );
    }
}

/// A circular 645 km sun-synchronous orbit over the equator (the default scene's), nadir.
fn scene(altitude_m: f64, roll_deg: f64) -> EarthCase {
    let radius = Ellipsoid::WGS84.a_m + altitude_m;
    EarthCase {
        camera: EarthCamera {
            focal_m: 0.555,
            pixel_m: 13e-6,
            p1_m: 0.0,
        },
        geometry: EarthGeometry {
            state: core_math::earth::circular_state(radius, 97.98f64.to_radians(), 0.3),
            attitude: Attitude {
                roll_rad: roll_deg.to_radians(),
                ..Attitude::default()
            },
            ground_h_m: 0.0,
            ellipsoid: Ellipsoid::WGS84,
            earth_rate_rad_s: core_math::EARTH_RATE_RAD_S,
        },
        n_px: 0.0,
    }
}

/// A grid of scenes (altitudes 200-2 000 km, inclinations, positions along the orbit,
/// pitch, yaw and rates, both limbs), each with lines of sight at fixed distances from
/// the limb down to 1e-5 deg: the bound per hit, the targets per band.
#[test]
fn near_limb_grid_within_bound() {
    let mut worst = [0f64; BANDS_DEG.len()];
    let mut cases = [0usize; BANDS_DEG.len()];
    for (i, &alt_km) in [200.0f64, 645.0, 2000.0].iter().enumerate() {
        for (j, &incl_deg) in [0.0f64, 51.6, 97.98, 180.0].iter().enumerate() {
            for &arg in &[0.0, 1.2, 2.5, 4.0] {
                for &(pitch_deg, yaw_deg, rate_dps) in &[
                    (0.0f64, 0.0f64, 0.0f64),
                    (15.0, 30.0, 1.0),
                    (-30.0, -100.0, -2.0),
                ] {
                    for margin_deg in [3.0f64, 1.0, 0.1, 0.01, 1e-3, 1e-4, 1e-5] {
                        for side in [1.0, -1.0] {
                            let mut c = scene(alt_km * 1e3, 0.0);
                            let radius = Ellipsoid::WGS84.a_m + alt_km * 1e3;
                            c.geometry.state = core_math::earth::circular_state(
                                radius,
                                f64::to_radians(incl_deg),
                                arg,
                            );
                            c.n_px = (i as f64 - 1.0) * 20_000.0 + j as f64 * 3_000.0;
                            let a = &mut c.geometry.attitude;
                            a.pitch_rad = pitch_deg.to_radians();
                            a.yaw_rad = yaw_deg.to_radians();
                            a.roll_rate_rad_s = rate_dps.to_radians();
                            a.pitch_rate_rad_s = -rate_dps.to_radians();
                            a.yaw_rate_rad_s = 0.5 * rate_dps.to_radians();
                            let Some(roll) = core_math::sample::roll_at_limb_margin(
                                &c,
                                margin_deg.to_radians(),
                                side,
                            ) else {
                                continue;
                            };
                            c.geometry.attitude.roll_rad = roll;
                            let o = compare(&c);
                            let m = o.margin_deg;
                            let Some((e, b)) = o.err else {
                                assert!(m < EITHER_DEG, "{:?} at {m} deg: {c:?}", o.fixed);
                                continue;
                            };
                            assert!(e <= b, "{e:e} > bound {b:e} at {m} deg: {c:?}");
                            assert_target(&c, m, e);
                            worst[band(m)] = worst[band(m)].max(e);
                            cases[band(m)] += 1;
                        }
                    }
                }
            }
        }
    }
    println!("grid: cases by band {cases:?}, worst {}", sci(&worst));
    assert!(cases.iter().all(|&n| n >= 15), "{cases:?}");
}

/// The corners of the envelope, where the range analysis is tightest: C / |r|^2 at
/// both ends, every attitude rate at +/-0.04 rad/s, roll and pitch at 0 and +/-45 deg,
/// |p| / f at 0 and 1 on both axes, f at 0.01 and 1 000 m. In the test profile every
/// operation is overflow-checked: nothing may wrap; each hit within its bound, each
/// refusal the general form's (or within 1e-4 deg of the limb).
#[test]
fn corners_of_the_envelope() {
    let a = Ellipsoid::WGS84.a_m;
    let (mut hits, mut refused) = (0, 0);
    // C / |r|^2 = 1 - a^2 / r^2 on the equator: just inside 0.05 and 0.5.
    for c_over_r2 in [0.0505, 0.495] {
        let radius = a / libm::sqrt(1.0 - c_over_r2);
        for roll_deg in [-45.0f64, 0.0, 45.0] {
            for pitch_deg in [-45.0f64, 0.0, 45.0] {
                for (yaw_deg, sign) in [(0.0f64, 1.0), (90.0, -1.0)] {
                    for rate_sign in [1.0, -1.0] {
                        for focal_m in [0.01, 1000.0] {
                            for t1 in [-1.0, 0.0, 1.0] {
                                for t2 in [-1.0, 0.0, 1.0] {
                                    let mut c = scene(0.0, roll_deg);
                                    c.geometry.state =
                                        core_math::earth::circular_state(radius, 0.0, 0.7);
                                    let at = &mut c.geometry.attitude;
                                    at.pitch_rad = pitch_deg.to_radians();
                                    at.yaw_rad = yaw_deg.to_radians();
                                    at.roll_rate_rad_s = 0.04 * rate_sign;
                                    at.pitch_rate_rad_s = 0.04 * rate_sign * sign;
                                    at.yaw_rate_rad_s = -0.04 * rate_sign;
                                    c.camera = EarthCamera {
                                        focal_m,
                                        pixel_m: 1e-5,
                                        p1_m: t1 * focal_m,
                                    };
                                    c.n_px = t2 * focal_m / 1e-5;
                                    let o = compare(&c);
                                    match (&o.fixed, o.err) {
                                        (Ok(_), Some((e, b))) => {
                                            assert!(e <= b, "{e:e} > {b:e}: {c:?}");
                                            hits += 1;
                                        }
                                        (Err(x), _) => {
                                            // A v1 within the backend's error of 0
                                            // (a symmetric case's exact 0) may come out
                                            // as 0: no motion.
                                            let tiny = match (x, o.general) {
                                                (ModelError::NoAlongTrackMotion, Ok(g)) => {
                                                    let gw = geometry_from_f64(&c.geometry)
                                                        .unwrap()
                                                        .to_f64();
                                                    let speed = libm::hypot(g.v1_mps, g.v2_mps);
                                                    g.v1_mps.abs() <= bound(&c, &gw, &g) * speed
                                                }
                                                _ => false,
                                            };
                                            assert!(
                                                o.general.map(|_| ()) == Err(*x)
                                                    || o.margin_deg.abs() < EITHER_DEG
                                                    || tiny,
                                                "{x:?} / {:?}: {c:?}",
                                                o.general
                                            );
                                            refused += 1;
                                        }
                                        (Ok(_), None) => assert!(
                                            o.margin_deg.abs() < EITHER_DEG,
                                            "{:?}: {c:?}",
                                            o.reference
                                        ),
                                    }
                                }
                            }
                        }
                    }
                }
            }
        }
    }
    println!("corners: {hits} hits, {refused} refused");
    assert!(hits > 300 && refused > 100, "{hits} {refused}");
}

/// The contract's refusals, each the general form's, and the envelope's own.
#[test]
fn typed_refusals() {
    let base = scene(645e3, 0.0);
    let both = |c: &EarthCase| {
        let g = geometry_from_f64(&c.geometry).unwrap();
        let fixed = EARTH_FIXED.evaluate(&c.camera, &g, c.n_px).map(|_| ());
        let general = GENERAL_F64
            .evaluate(&c.camera, &g.to_f64(), c.n_px)
            .map(|_| ());
        (fixed, general)
    };
    // Beyond the limb, inside the Earth, a degenerate state, a bad focal length.
    let mut beyond = base;
    beyond.geometry.attitude.roll_rad = 70f64.to_radians();
    let mut inside = base;
    inside.geometry.state.position_m = [6.0e6, 0.0, 0.0];
    let mut degenerate = base;
    degenerate.geometry.state.velocity_mps = [7.5e3, 0.0, 0.0];
    degenerate.geometry.state.position_m = [7.0e6, 0.0, 0.0];
    let mut focal = base;
    focal.camera.focal_m = 0.0;
    let mut nan_h = base;
    nan_h.geometry.ground_h_m = f64::NAN;
    for (c, want) in [
        (beyond, ModelError::LineOfSightMissesEarth),
        (inside, ModelError::SatelliteNotAboveGround),
        (degenerate, ModelError::DegenerateState),
        (focal, ModelError::InvalidInput(Param::FocalLength)),
        (nan_h, ModelError::NonFinite(Param::GroundHeight)),
    ] {
        assert_eq!(both(&c), (Err(want), Err(want)), "{c:?}");
    }
    // The envelope: the general form evaluates these, the fixed backend refuses them.
    let mut fast = base;
    fast.geometry.attitude.pitch_rate_rad_s = 0.05;
    let mut low = base;
    low.geometry.state = core_math::earth::circular_state(Ellipsoid::WGS84.a_m + 100e3, 1.7, 0.3);
    let mut short = base;
    short.camera.focal_m = 0.005;
    let mut wide = base;
    wide.n_px = 0.6 / 13e-6;
    for (c, want) in [
        (fast, ModelError::OutOfDomain(Param::PitchRate)),
        (low, ModelError::OutOfDomain(Param::Position)),
        (short, ModelError::OutOfDomain(Param::FocalLength)),
        (wide, ModelError::OutOfDomain(Param::PixelOffset)),
    ] {
        let (fixed, general) = both(&c);
        assert_eq!(fixed, Err(want), "{c:?}");
        assert!(general.is_ok(), "{general:?}: {c:?}");
    }
    // Non-finite attitude: refused when rounded to the backend's input.
    let mut nan_roll = base;
    nan_roll.geometry.attitude.roll_rad = f64::NAN;
    assert_eq!(
        geometry_from_f64(&nan_roll.geometry),
        Err(ModelError::NonFinite(Param::Roll))
    );
}

/// The fixed-point update turned by a yaw (`EarthFixedUpdate::yawed`, the Cortex-M3
/// controller's steered centre) against the f64 general form's turned update
/// (`GeneralUpdate::yawed`, exact): the same motion within the backend's 2e-6 target,
/// over altitudes, rolls, rates and turns of up to 1.2 rad either way.
#[test]
fn yawed_update_matches_the_turned_general_form() {
    let mut rng = SplitMix64(0x7A3D_2026_1127);
    let general = core_math::General::<f64>::new();
    let (mut worst, mut checked) = (0f64, 0);
    for _ in 0..400 {
        let mut c = scene(rng.uniform(300e3, 1_200e3), rng.uniform(-30.0, 30.0));
        c.geometry.attitude.pitch_rad = rng.uniform(-0.35, 0.35);
        c.geometry.attitude.yaw_rad = rng.uniform(-0.1, 0.1);
        c.geometry.attitude.roll_rate_rad_s = rng.uniform(-0.02, 0.02);
        c.geometry.attitude.pitch_rate_rad_s = rng.uniform(-0.01, 0.01);
        c.n_px = rng.uniform(-30_000.0, 30_000.0);
        let delta = rng.uniform(-1.2, 1.2);
        let (s, co) = (libm::sin(delta), libm::cos(delta));
        let q30 = |x: f64| libm::round(x * (1u64 << 30) as f64) as i32;
        let g = geometry_from_f64(&c.geometry).unwrap();
        let gw = g.to_f64();
        let up = EARTH_FIXED.update(&g).unwrap();
        let px = EARTH_FIXED.pixel(&c.camera, c.n_px).unwrap();
        let fixed = EARTH_FIXED
            .motion(&up.yawed(q30(s), q30(co)).unwrap(), &px)
            .map(|m| motion_to_f64(&m));
        let up64 = general.update(&gw).unwrap().yawed(s, co);
        let want = general.motion(&up64, &general.pixel(&c.camera, c.n_px).unwrap());
        match (fixed, want) {
            (Ok(f), Ok(w)) => {
                worst = worst.max(rel(&f, &w));
                checked += 1;
            }
            (f, w) => assert_eq!(f.is_ok(), w.is_ok(), "{f:?} vs {w:?}"),
        }
    }
    assert!(checked > 300, "{checked}");
    assert!(worst <= FAR_TARGET, "{worst:e}");
    eprintln!("yawed fixed update: worst relative error {worst:.2e} over {checked} pixels");
}

/// The boresight's motion over f (`EarthFixedUpdate::boresight_over_focal`, the
/// Cortex-M3 controller's yaw request) against the f64 reference at the same pixel:
/// direction (rad) and speed (relative) within the backend's 2e-6 target.
#[test]
fn boresight_over_focal_matches_the_reference() {
    let mut rng = SplitMix64(0xB02E_5147);
    let mut worst = (0f64, 0f64);
    for _ in 0..300 {
        let mut c = scene(rng.uniform(300e3, 1_200e3), rng.uniform(-30.0, 30.0));
        c.geometry.attitude.pitch_rad = rng.uniform(-0.35, 0.35);
        c.geometry.attitude.yaw_rad = rng.uniform(-1.0, 1.0);
        c.geometry.attitude.roll_rate_rad_s = rng.uniform(-0.02, 0.02);
        c.geometry.attitude.yaw_rate_rad_s = rng.uniform(-0.01, 0.01);
        let g = geometry_from_f64(&c.geometry).unwrap();
        let up = EARTH_FIXED.update(&g).unwrap();
        let (vf1, vf2) = up.boresight_over_focal().unwrap();
        let f = c.camera.focal_m;
        let q63 = (1u64 << 63) as f64;
        let (v1, v2) = (vf1 as f64 / q63 * f, vf2 as f64 / q63 * f);
        let r = EarthReference
            .evaluate(&c.camera, &g.to_f64(), 0.0)
            .unwrap();
        let angle = (libm::atan2(v2, v1) - libm::atan2(r.v2_mps, r.v1_mps)).abs();
        let speed = (libm::hypot(v1, v2) / libm::hypot(r.v1_mps, r.v2_mps) - 1.0).abs();
        worst = (worst.0.max(angle), worst.1.max(speed));
    }
    assert!(worst.0 <= FAR_TARGET && worst.1 <= FAR_TARGET, "{worst:?}");
    eprintln!(
        "boresight over f: worst direction {:.2e} rad, speed {:.2e}",
        worst.0, worst.1
    );
}
