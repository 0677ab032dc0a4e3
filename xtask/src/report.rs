//! `cargo xtask report [--csv] [--cases N] [--seed S] [--no-bench]`: error against
//! run time, one row per backend.
//!
//! Errors: |v_P| of each backend against the f64 reference chain over ONE shared, seeded
//! random sample of the envelope (altitude 200-2000 km, R = 6371 km, roll up to 45 deg,
//! field angle up to 40 deg, any inclination and argument of latitude; camera f = 0.555 m,
//! A = 13 um). Three cases in four draw the field angle uniformly, one in four puts the
//! line of sight log-uniformly 1e-5 to 1 deg short of a limb. The geometry is rounded to
//! f32 once, so every backend and the reference see the same values (exact in f32 and,
//! to 2^-40, in the fixed backend's I24F40). `max_rel_err` and `p99_rel_err` are over the
//! cases at least 1 deg from the limb, `max_rel_err_near_limb` over those within 1 deg.
//!
//! Run time: guest instructions under QEMU from `cargo xtask bench` (the same build, the
//! same plugin, [`crate::qemu::bench_counts`]), on the Cortex-M4F (mps2-an386) and on the
//! Cortex-M3 without FPU (mps2-an385, where f32 and f64 are software): per pixel, the
//! count of `motion` over 32 pixels across the swath in a loop, divided by 32 (the
//! marginal cost inside the loop the controller runs, without a one-pixel region's call
//! and return); per update, `update` then `motion` at each of the default scene's
//! planned sample points. Instructions, not cycles.
//!
//! `flash_bytes`: [`crate::footprint`], one link per backend and board.

use anyhow::{anyhow, Context, Result};
use core_math::accuracy::{earth_kappa, EARTH_F32_KAPPA_LIMIT};
use core_math::earth;
use core_math::sample::SplitMix64 as Rng;
use core_math::sphere::accuracy::limb_margin_rad;
use core_math::sphere::fixed_point::{geometry_from_f64, motion_to_f64};
use core_math::sphere::{
    Geometry, MicroF32, NaiveF32, Reference, CLOSED_F32, CLOSED_F64, CLOSED_MICROMATH, FIXED,
};
use core_math::{Backend, Camera, EarthReference, ImageMotion, GENERAL_F64};

use crate::accuracy::{percentile, EARTH_FIXED_MOTION, GENERAL_F32_MOTION, U_F32};
use crate::markdown;
use crate::plot::{Plot, Series};
use crate::qemu::board::Board;
use crate::qemu::{bench_counts, BenchCounts};

const DEFAULT_CASES: usize = 200_000;
const DEFAULT_SEED: u64 = 0x5EED_2013_0605_0750;
const CAMERA: Camera = Camera {
    focal_m: 0.555,
    pixel_m: 13e-6,
};
/// "Near the limb": the line of sight within this angle (deg) of the limb.
const NEAR_LIMB_DEG: f64 = 1.0;

/// Pixels in the bench's loop regions (firmware/src/bin/bench.rs, `LOOP_PX`).
const LOOP_PX: u64 = 32;

/// One backend of the report: its name (also its `--cfg footprint` value) and the name
/// of its bench regions: `<backend> motion, 32 pixels in a loop` (`motion` over
/// `LOOP_PX` pixels) and `<backend> full update` (one full update of the default scene:
/// `update`, then `motion` at each of its planned sample points).
struct Variant(&'static str, &'static str);

impl Variant {
    fn loop_label(&self) -> String {
        format!("{} motion, {LOOP_PX} pixels in a loop", self.1)
    }

    fn full_update_label(&self) -> String {
        format!("{} full update", self.1)
    }
}

/// The round-Earth variants first (`SPHERE_VARIANTS` of them, errors over the round-Earth
/// sample), then the real-Earth ones (errors over the real-Earth sample).
const SPHERE_VARIANTS: usize = 6;
const VARIANTS: [Variant; 10] = [
    Variant("naive-f32", "NaiveF32"),
    Variant("reference", "Reference"),
    Variant("f64", "CLOSED_F64"),
    Variant("f32", "CLOSED_F32"),
    Variant("f32-micromath", "CLOSED_MICROMATH"),
    Variant("fixed", "FIXED"),
    Variant("earth-reference", "EarthReference"),
    Variant("earth-f64", "GENERAL_F64"),
    Variant("earth-f32", "GENERAL_F32"),
    Variant("earth-fixed", "EARTH_FIXED"),
];
/// The boards whose counts and flash fill the table: the M4F, then the M3 (no FPU).
const BOARDS: [Board; 2] = [Board::Mps2An386, Board::Mps2An385];

#[derive(Default)]
struct Errors {
    far: Vec<f64>,
    max_near: f64,
    refused: u64,
}

impl Errors {
    /// One case's relative error (None: the backend refused it).
    fn push(&mut self, rel: Option<f64>, is_near: bool) {
        match rel {
            None => self.refused += 1,
            Some(rel) if is_near => self.max_near = self.max_near.max(rel),
            Some(rel) => self.far.push(rel),
        }
    }
}

struct Sample {
    cases: usize,
    near: usize,
    earth_near: usize,
    errors: Vec<Errors>,
    earth_f32: EarthF32Split,
}

/// `earth-f32`'s errors against the problem's condition number kappa
/// (`core_math::accuracy::earth_kappa`): its 2e-6 and 2e-5 bounds hold up to
/// `EARTH_F32_KAPPA_LIMIT`;
/// everywhere at least 0.01 deg from the limb err / (kappa u32) is bounded.
#[derive(Default)]
struct EarthF32Split {
    /// Max error at least 1 deg from the limb, kappa <= 30.
    far: f64,
    /// Max error 0.01-1 deg from the limb, kappa <= 30.
    near: f64,
    /// Cases with kappa > 30 (at least 0.01 deg from the limb).
    stiff: usize,
    /// Max err/(kappa u32) over every case at least 0.01 deg from the limb.
    ratio: f64,
    /// Cases at least 0.01 deg from the limb.
    all: usize,
}

#[derive(clap::Args)]
pub struct Args {
    /// The table as CSV on stdout (the notes on stderr); the doc is not rewritten
    #[arg(long)]
    csv: bool,
    /// Cases in each sample (only the default rewrites the doc)
    #[arg(long, value_name = "N", default_value_t = DEFAULT_CASES, value_parser = positive)]
    cases: usize,
    /// Seed of the samples, decimal or 0x hex [default: the doc's]
    #[arg(long, value_name = "S", value_parser = parse_seed)]
    seed: Option<u64>,
    /// Errors only: no instruction counts or flash bytes (no QEMU, no firmware builds)
    #[arg(long)]
    no_bench: bool,
}

pub fn run(args: &Args) -> Result<()> {
    let (csv, bench, cases) = (args.csv, !args.no_bench, args.cases);
    let seed = args.seed.unwrap_or(DEFAULT_SEED);
    let sample = sweep(seed, cases);
    let names: Vec<&str> = VARIANTS.iter().map(|v| v.0).collect();
    let mut runs = Vec::new();
    if bench {
        for board in BOARDS {
            runs.push((
                bench_counts(board, true)?,
                crate::footprint::variant_bytes(board, &names)?,
            ));
        }
    }
    let rows = print_table(&sample, &runs, csv, seed)?;
    // The model's own error, for scale: the round Earth against WGS 84 (docs/earth-model.md).
    let earth = format!(
        "Model error for scale: {}.",
        crate::ellipsoid::summary()?.line()
    );
    if csv {
        eprintln!("report: {earth}");
    } else {
        println!("\n{earth}");
    }
    // The default (full sample, bench run, markdown) regenerates the doc's table and plot.
    if !csv && !runs.is_empty() && cases == DEFAULT_CASES && seed == DEFAULT_SEED {
        write_artefacts(&rows, &earth)?;
    }
    Ok(())
}

const DOC: &str = "docs/error-vs-runtime.md";
const PNG: &str = "docs/error-vs-runtime.png";
const BEGIN: &str = "<!-- report:begin (written by `cargo xtask report`) -->";
const END: &str = "<!-- report:end -->";

/// `doc` with the markdown table of `rows`, then the paragraph `trailer`, between its
/// markers.
fn replace_table(doc: &str, rows: &[Row], trailer: &str) -> Option<String> {
    let mut block = format!("{BEGIN}\n\n{}\n", markdown::table(&HEADER, rows));
    if !trailer.is_empty() {
        block.push_str(trailer);
        block.push_str("\n\n");
    }
    block.push_str(END);
    markdown::replace_between(doc, BEGIN, END, &block)
}

/// Replaces the table between the doc's markers and draws the plot: each variant's
/// worst error at least 1 deg from the limb (a cross) and within 1 deg (a slash, dashed)
/// against log10 of its instructions per pixel on the M4F, and the far error again at
/// the M3's count (a thin cross). The reference is the golden source (error 0 by
/// definition) and has no point on a log axis.
fn write_artefacts(rows: &[Row], trailer: &str) -> Result<()> {
    let root = crate::qemu::workspace_root();
    let doc_path = root.join(DOC);
    let doc = std::fs::read_to_string(&doc_path).with_context(|| format!("reading {DOC}"))?;
    let new_doc = replace_table(&doc, rows, trailer)
        .with_context(|| format!("{DOC} lacks the report markers"))?;
    std::fs::write(&doc_path, new_doc).with_context(|| format!("writing {DOC}"))?;
    let mut plot = Plot::new(
        "Error against run time, per backend (Cortex-M4F; thin: Cortex-M3)",
        "log10 instructions per pixel",
        "max relative error of |v_P|",
    )
    .log_y(true)
    .x_range(1.5, 5.5)
    .y_range(1e-15, 1e-2);
    for (i, r) in rows.iter().enumerate() {
        let parse = |k: usize| r[k].parse::<f64>().ok().filter(|v| *v > 0.0);
        let (Some(far), Some(near), Some(instr)) = (parse(1), parse(3), parse(4)) else {
            continue;
        };
        // A cross at the M4F's count (named), a slash for the near-limb error (dashed), a
        // thin cross at the M3's count.
        let mark = |name: &str, pts: Vec<(f64, f64)>, width: f64| {
            Series::line(name, pts).palette(i).width(width)
        };
        let x = instr.log10();
        plot = plot
            .series(mark(&r[0], vec![(x - 0.06, far), (x + 0.06, far)], 3.0))
            .series(mark("", vec![(x, far / 1.6), (x, far * 1.6)], 3.0))
            .series(
                mark(
                    "",
                    vec![(x - 0.06, near / 1.6), (x + 0.06, near * 1.6)],
                    3.0,
                )
                .dashed(),
            );
        if let Some(m3) = parse(7) {
            let x = m3.log10();
            plot = plot
                .series(mark("", vec![(x - 0.04, far), (x + 0.04, far)], 1.5))
                .series(mark("", vec![(x, far / 1.4), (x, far * 1.4)], 1.5));
        }
    }
    plot.save(&root.join(PNG))?;
    eprintln!("report: wrote {DOC} (table) and {PNG}");
    Ok(())
}

fn parse_seed(v: &str) -> Result<u64> {
    match v.strip_prefix("0x") {
        Some(hex) => u64::from_str_radix(&hex.replace('_', ""), 16),
        None => v.parse(),
    }
    .map_err(|e| anyhow!("not a decimal or 0x hex integer: {e}"))
}

fn positive(v: &str) -> Result<usize> {
    v.parse()
        .ok()
        .filter(|&n| n > 0)
        .ok_or_else(|| anyhow!("not a positive count"))
}

/// One case whose line of sight meets the Earth (per the reference), geometry rounded to
/// f32, and its limb margin (deg).
fn case(rng: &mut Rng) -> Option<(Geometry<f64>, f64, f64)> {
    let g = rng.envelope_geometry();
    let n_px = rng.envelope_pixel(&g, &CAMERA)?;
    let margin = limb_margin_rad(&CAMERA, &g, n_px).ok()?;
    (margin > 0.0).then_some((g, n_px, margin.to_degrees()))
}

fn sweep(seed: u64, cases: usize) -> Sample {
    let mut rng = Rng(seed);
    let mut errors: Vec<Errors> = VARIANTS.iter().map(|_| Errors::default()).collect();
    let (mut done, mut near) = (0, 0);
    while done < cases {
        let Some((g, n_px, margin_deg)) = case(&mut rng) else {
            continue;
        };
        let Ok(r) = Reference.evaluate(&CAMERA, &g, n_px) else {
            continue;
        };
        done += 1;
        let is_near = margin_deg < NEAR_LIMB_DEG;
        near += usize::from(is_near);
        let g32 = g.to::<f32>();
        let speeds: [Option<f64>; 6] = [
            NaiveF32
                .evaluate(&CAMERA, &g32, n_px)
                .ok()
                .map(|m| f64::from(m.speed_mps())),
            Some(r.speed_mps()),
            CLOSED_F64
                .evaluate(&CAMERA, &g, n_px)
                .ok()
                .map(|m| m.speed_mps()),
            CLOSED_F32
                .evaluate(&CAMERA, &g32, n_px)
                .ok()
                .map(|m| f64::from(m.speed_mps())),
            CLOSED_MICROMATH
                .evaluate(&CAMERA, &g.to::<MicroF32>(), n_px)
                .ok()
                .map(|m| m.speed_mps().0.into()),
            geometry_from_f64(&g)
                .and_then(|gq| FIXED.evaluate(&CAMERA, &gq, n_px))
                .ok()
                .map(|m| motion_to_f64(&m).speed_mps()),
        ];
        let sp = r.speed_mps();
        for (e, s) in errors.iter_mut().zip(speeds) {
            e.push(s.map(|s| (s - sp).abs() / sp), is_near);
        }
    }
    let (earth_near, earth_f32) = earth_sweep(seed, cases, &mut errors[SPHERE_VARIANTS..]);
    Sample {
        cases,
        near,
        earth_near,
        errors,
        earth_f32,
    }
}

/// The real-Earth rows: `cases` draws of the real-Earth envelope
/// (`core_math::sample::SplitMix64::earth_case`, WGS 84, eccentric orbits, agile attitude,
/// terrain, p1 != 0) that the reference accepts; error |dv| / |v| (the vector
/// difference) against `EarthReference` at the inputs as given. Returns how many lie
/// within `NEAR_LIMB_DEG` of the limb, and the f32 errors split by condition number.
fn earth_sweep(seed: u64, cases: usize, errors: &mut [Errors]) -> (usize, EarthF32Split) {
    let mut split = EarthF32Split::default();
    let mut rng = Rng(seed ^ 0xEA27_0000_0000_0000);
    let (mut done, mut near) = (0, 0);
    while done < cases {
        let Some(c) = rng.earth_case() else { continue };
        let Ok(r) = EarthReference.evaluate(&c.camera, &c.geometry, c.n_px) else {
            continue;
        };
        let Ok(margin) = earth::limb_margin_rad(&c.geometry, &c.camera, c.n_px) else {
            continue;
        };
        done += 1;
        let is_near = margin.to_degrees() < NEAR_LIMB_DEG;
        near += usize::from(is_near);
        let motions = [
            Some(r),
            GENERAL_F64.evaluate(&c.camera, &c.geometry, c.n_px).ok(),
            GENERAL_F32_MOTION(&c.camera, &c.geometry, c.n_px).ok(),
            EARTH_FIXED_MOTION(&c.camera, &c.geometry, c.n_px).ok(),
        ];
        let sp = r.speed_mps();
        let rel = |m: ImageMotion<f64>| (m.v1_mps - r.v1_mps).hypot(m.v2_mps - r.v2_mps) / sp;
        let f32_err = motions[2].map(rel);
        for (e, m) in errors.iter_mut().zip(motions) {
            e.push(m.map(rel), is_near);
        }
        let (Some(err), true) = (f32_err, margin.to_degrees() >= 0.01) else {
            continue;
        };
        let Ok(kappa) = earth_kappa(&c.camera, &c.geometry, c.n_px) else {
            continue;
        };
        split.all += 1;
        split.ratio = split.ratio.max(err / (kappa * U_F32));
        if kappa > EARTH_F32_KAPPA_LIMIT {
            split.stiff += 1;
        } else if is_near {
            split.near = split.near.max(err);
        } else {
            split.far = split.far.max(err);
        }
    }
    (near, split)
}

const HEADER: [&str; 10] = [
    "variant",
    "max_rel_err",
    "p99_rel_err",
    "max_rel_err_near_limb",
    "instr_per_pixel",
    "instr_per_update",
    "flash_bytes",
    "m3_instr_per_pixel",
    "m3_instr_per_update",
    "m3_flash_bytes",
];
type Row = [String; 10];

fn print_table(
    sample: &Sample,
    runs: &[(BenchCounts, Vec<u64>)],
    csv: bool,
    seed: u64,
) -> Result<Vec<Row>> {
    let notes = format!(
        "{} cases (seed {seed:#x}), {} within {NEAR_LIMB_DEG} deg of the limb; errors of |v_P| \
         relative to the f64 reference chain (reference: 0 by definition); earth rows: {} \
         cases of the real-Earth envelope, {} within {NEAR_LIMB_DEG} deg of the limb, error \
         |dv|/|v| against EarthReference; instructions: \
         Cortex-M4F (mps2-an386) and, m3_ columns, Cortex-M3 without FPU (mps2-an385) under \
         QEMU {}, release, per pixel = motion over {LOOP_PX} pixels in a \
         loop / {LOOP_PX}, per update = update + motion at the default scene's planned \
         sample points, instructions not cycles; flash_bytes = loadable bytes the backend's \
         pixel + update + motion add to an empty binary (xtask/src/footprint.rs)",
        sample.cases,
        sample.near,
        sample.cases,
        sample.earth_near,
        runs.first()
            .map_or("(not run: --no-bench)", |(c, _)| c.qemu_version.as_str()),
    );
    let mut rows = Vec::new();
    for (i, (v, e)) in VARIANTS.iter().zip(&sample.errors).enumerate() {
        let name = v.0;
        let mut far = e.far.clone();
        let p99 = percentile(&mut far, 0.99);
        let max = far.last().copied().unwrap_or(0.0);
        let mut row: Row = Default::default();
        row[0] = name.to_string();
        row[1] = format!("{max:.2e}");
        row[2] = format!("{p99:.2e}");
        row[3] = format!("{:.2e}", e.max_near);
        for ((counts, flash), cells) in runs.iter().zip(row[4..].chunks_mut(3)) {
            let count = |label: &str| -> Result<u64> {
                counts
                    .net(label)
                    .with_context(|| format!("report: no bench region `{label}`"))
            };
            cells[0] = format!("{:.1}", count(&v.loop_label())? as f64 / LOOP_PX as f64);
            cells[1] = count(&v.full_update_label())?.to_string();
            cells[2] = flash.get(i).map_or(String::new(), |b| b.to_string());
        }
        rows.push(row);
        if e.refused > 0 {
            eprintln!(
                "report: {name} refused {} case(s) the reference accepts (not in its errors)",
                e.refused
            );
        }
    }
    let split = &sample.earth_f32;
    let notes = format!(
        "{notes}. earth-f32 against the problem's condition number kappa \
         (core_math::accuracy::earth_kappa): where kappa <= 30, max {:.2e} at least 1 deg \
         from the limb and {:.2e} at 0.01-1 deg; kappa > 30 in {} of {} cases at least \
         0.01 deg from the limb; max err / (kappa u32) over all of them {:.2}",
        split.far, split.near, split.stiff, split.all, split.ratio
    );
    if csv {
        eprintln!("report: {notes}");
        let mut out = crate::csv::Writer::new("", &HEADER)?;
        for r in &rows {
            out.row(r)?;
        }
        print!("{}", out.into_string()?);
    } else {
        println!("{notes}\n");
        print!("{}", markdown::table(&HEADER, &rows));
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_between_the_markers_is_replaced_and_the_rest_kept() {
        let doc = format!("intro\n{BEGIN}\nold table\n{END}\nreading\n");
        let row = ["f32", "1e-7", "1e-7", "1e-7", "87", "5264", "", "", "", ""].map(String::from);
        let new = replace_table(&doc, &[row], "model error").unwrap();
        assert!(new.starts_with("intro\n"));
        assert!(new.ends_with(&format!("{END}\nreading\n")));
        assert!(!new.contains("old table"));
        assert!(new.contains("| f32 | 1e-7 | 1e-7 | 1e-7 | 87 | 5264 |  |  |  |  |"));
        assert!(new.contains("|  |\n\nmodel error\n\n<!-- report:end"));
        assert!(replace_table("no markers", &[], "").is_none());
    }
}
