//! `cargo xtask accuracy [--quick] [--model <sphere|earth>]`: a model's f32 and f64
//! forms against its f64 reference, bucketed by the angular distance from the line of
//! sight to the Earth's limb, with the problem's condition number. The figures in
//! docs/accuracy.md come from this command.
//!
//! - `sphere` (the default): the closed forms against `Reference` over a dense,
//!   deterministic grid of the envelope.
//! - `earth`: the real-Earth general form against `EarthReference` over a seeded sample
//!   of the real-Earth envelope (`core_math::sample::SplitMix64::earth_case`: WGS 84,
//!   altitude 200-2000 km, eccentricity to 0.05, any inclination, roll and pitch to
//!   +-45 deg, any yaw, rates to +-2 deg/s, terrain -500 to 9 000 m, p1 to +-0.05 m,
//!   field angle to 40 deg; one draw in four 0.001-3 deg from a limb), with the
//!   componentwise condition number kappa (`core_math::accuracy::earth_kappa`).

use anyhow::{anyhow, Result};
use core_math::accuracy::{earth_kappa, EARTH_F32_KAPPA_LIMIT};
use core_math::earth::fixed::{geometry_from_f64, motion_to_f64};
use core_math::earth::{limb_margin_rad, EarthCamera, EarthGeometry};
use core_math::sample::SplitMix64;
use core_math::sphere::accuracy::F32_REL_TOLERANCE;
use core_math::sphere::{Geometry, Reference, CLOSED_F32, CLOSED_F64};
use core_math::{
    Backend, Camera, EarthReference, ImageMotion, ModelError, EARTH_FIXED, GENERAL_F32, GENERAL_F64,
};

use crate::eval::Model;

/// Unit roundoff of f32, 2^-24.
pub(crate) const U_F32: f64 = f32::EPSILON as f64 / 2.0;

/// Limb-margin buckets (deg): a case falls in the first bucket whose lower bound it meets.
/// Shared with `stability`'s limb table, so that the two documents' bands are the same.
pub(crate) const BUCKETS_DEG: [(f64, &str); 6] = [
    (1.0, ">= 1 deg"),
    (0.1, "0.1 - 1 deg"),
    (0.01, "0.01 - 0.1 deg"),
    (1e-3, "1e-3 - 0.01 deg"),
    (1e-4, "1e-4 - 1e-3 deg"),
    (0.0, "< 1e-4 deg"),
];

/// Extra field points this close to each limb (deg), on top of the regular grid.
const LIMB_MARGINS_DEG: [f64; 11] = [3.0, 1.0, 0.3, 0.1, 0.03, 0.01, 3e-3, 1e-3, 3e-4, 1e-4, 1e-5];

#[derive(Clone, Default)]
struct Stat {
    n: u64,
    /// f32 at f32 inputs vs reference at the same inputs: the algorithm's error.
    f32_speed: Vec<f64>,
    max_f32_v1: f64,
    max_f32_v2_over_speed: f64,
    max_f64_speed: f64,
    /// Relative condition number of |v| with respect to the nadir angle, |d ln v / d eta| |eta|.
    max_cond: f64,
    /// f32 at rounded inputs vs reference at the unrounded inputs: what a user sees.
    max_input_rounding: f64,
    /// The same divided by (cond * u + algorithmic bound): <= 1 means explained.
    max_explained: f64,
    refused: u64,
}

#[derive(clap::Args)]
pub struct Args {
    /// A coarser grid (a few seconds)
    #[arg(long)]
    quick: bool,
    /// The model's Earth
    #[arg(long, value_enum, default_value_t = Model::Sphere)]
    model: Model,
}

pub fn run(args: &Args) -> Result<()> {
    let quick = args.quick;
    if args.model == Model::Earth {
        return earth(quick);
    }
    let t0 = std::time::Instant::now();
    let stats = sweep(quick);
    print_report(&stats, quick, t0.elapsed().as_secs_f64());
    Ok(())
}

/// A real-Earth form under test: its motion at a camera, geometry and pixel, widened to
/// f64, from the inputs in f64 as the other forms and the reference take them.
pub(crate) type Motion =
    fn(&EarthCamera, &EarthGeometry<f64>, f64) -> Result<ImageMotion<f64>, ModelError>;

/// `GENERAL_F32`: the attitude rounded to f32 by the call.
pub(crate) const GENERAL_F32_MOTION: Motion = |c, g, n_px| {
    let m = GENERAL_F32.evaluate(c, &g.to::<f32>(), n_px)?;
    Ok(ImageMotion {
        v1_mps: f64::from(m.v1_mps),
        v2_mps: f64::from(m.v2_mps),
    })
};

/// `EARTH_FIXED`: the inputs rounded to I24F40 (`geometry_from_f64`).
pub(crate) const EARTH_FIXED_MOTION: Motion = |c, g, n_px| {
    let q = geometry_from_f64(g)?;
    Ok(motion_to_f64(&EARTH_FIXED.evaluate(c, &q, n_px)?))
};

pub(crate) fn bucket(margin_deg: f64) -> usize {
    BUCKETS_DEG
        .iter()
        .position(|(lo, _)| margin_deg >= *lo)
        .unwrap_or(BUCKETS_DEG.len() - 1)
}

/// |d ln |v| / d eta| |eta| by a central difference of the reference in roll (which moves
/// eta one for one), with a step well inside the limb margin.
fn condition(
    camera: &Camera,
    g: &Geometry<f64>,
    n_px: f64,
    eta: f64,
    margin_rad: f64,
) -> Option<f64> {
    let d = (margin_rad * 0.1).min(1e-6);
    let at = |droll: f64| {
        let gg = Geometry {
            roll_rad: g.roll_rad + droll,
            ..*g
        };
        Reference
            .evaluate(camera, &gg, n_px)
            .ok()
            .map(|m| m.speed_mps())
    };
    let (lo, mid, hi) = (at(-d)?, at(0.0)?, at(d)?);
    Some(((hi - lo) / (2.0 * d) / mid).abs() * eta.abs())
}

fn sweep(quick: bool) -> Vec<Stat> {
    let camera = Camera {
        focal_m: 0.555,
        pixel_m: 13e-6,
    };
    let mut stats = vec![Stat::default(); BUCKETS_DEG.len()];
    let alts_km: &[f64] = if quick {
        &[200.0, 645.0, 2000.0]
    } else {
        &[200.0, 400.0, 645.0, 1000.0, 1500.0, 2000.0]
    };
    let step = if quick { 4 } else { 1 };
    for &alt_km in alts_km {
        for i0 in (0..=180).step_by(15 * step) {
            for g0 in (0..360).step_by(15 * step) {
                for roll_half_deg in (-90..=90).step_by(3 * step) {
                    let g = Geometry::circular(
                        (roll_half_deg as f64 * 0.5).to_radians(),
                        (i0 as f64).to_radians(),
                        (g0 as f64).to_radians(),
                        alt_km * 1e3,
                        6_371e3,
                    );
                    sweep_geometry(&camera, &g, step, &mut stats);
                }
            }
        }
    }
    stats
}

fn sweep_geometry(camera: &Camera, g: &Geometry<f64>, step: usize, stats: &mut [Stat]) {
    let g32 = g.to::<f32>();
    // The reference at exactly the f32 inputs, so that the comparison sees only the
    // algorithm's error.
    let gx = g32.to_f64();
    let (Ok(u32c), Ok(u64c)) = (CLOSED_F32.update(&g32), CLOSED_F64.update(&gx)) else {
        return;
    };
    let limb = libm::asin(gx.earth_radius_m / (gx.earth_radius_m + gx.altitude_m));
    // Field angles up to 40 deg, then extra points approaching either limb.
    let mut fields: Vec<f64> = (-40..=40)
        .step_by(step)
        .map(|d| (d as f64).to_radians())
        .collect();
    for m in LIMB_MARGINS_DEG {
        for side in [1.0, -1.0] {
            let a = side * (limb - m.to_radians()) - gx.roll_rad;
            if a.abs() <= 40f64.to_radians() {
                fields.push(a);
            }
        }
    }
    for alpha in fields {
        let n_px = libm::tan(alpha) * camera.focal_m / camera.pixel_m;
        let eta = gx.roll_rad + libm::atan(n_px * camera.pixel_m / camera.focal_m);
        let margin = limb - eta.abs();
        if margin <= 0.0 {
            continue;
        }
        let Ok(r) = Reference.evaluate(camera, &gx, n_px) else {
            continue;
        };
        let s = &mut stats[bucket(margin.to_degrees())];
        s.n += 1;
        let p32 = CLOSED_F32.pixel(camera, n_px).expect("pixel in domain");
        let p64 = CLOSED_F64.pixel(camera, n_px).expect("pixel in domain");
        let (Ok(m32), Ok(m64)) = (
            CLOSED_F32.motion(&u32c, &p32),
            CLOSED_F64.motion(&u64c, &p64),
        ) else {
            s.refused += 1;
            continue;
        };
        let sp = r.speed_mps();
        let e_sp = ((m32.speed_mps() as f64) - sp).abs() / sp;
        s.f32_speed.push(e_sp);
        s.max_f32_v1 = s
            .max_f32_v1
            .max(((m32.v1_mps as f64) - r.v1_mps).abs() / r.v1_mps.abs());
        s.max_f32_v2_over_speed = s
            .max_f32_v2_over_speed
            .max(((m32.v2_mps as f64) - r.v2_mps).abs() / sp);
        s.max_f64_speed = s.max_f64_speed.max((m64.speed_mps() - sp).abs() / sp);
        // What rounding the roll to f32 costs, against the exact inputs.
        if let (Some(cond), Ok(exact)) = (
            condition(camera, &gx, n_px, eta, margin),
            Reference.evaluate(camera, g, n_px),
        ) {
            let e_in = ((m32.speed_mps() as f64) - exact.speed_mps()).abs() / exact.speed_mps();
            s.max_cond = s.max_cond.max(cond);
            s.max_input_rounding = s.max_input_rounding.max(e_in);
            let bound = cond * U_F32 + F32_REL_TOLERANCE;
            s.max_explained = s.max_explained.max(e_in / bound);
        }
    }
}

/// The `p` quantile of `v` (sorted in place; 0 when empty).
pub(crate) fn percentile(v: &mut [f64], p: f64) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    v[((v.len() - 1) as f64 * p).round() as usize]
}

fn print_report(stats: &[Stat], quick: bool, secs: f64) {
    let total: u64 = stats.iter().map(|s| s.n).sum();
    println!(
        "accuracy sweep ({}): {total} cases, {secs:.1} s",
        if quick { "quick" } else { "full" }
    );
    println!(
        "f32 inputs; errors relative to the f64 reference's |v_P| (v2: error / |v_P|); u = 2^-24\n"
    );
    println!("| limb margin | cases | f32 max rel err |v| | f32 p99 |v| | f32 max rel err v1 | f32 max err v2/|v| | f64 max rel err |v| | max cond kappa | f32 err vs unrounded inputs | ... / (kappa u + 1e-6) | refused |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|");
    for ((_, name), s) in BUCKETS_DEG.iter().zip(stats) {
        let mut v = s.f32_speed.clone();
        let p99 = percentile(&mut v, 0.99);
        let max = v.last().copied().unwrap_or(0.0);
        println!(
            "| {name} | {} | {:.2e} | {:.2e} | {:.2e} | {:.2e} | {:.2e} | {:.3e} | {:.2e} | {:.2} | {} |",
            s.n, max, p99, s.max_f32_v1, s.max_f32_v2_over_speed, s.max_f64_speed, s.max_cond, s.max_input_rounding, s.max_explained, s.refused
        );
    }
}

/// The real-Earth sample's seed.
const SEED: u64 = 0x0EA7_2013_0605_0011;

/// One limb-margin bucket of the real-Earth sweep.
#[derive(Clone, Default)]
struct EarthStat {
    n: u64,
    f64_max: f64,
    f32: Vec<f64>,
    kappa_max: f64,
    /// Max err / (kappa u32).
    ratio_max: f64,
    /// Cases with kappa above the limit, and the max error of the others.
    stiff: u64,
    f32_max_tame: f64,
    /// Where the backends disagree on hit or miss (allowed within 1e-4 deg).
    disagree: u64,
}

fn rel(m: &ImageMotion<f64>, r: &ImageMotion<f64>) -> f64 {
    (m.v1_mps - r.v1_mps).hypot(m.v2_mps - r.v2_mps) / r.v1_mps.hypot(r.v2_mps)
}

/// `--model earth`.
fn earth(quick: bool) -> Result<()> {
    let t0 = std::time::Instant::now();
    let draws = if quick { 20_000 } else { 200_000 };
    let mut rng = SplitMix64(SEED);
    let mut stats = vec![EarthStat::default(); BUCKETS_DEG.len()];
    let (mut misses, mut miss_disagree) = (0u64, 0u64);
    for _ in 0..draws {
        let Some(c) = rng.earth_case() else { continue };
        let margin_deg = limb_margin_rad(&c.geometry, &c.camera, c.n_px)
            .map_err(|e| anyhow!("accuracy: {e}"))?
            .to_degrees();
        let r = EarthReference.evaluate(&c.camera, &c.geometry, c.n_px);
        let f = GENERAL_F64.evaluate(&c.camera, &c.geometry, c.n_px);
        let s = GENERAL_F32_MOTION(&c.camera, &c.geometry, c.n_px);
        let Ok(r) = r else {
            misses += 1;
            let all_miss = f == Err(ModelError::LineOfSightMissesEarth)
                && s == Err(ModelError::LineOfSightMissesEarth);
            if !all_miss {
                miss_disagree += 1;
            }
            continue;
        };
        let st = &mut stats[bucket(margin_deg)];
        st.n += 1;
        let (Ok(f), Ok(s)) = (f, s) else {
            st.disagree += 1;
            continue;
        };
        st.f64_max = st.f64_max.max(rel(&f, &r));
        let e = rel(&s, &r);
        st.f32.push(e);
        let kappa = earth_kappa(&c.camera, &c.geometry, c.n_px).map_err(|e| anyhow!("{e}"))?;
        st.kappa_max = st.kappa_max.max(kappa);
        st.ratio_max = st.ratio_max.max(e / (kappa * U_F32));
        if kappa > EARTH_F32_KAPPA_LIMIT {
            st.stiff += 1;
        } else {
            st.f32_max_tame = st.f32_max_tame.max(e);
        }
    }
    println!(
        "Real-Earth model: GENERAL_F64 and GENERAL_F32 against EarthReference, {draws} draws \
         (seed {SEED:#x}{}), {misses} beyond the limb ({miss_disagree} of them not refused by \
         every backend). Error |dv|/|v| (the vector difference), inputs as given in f64 (the \
         f32 attitude rounding counts); kappa = componentwise condition number of v over its \
         19 inputs; u = 2^-24.\n",
        if quick { ", --quick" } else { "" }
    );
    println!(
        "| limb margin | cases | f64 max | f32 max | f32 p99 | f32 max, kappa <= {l} | cases kappa > {l} | max kappa | max f32 err / (kappa u) | hit/miss disagreements |",
        l = EARTH_F32_KAPPA_LIMIT
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for ((_, label), st) in BUCKETS_DEG.iter().zip(&mut stats) {
        if st.n == 0 {
            continue;
        }
        let p99 = percentile(&mut st.f32, 0.99);
        let max = st.f32.last().copied().unwrap_or(0.0);
        println!(
            "| {label} | {} | {:.2e} | {max:.2e} | {p99:.2e} | {:.2e} | {} | {:.3e} | {:.2} | {} |",
            st.n, st.f64_max, st.f32_max_tame, st.stiff, st.kappa_max, st.ratio_max, st.disagree
        );
    }
    println!("\n({:.1} s)", t0.elapsed().as_secs_f64());
    Ok(())
}
