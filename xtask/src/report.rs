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
//! Run time: guest instructions on the Cortex-M4 under QEMU from `cargo xtask bench`
//! (the same build, the same plugin, [`crate::target::bench_counts`]): `motion` for one
//! pixel at n = 0 and one `update`. Instructions, not cycles.
//!
//! `flash_bytes` is left empty: with fat LTO every backend is inlined into the bench's
//! regions, so no symbol size measures one backend's code honestly.

use core_math::fixed_point::{geometry_from_f64, motion_to_f64};
use core_math::{Backend, Camera, Geometry, NaiveF32, Reference, CLOSED_F32, CLOSED_F64, FIXED};

use crate::target::{bench_counts, BenchCounts};
use core_math::sample::SplitMix64 as Rng;

const USAGE: &str = "usage: report [--csv] [--cases N] [--seed S] [--no-bench]";
const DEFAULT_CASES: usize = 200_000;
const DEFAULT_SEED: u64 = 0x5EED_2013_0605_0750;
const CAMERA: Camera = Camera {
    focal_m: 0.555,
    pixel_m: 13e-6,
};
/// "Near the limb": the line of sight within this angle (deg) of the limb.
const NEAR_LIMB_DEG: f64 = 1.0;

/// The backends, in report order, with their bench labels (motion at n = 0, update).
const VARIANTS: [(&str, &str, &str); 5] = [
    (
        "naive-f32",
        "NaiveF32 motion, 1 pixel (n = 0)",
        "NaiveF32 update (checks and stores the geometry)",
    ),
    (
        "reference",
        "Reference motion (f64 chain), 1 pixel (n = 0)",
        "Reference update (checks and stores the geometry)",
    ),
    (
        "f64",
        "CLOSED_F64 motion, 1 pixel (n = 0)",
        "CLOSED_F64 update",
    ),
    (
        "f32",
        "CLOSED_F32 motion, 1 pixel (n = 0)",
        "CLOSED_F32 update (once per telemetry update)",
    ),
    (
        "fixed",
        "FIXED motion, 1 pixel (n = 0; integer only)",
        "FIXED update (once per telemetry update; integer only)",
    ),
];

#[derive(Default)]
struct Errors {
    far: Vec<f64>,
    max_near: f64,
    refused: u64,
}

struct Sample {
    cases: usize,
    near: usize,
    errors: Vec<Errors>,
}

pub fn run(args: &[String]) -> Result<(), String> {
    let mut csv = false;
    let mut bench = true;
    let mut cases = DEFAULT_CASES;
    let mut seed = DEFAULT_SEED;
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--csv" => csv = true,
            "--no-bench" => bench = false,
            "--cases" => {
                cases = it
                    .next()
                    .and_then(|v| v.parse().ok())
                    .filter(|&n| n > 0)
                    .ok_or_else(|| format!("report: --cases needs a positive count ({USAGE})"))?;
            }
            "--seed" => {
                seed = it
                    .next()
                    .and_then(|v| parse_seed(v))
                    .ok_or_else(|| format!("report: --seed needs an integer ({USAGE})"))?;
            }
            other => return Err(format!("report: unknown argument `{other}` ({USAGE})")),
        }
    }
    let sample = sweep(seed, cases);
    let counts = if bench {
        Some(bench_counts(true)?)
    } else {
        None
    };
    let rows = print_table(&sample, counts.as_ref(), csv, seed)?;
    // The default (full sample, bench run, markdown) regenerates the doc's table and plot.
    if !csv && counts.is_some() && cases == DEFAULT_CASES && seed == DEFAULT_SEED {
        write_artefacts(&rows)?;
    }
    Ok(())
}

const DOC: &str = "docs/error-vs-runtime.md";
const PNG: &str = "docs/error-vs-runtime.png";
const BEGIN: &str = "<!-- report:begin (written by `cargo xtask report`) -->";
const END: &str = "<!-- report:end -->";

/// `doc` with the markdown table of `rows` between its markers.
fn replace_table(doc: &str, rows: &[[String; 7]]) -> Option<String> {
    let b = doc.find(BEGIN)?;
    let e = doc[b..].find(END)? + b;
    let mut table = format!(
        "{BEGIN}\n\n| {} |\n|{}\n",
        HEADER.join(" | "),
        "---|".repeat(HEADER.len())
    );
    for r in rows {
        table.push_str(&format!("| {} |\n", r.join(" | ")));
    }
    table.push('\n');
    Some(format!("{}{table}{}", &doc[..b], &doc[e..]))
}

/// Replaces the table between the doc's markers and draws the plot: each variant's
/// worst error at least 1 deg from the limb (a cross) and within 1 deg (a slash, dashed)
/// against log10 of its instructions per pixel. The reference is the golden source
/// (error 0 by definition) and has no point on a log axis.
fn write_artefacts(rows: &[[String; 7]]) -> Result<(), String> {
    let root = crate::target::workspace_root();
    let doc_path = root.join(DOC);
    let doc = std::fs::read_to_string(&doc_path).map_err(|e| format!("reading {DOC}: {e}"))?;
    let new_doc = replace_table(&doc, rows).ok_or(format!("{DOC} lacks the report markers"))?;
    std::fs::write(&doc_path, new_doc).map_err(|e| format!("writing {DOC}: {e}"))?;
    let mut plot = crate::plot::Plot::new(
        "Error against run time, per backend (Cortex-M4 under QEMU)",
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
        let x = instr.log10();
        let c = crate::plot::Series::line(&r[0], vec![(x - 0.06, far), (x + 0.06, far)]);
        plot = plot
            .series(c.palette(i).width(3.0))
            .series(
                crate::plot::Series::line("", vec![(x, far / 1.6), (x, far * 1.6)])
                    .palette(i)
                    .width(3.0),
            )
            .series(
                crate::plot::Series::line("", vec![(x - 0.06, near / 1.6), (x + 0.06, near * 1.6)])
                    .palette(i)
                    .width(3.0)
                    .dashed(),
            );
    }
    plot.save(&root.join(PNG))?;
    eprintln!("report: wrote {DOC} (table) and {PNG}");
    Ok(())
}

fn parse_seed(v: &str) -> Option<u64> {
    match v.strip_prefix("0x") {
        Some(hex) => u64::from_str_radix(&hex.replace('_', ""), 16).ok(),
        None => v.parse().ok(),
    }
}

/// One case whose line of sight meets the Earth (per the reference), geometry rounded to
/// f32, and its limb margin (deg).
fn case(rng: &mut Rng) -> Option<(Geometry<f64>, f64, f64)> {
    let g = Geometry::circular(
        rng.uniform(-45.0, 45.0).to_radians(),
        rng.uniform(0.0, 180.0).to_radians(),
        rng.uniform(0.0, 360.0).to_radians(),
        rng.uniform(200e3, 2000e3),
        6_371e3,
    )
    .to::<f32>()
    .to_f64();
    let limb = libm::asin(g.earth_radius_m / (g.earth_radius_m + g.altitude_m));
    let alpha = if rng.next_u64() & 3 == 0 {
        let margin = libm::pow(10.0, rng.uniform(-5.0, 0.0)).to_radians();
        let side = if rng.next_u64() & 1 == 0 { 1.0 } else { -1.0 };
        side * (limb - margin) - g.roll_rad
    } else {
        rng.uniform(-40.0, 40.0).to_radians()
    };
    if alpha.abs() > 40f64.to_radians() {
        return None;
    }
    let n_px = libm::tan(alpha) * CAMERA.focal_m / CAMERA.pixel_m;
    let margin = core_math::accuracy::limb_margin_rad(&CAMERA, &g, n_px).ok()?;
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
        let speeds: [Option<f64>; 5] = [
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
            geometry_from_f64(&g)
                .and_then(|gq| FIXED.evaluate(&CAMERA, &gq, n_px))
                .ok()
                .map(|m| motion_to_f64(&m).speed_mps()),
        ];
        let sp = r.speed_mps();
        for (e, s) in errors.iter_mut().zip(speeds) {
            let Some(s) = s else {
                e.refused += 1;
                continue;
            };
            let rel = (s - sp).abs() / sp;
            if is_near {
                e.max_near = e.max_near.max(rel);
            } else {
                e.far.push(rel);
            }
        }
    }
    Sample {
        cases,
        near,
        errors,
    }
}

const HEADER: [&str; 7] = [
    "variant",
    "max_rel_err",
    "p99_rel_err",
    "max_rel_err_near_limb",
    "instr_per_pixel",
    "instr_per_update",
    "flash_bytes",
];

fn print_table(
    sample: &Sample,
    counts: Option<&BenchCounts>,
    csv: bool,
    seed: u64,
) -> Result<Vec<[String; 7]>, String> {
    let notes = format!(
        "{} cases (seed {seed:#x}), {} within {NEAR_LIMB_DEG} deg of the limb; errors of |v_P| \
         relative to the f64 reference chain (reference: 0 by definition); instructions: \
         Cortex-M4 under QEMU {}, release, motion at n = 0 and one update, instructions \
         not cycles; flash_bytes not measured (fat LTO inlines every backend)",
        sample.cases,
        sample.near,
        counts.map_or("(not run: --no-bench)", |c| c.qemu_version.as_str()),
    );
    let mut rows = Vec::new();
    for ((name, motion, update), e) in VARIANTS.iter().zip(&sample.errors) {
        let mut far = e.far.clone();
        far.sort_by(f64::total_cmp);
        let max = far.last().copied().unwrap_or(0.0);
        let p99 = far
            .get(((far.len().max(1) - 1) as f64 * 0.99).round() as usize)
            .copied()
            .unwrap_or(0.0);
        let count = |label: &str| -> Result<String, String> {
            match counts {
                None => Ok(String::new()),
                Some(c) => c
                    .net(label)
                    .map(|n| n.to_string())
                    .ok_or_else(|| format!("report: no bench region `{label}`")),
            }
        };
        rows.push([
            name.to_string(),
            format!("{max:.2e}"),
            format!("{p99:.2e}"),
            format!("{:.2e}", e.max_near),
            count(motion)?,
            count(update)?,
            String::new(),
        ]);
        if e.refused > 0 {
            eprintln!(
                "report: {name} refused {} case(s) the reference accepts (not in its errors)",
                e.refused
            );
        }
    }
    if csv {
        eprintln!("report: {notes}");
        println!("{}", HEADER.join(","));
        for r in &rows {
            println!("{}", r.join(","));
        }
    } else {
        println!("{notes}\n");
        println!("| {} |", HEADER.join(" | "));
        println!("|{}", "---|".repeat(HEADER.len()));
        for r in &rows {
            println!("| {} |", r.join(" | "));
        }
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_between_the_markers_is_replaced_and_the_rest_kept() {
        let doc = format!("intro\n{BEGIN}\nold table\n{END}\nreading\n");
        let row = ["f32", "1e-7", "1e-7", "1e-7", "87", "5264", ""].map(String::from);
        let new = replace_table(&doc, &[row]).unwrap();
        assert!(new.starts_with("intro\n"));
        assert!(new.ends_with(&format!("{END}\nreading\n")));
        assert!(!new.contains("old table"));
        assert!(new.contains("| f32 | 1e-7 | 1e-7 | 1e-7 | 87 | 5264 |  |"));
        assert!(replace_table("no markers", &[]).is_none());
    }
}
