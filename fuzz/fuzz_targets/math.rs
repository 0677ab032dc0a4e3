//! core-math on arbitrary inputs: every backend's `evaluate` (the round-Earth and the
//! real-Earth models), `mtf_mismatch`, `StageRule::max_stages`, `line_period_s` and
//! `line_period_ticks`.
//!
//! Oracles: no panic (the crate promises "no panics on any input"), every `Ok` value
//! finite, `line_period_ticks` within half a tick (plus rounding) of period x clock,
//! `max_stages` at most the limit and meeting the floor (in f64 also the largest such).
//! The real Earth's fixed-point backend (`EARTH_FIXED`) gets the same inputs as the
//! float forms and is also held to its accuracy targets against the reference
//! (`earth_fixed_within_target`).
//!
//! Each input value is either a raw f64 (any bit pattern: NaN, inf, subnormal, huge)
//! or a fraction mapped into a range around the model's domain, so that the fuzzer
//! reaches the arithmetic as well as the refusals.
#![no_main]

use arbitrary::Arbitrary;
use core_math::earth::{Attitude, EarthCamera, EarthGeometry, Ellipsoid};
use core_math::sphere::fixed_point::{geometry_from_f64, motion_to_f64};
use core_math::sphere::speed_line_period_s;
use core_math::{line_period_ticks, mtf_mismatch, Backend, Camera, ImageMotion, Real, StageRule};
use core_math::sphere::{Geometry, CLOSED_F32, CLOSED_F64, FIXED};
use libfuzzer_sys::fuzz_target;

#[derive(Arbitrary, Debug, Clone, Copy)]
enum V {
    /// Any f64 bit pattern.
    Raw(f64),
    /// lo + (hi - lo) * frac, for the field's (lo, hi).
    In(u32),
    /// lo or hi, nudged by a few ulp (the domain edges).
    Edge(bool, i8),
}

impl V {
    fn get(self, lo: f64, hi: f64) -> f64 {
        match self {
            V::Raw(x) => x,
            V::In(k) => lo + (hi - lo) * (f64::from(k) / f64::from(u32::MAX)),
            V::Edge(top, ulps) => {
                let x = if top { hi } else { lo };
                let bits = x.to_bits() as i64 + i64::from(ulps);
                f64::from_bits(bits as u64)
            }
        }
    }
}

#[derive(Arbitrary, Debug)]
struct Input {
    focal_m: V,
    pixel_m: V,
    n_px: V,
    roll: V,
    inclination: V,
    arg_latitude: V,
    altitude: V,
    earth_radius: V,
    earth_rate: V,
    orbit_rate: V,
    /// Derive the orbit rate from R and H (circular orbit) instead of `orbit_rate`.
    circular: bool,
    stages: u32,
    rel_mismatch: V,
    mtf_floor: V,
    stage_limit: u32,
    period_s: V,
    clock_hz: V,
    earth: EarthInput,
}

/// The real-Earth model's inputs. `near_earth` maps the state into orbit-like ranges
/// (radius 6.3e6-9e6 m, speed up to 1.2e4 m/s) so that the arithmetic is reached, not
/// only the refusals; `wgs84` fixes the Earth.
#[derive(Arbitrary, Debug)]
struct EarthInput {
    near_earth: bool,
    wgs84: bool,
    r: [V; 3],
    v: [V; 3],
    angles: [V; 3],
    rates: [V; 3],
    ground_h: V,
    a: V,
    flattening: V,
    earth_rate: V,
    focal_m: V,
    pixel_m: V,
    p1_m: V,
    n_px: V,
}

fn earth(e: &EarthInput) -> (EarthCamera, EarthGeometry<f64>, f64) {
    let (r_lim, v_lim) = if e.near_earth {
        (9.0e6, 1.2e4)
    } else {
        (1.1e9, 1.1e5)
    };
    let ellipsoid = if e.wgs84 {
        Ellipsoid::WGS84
    } else {
        Ellipsoid {
            a_m: e.a.get(-1.0e3, 1.1e8),
            flattening: e.flattening.get(-0.1, 1.1),
        }
    };
    let geometry = EarthGeometry {
        state: core_math::StateVector {
            position_m: e.r.map(|x| x.get(-r_lim, r_lim)),
            velocity_mps: e.v.map(|x| x.get(-v_lim, v_lim)),
        },
        attitude: Attitude {
            roll_rad: e.angles[0].get(-1.1e5, 1.1e5),
            pitch_rad: e.angles[1].get(-1.6, 1.6),
            yaw_rad: e.angles[2].get(-4.0, 4.0),
            roll_rate_rad_s: e.rates[0].get(-1.1, 1.1),
            pitch_rate_rad_s: e.rates[1].get(-1.1, 1.1),
            yaw_rate_rad_s: e.rates[2].get(-1.1, 1.1),
        },
        ground_h_m: e.ground_h.get(-7.0e6, 2.0e4),
        ellipsoid,
        earth_rate_rad_s: e.earth_rate.get(-1.1, 1.1),
    };
    let camera = EarthCamera {
        focal_m: e.focal_m.get(0.0, 1.1e3),
        pixel_m: e.pixel_m.get(0.0, 1.1),
        p1_m: e.p1_m.get(-1.0, 1.0),
    };
    (camera, geometry, e.n_px.get(-1.0e6, 1.0e6))
}

/// The targets `docs/fixed-point.md` states for EARTH_FIXED (relative |dv| / |v|): 2e-6
/// from 1 deg inside the limb outward, 2e-5 from 0.01 deg, where the problem's
/// condition number is at most `EARTH_F32_KAPPA_LIMIT` (30); plus the reference's own
/// error (the general f64 form and the reference agree within 1e-12).
const FIXED_FAR_TARGET: f64 = 2e-6;
const FIXED_NEAR_TARGET: f64 = 2e-5;
const REFERENCE_SLACK: f64 = 1e-11;

/// An `Ok` of EARTH_FIXED at the rounded geometry `g` against the reference at the same
/// inputs: where the reference accepts and the line of sight is at least 0.01 deg inside
/// the limb, within its band's target unless kappa exceeds 30 (kappa costs 38 reference
/// evaluations, so it is computed only for a case over its target).
fn earth_fixed_within_target(
    c: &EarthCamera,
    g: &EarthGeometry<f64>,
    n_px: f64,
    m: &ImageMotion<f64>,
    e: &EarthInput,
) {
    let Ok(margin_rad) = core_math::earth::limb_margin_rad(g, c, n_px) else {
        return;
    };
    let margin_deg = margin_rad.to_degrees();
    let target = if margin_deg >= 1.0 {
        FIXED_FAR_TARGET
    } else if margin_deg >= 0.01 {
        FIXED_NEAR_TARGET
    } else {
        return;
    };
    let Ok(r) = core_math::EarthReference.evaluate(c, g, n_px) else {
        return;
    };
    let v = libm::hypot(r.v1_mps, r.v2_mps);
    let err = libm::hypot(m.v1_mps - r.v1_mps, m.v2_mps - r.v2_mps) / v;
    // How often the accuracy oracle is reached (grep the replay of a corpus for it).
    if std::env::var_os("FUZZ_DEBUG").is_some() {
        eprintln!("EARTH_FIXED compared: err {err:e}, margin {margin_deg} deg");
    }
    // F8 (docs/fuzzing.md): the roundings are absolute (2^-34 rad/s on W and V / sigma),
    // so the targets are stated for image rates |v| / f of at least 1e-4 rad/s
    // (docs/fixed-point.md) besides kappa <= 30.
    let f8 = v / c.focal_m < 1e-4;
    if err > target + REFERENCE_SLACK && !f8 {
        let kappa = core_math::accuracy::earth_kappa(c, g, n_px);
        assert!(
            matches!(kappa, Ok(k) if k > core_math::accuracy::EARTH_F32_KAPPA_LIMIT),
            "EARTH_FIXED: err {err:e} > target {target:e} at {margin_deg} deg inside the \
             limb, kappa {kappa:?}: {m:?} vs reference {r:?} for {e:?}"
        );
    }
}

/// An `Ok` of the real-Earth model: finite motion, v1 != 0, and derived outputs (the
/// line period pixel/|v1| and the drift atan(v2/v1)) finite.
fn check_earth<T: Real>(m: &ImageMotion<T>, pixel_m: f64, what: &str, e: &EarthInput) {
    assert!(
        m.v1_mps.is_finite() && m.v2_mps.is_finite() && m.speed_mps().is_finite(),
        "{what}: Ok but non-finite motion {m:?} for {e:?}"
    );
    let period = core_math::line_period_s(T::from_f64(pixel_m), m);
    assert!(
        period.is_finite() && period > T::ZERO,
        "{what}: line period {period:?} for {e:?}"
    );
    assert!(m.drift_rad().is_finite(), "{what}: drift for {e:?}");
}

fn check_motion<T: Real>(m: &ImageMotion<T>, what: &str, input: &Input) {
    assert!(
        m.v1_mps.is_finite() && m.v2_mps.is_finite(),
        "{what}: Ok but non-finite motion {m:?} for {input:?}"
    );
    let s = m.speed_mps();
    assert!(s.is_finite(), "{what}: non-finite speed for {input:?}");
}

/// `largest`: also check that M + 1 misses the floor (the doc's "largest M"); asked of
/// f64 only, where every u32 stage count and the guess are exact to well under a stage.
fn stage_rule<T: Real + core::fmt::Debug>(floor: f64, rel: T, limit: u32, largest: bool) {
    if let Ok(rule) = StageRule::<T>::new(floor) {
        // F4 (docs/fuzzing.md, fixed): the correction of the guess is bounded, so any
        // limit up to u32::MAX is checked (the run's -timeout catches a slow search).
        assert!(rule.mismatch_budget().is_finite() && rule.mtf_floor().is_finite());
        if let Ok(m) = rule.max_stages(rel, limit) {
            assert!(m <= limit, "max_stages {m} > limit {limit}");
            if m > 0 {
                let mtf = mtf_mismatch(m, rel).expect("finite rel");
                assert!(
                    mtf >= rule.mtf_floor(),
                    "max_stages {m} misses the floor: mtf {mtf:?} < {:?} (rel {rel:?})",
                    rule.mtf_floor()
                );
            }
            // Limits are capped at MAX_STAGE_LIMIT (finding F5): the largest M below it.
            if largest && m < limit.min(core_math::mtf::MAX_STAGE_LIMIT) {
                let next = mtf_mismatch(m + 1, rel).expect("finite rel");
                assert!(
                    !(next >= rule.mtf_floor()),
                    "max_stages {m} is not the largest: mtf(M + 1) {next:?} >= {:?} (rel {rel:?})",
                    rule.mtf_floor()
                );
            }
        }
    }
}

fn ticks<T: Real + core::fmt::Debug>(period: T, clock: T, eps: f64) {
    if let Ok(t) = line_period_ticks(period, clock) {
        assert!(t.ticks >= 1);
        assert!(t.rounding_error_s.is_finite(), "non-finite rounding error");
        let exact = period.to_f64() * clock.to_f64();
        // Half a tick, plus the rounding of period x clock in T.
        let tol = 0.5 + exact.abs() * 2.0 * eps + 1e-9;
        assert!(
            (f64::from(t.ticks) - exact).abs() <= tol,
            "ticks {} for period {period:?} x clock {clock:?} = {exact}",
            t.ticks
        );
    }
}

fuzz_target!(|input: Input| {
    if std::env::var_os("FUZZ_DEBUG").is_some() {
        eprintln!("{input:?}");
    }
    let camera = Camera {
        focal_m: input.focal_m.get(0.0, 1.1e3),
        pixel_m: input.pixel_m.get(0.0, 1.1),
    };
    let n_px = input.n_px.get(-1.0e6, 1.0e6);
    let earth_radius_m = input.earth_radius.get(0.0, 1.1e8);
    let altitude_m = input.altitude.get(0.0, 2.0e7);
    let orbit_rate_rad_s = if input.circular {
        core_math::sphere::orbital_rate_rad_s(earth_radius_m, altitude_m)
    } else {
        input.orbit_rate.get(-1.1, 1.1)
    };
    let g = Geometry {
        roll_rad: input.roll.get(-1.6, 1.6),
        inclination_rad: input.inclination.get(-1.1e5, 1.1e5),
        arg_latitude_rad: input.arg_latitude.get(-1.1e5, 1.1e5),
        altitude_m,
        earth_radius_m,
        earth_rate_rad_s: input.earth_rate.get(-1.1, 1.1),
        orbit_rate_rad_s,
    };

    {
        if let Ok(m) = core_math::sphere::Reference.evaluate(&camera, &g, n_px) {
            check_motion(&m, "Reference", &input);
        }
        // F3 (docs/fuzzing.md, fixed): rolls beyond pi are checked like any other.
        if let Ok(m) = CLOSED_F64.evaluate(&camera, &g, n_px) {
            check_motion(&m, "CLOSED_F64", &input);
        }
        if let Ok(m) = CLOSED_F32.evaluate(&camera, &g.to::<f32>(), n_px) {
            check_motion(&m, "CLOSED_F32", &input);
        }
        if let Ok(gf) = geometry_from_f64(&g) {
            if let Ok(m) = FIXED.evaluate(&camera, &gf, n_px) {
                check_motion(&motion_to_f64(&m), "FIXED", &input);
            }
        }
    }

    {
        let (ec, eg, en) = earth(&input.earth);
        if let Ok(m) = core_math::EarthReference.evaluate(&ec, &eg, en) {
            check_earth(&m, ec.pixel_m, "EarthReference", &input.earth);
        }
        if let Ok(m) = core_math::GENERAL_F64.evaluate(&ec, &eg, en) {
            check_earth(&m, ec.pixel_m, "GENERAL_F64", &input.earth);
        }
        if let Ok(m) = core_math::GENERAL_F32.evaluate(&ec, &eg.to::<f32>(), en) {
            check_earth(&m, ec.pixel_m, "GENERAL_F32", &input.earth);
        }
        // The attitude rounded to I24F40 as the backend takes it; the reference is
        // compared at those rounded inputs.
        if let Ok(gf) = core_math::earth::fixed::geometry_from_f64(&eg) {
            if let Ok(m) = core_math::EARTH_FIXED.evaluate(&ec, &gf, en) {
                let m = core_math::earth::fixed::motion_to_f64(&m);
                check_earth(&m, ec.pixel_m, "EARTH_FIXED", &input.earth);
                earth_fixed_within_target(&ec, &gf.to_f64(), en, &m, &input.earth);
            }
        }
    }

    let rel = input.rel_mismatch.get(-0.1, 0.1);
    // F1 (docs/fuzzing.md, fixed): an overflowing sinc argument must give a finite
    // value too (its limit, 0), so every Ok is asserted finite.
    // F7 (docs/fuzzing.md, fixed): the same beyond the sine's domain (1 647 099 rad).
    if let Ok(x) = mtf_mismatch(input.stages, rel) {
        assert!(x.is_finite(), "mtf_mismatch f64 {x} for {input:?}");
    }
    if let Ok(x) = mtf_mismatch(input.stages, rel as f32) {
        assert!(x.is_finite(), "mtf_mismatch f32 {x} for {input:?}");
    }
    let floor = input.mtf_floor.get(0.0, 1.0);
    stage_rule::<f64>(floor, rel, input.stage_limit, true);
    // Finding F5 (docs/fuzzing.md, fixed): f32 gets any u32 limit again.
    stage_rule::<f32>(floor, rel as f32, input.stage_limit, false);

    let period = input.period_s.get(0.0, 1.0e-2);
    let clock = input.clock_hz.get(0.0, 1.0e9);
    ticks::<f64>(period, clock, f64::EPSILON);
    ticks::<f32>(period as f32, clock as f32, f64::from(f32::EPSILON));
    // F2 (docs/fuzzing.md, fixed): no zero period any more, so every Ok is finite and
    // strictly positive.
    if let Ok(p) = speed_line_period_s(camera.pixel_m, period) {
        assert!(
            p.is_finite() && p > 0.0,
            "line_period_s f64 {p} for {input:?}"
        );
    }
    if let Ok(p) = speed_line_period_s(camera.pixel_m as f32, period as f32) {
        assert!(
            p.is_finite() && p > 0.0,
            "line_period_s f32 {p} for {input:?}"
        );
    }
});
