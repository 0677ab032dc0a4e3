//! `cargo xtask accuracy --model earth [--quick]`: the real-Earth general form (f64, f32)
//! against `EarthReference` over a seeded sample of the real-Earth envelope
//! (`core_math::sample::SplitMix64::earth_case`: WGS 84, altitude 200-2000 km,
//! eccentricity to 0.05, any inclination, roll and pitch to +-45 deg, any yaw, rates to
//! +-2 deg/s, terrain -500 to 9 000 m, p1 to +-0.05 m, field angle to 40 deg; one draw in
//! four 0.001-3 deg from a limb), bucketed by the limb margin, with the problem's
//! condition number kappa (`core_math::accuracy::earth_kappa`). The real-Earth figures in
//! docs/accuracy.md come from this command.

use anyhow::{anyhow, Result};
use core_math::accuracy::{earth_kappa, EARTH_F32_KAPPA_LIMIT};
use core_math::earth::limb_margin_rad;
use core_math::sample::SplitMix64;
use core_math::{Backend, EarthReference, ImageMotion, ModelError, GENERAL_F32, GENERAL_F64};

use super::{bucket, BUCKETS_DEG, U32};

const SEED: u64 = 0x0EA7_2013_0605_0011;

#[derive(Clone, Default)]
struct Stat {
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

pub fn run(quick: bool) -> Result<()> {
    let t0 = std::time::Instant::now();
    let draws = if quick { 20_000 } else { 200_000 };
    let mut rng = SplitMix64(SEED);
    let mut stats = vec![Stat::default(); BUCKETS_DEG.len()];
    let (mut misses, mut miss_disagree) = (0u64, 0u64);
    for _ in 0..draws {
        let Some(c) = rng.earth_case() else { continue };
        let margin_deg = limb_margin_rad(&c.geometry, &c.camera, c.n_px)
            .map_err(|e| anyhow!("accuracy: {e}"))?
            .to_degrees();
        let r = EarthReference.evaluate(&c.camera, &c.geometry, c.n_px);
        let f = GENERAL_F64.evaluate(&c.camera, &c.geometry, c.n_px);
        let s = GENERAL_F32
            .evaluate(&c.camera, &c.geometry.to::<f32>(), c.n_px)
            .map(|m| ImageMotion {
                v1_mps: f64::from(m.v1_mps),
                v2_mps: f64::from(m.v2_mps),
            });
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
        st.ratio_max = st.ratio_max.max(e / (kappa * U32));
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
        st.f32.sort_by(f64::total_cmp);
        let max = st.f32.last().copied().unwrap_or(0.0);
        let p99 = st
            .f32
            .get(((st.f32.len().max(1) - 1) as f64 * 0.99).round() as usize)
            .copied()
            .unwrap_or(0.0);
        println!(
            "| {label} | {} | {:.2e} | {max:.2e} | {p99:.2e} | {:.2e} | {} | {:.3e} | {:.2} | {} |",
            st.n, st.f64_max, st.f32_max_tame, st.stiff, st.kappa_max, st.ratio_max, st.disagree
        );
    }
    println!("\n({:.1} s)", t0.elapsed().as_secs_f64());
    Ok(())
}
