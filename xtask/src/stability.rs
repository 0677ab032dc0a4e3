//! `cargo xtask stability [--quick]`: maps of the f32 and fixed-point error of |v_P|
//! against the f64 reference over the envelope, with the problem's condition number.
//!
//! Three 2-D maps (altitude x limb margin, roll x field angle, inclination x argument of
//! latitude), each cell the worst of a few sub-samples. Per sample: the f32 error at
//! f32-rounded inputs against the reference at the same inputs and at the unrounded
//! ones, the fixed-point error, and kappa = sum_i |d ln|v_P| / d ln x_i| over the
//! rounded inputs (central differences of the reference). The full run rewrites
//! docs/stability.md (from `stability/template.md`, every number filled in here) and the
//! PNG maps under docs/stability/; `--quick` sweeps a coarser grid and only prints.
//! Both fail if any sample breaks the stated bound err <= C kappa u.

mod doc;
mod general;
mod general_fixed;
mod grid;
mod maps;
mod point;

use anyhow::{bail, Context, Result};
use std::collections::BTreeMap;
use std::time::Instant;

// Map A's limb-margin bands are the accuracy report's buckets, so that its table and
// this document's split the margin the same way.
use crate::accuracy::U_F32;
use crate::accuracy::{bucket, BUCKETS_DEG};
use crate::markdown::{e2, f2, sig, sig_range};
use doc::{describe, parts, COLUMNS};
use maps::{Cell, Map, MAPS};
use point::{Point, U_FIXED};

/// The stated bounds: f32 error (at the same or at the unrounded inputs) <= C_F32 kappa u,
/// fixed error <= C_FIXED kappa u_fx, at every sample of every map.
pub const C_F32: f64 = 5.0;
pub const C_FIXED: f64 = 1.0;

const DOC: &str = "docs/stability.md";
const PNG_DIR: &str = "docs/stability";
const TEMPLATE: &str = include_str!("stability/template.md");

/// `--quick`: a third of the cells in each direction, two sub-samples each (the general
/// maps keep all of theirs).
const QUICK: (usize, Option<usize>) = (3, Some(2));

#[derive(clap::Args)]
pub struct Args {
    /// A third of the cells each way, 2 sub-samples: the summary tables only, no files
    #[arg(long)]
    quick: bool,
}

pub fn run(args: &Args) -> Result<()> {
    let quick = args.quick;
    let t0 = Instant::now();
    let (div, sub) = if quick { QUICK } else { (1, None) };
    let maps = grid::sweep_all(&MAPS, div, sub);
    let secs = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let gmaps: Vec<general::GMap> = grid::sweep_all(&general::GMAPS, div, None);
    let gsecs = t1.elapsed().as_secs_f64();
    let t2 = Instant::now();
    let xmaps: Vec<general_fixed::FMap> = grid::sweep_all(&general::GMAPS, div, None);
    let xsecs = t2.elapsed().as_secs_f64();
    let mut values = figures(&maps, secs);
    values.extend(general::figures(&gmaps, gsecs));
    values.extend(general::f32_figures(&gmaps));
    values.extend(general::figures(&xmaps, xsecs));
    println!("{}", values["summary_table"]);
    println!("{}", values["bound_line"]);
    println!("sweep: {} samples in {secs:.1} s", values["samples_total"]);
    println!("{}", values["G.table"]);
    println!("{}", values["G.bound_line"]);
    println!(
        "general model: {} cases in {gsecs:.1} s",
        values["G.samples"]
    );
    println!("{}", values["X.table"]);
    println!("{}", values["X.bound_line"]);
    println!(
        "general model, EARTH_FIXED: {} cases in {xsecs:.1} s",
        values["X.samples"]
    );
    if !quick {
        let root = crate::qemu::workspace_root();
        let dir = root.join(PNG_DIR);
        std::fs::create_dir_all(&dir).with_context(|| format!("creating {PNG_DIR}"))?;
        for m in &maps {
            doc::write_pngs(m, &dir)?;
        }
        for m in &gmaps {
            general::write_pngs(m, &dir)?;
        }
        for m in &xmaps {
            general_fixed::write_pngs(m, &dir)?;
        }
        let text = doc::fill(TEMPLATE, &values)?;
        std::fs::write(root.join(DOC), text).with_context(|| format!("writing {DOC}"))?;
        eprintln!("stability: wrote {DOC} and the maps under {PNG_DIR}/");
    }
    let mut bad = grid::broken(&maps);
    bad.extend(grid::broken(&gmaps));
    bad.extend(grid::broken(&xmaps));
    if !bad.is_empty() {
        bail!("stability bound broken:\n{}", bad.join("\n"));
    }
    Ok(())
}

/// Altitude bands of map A (km).
const ALT_BANDS_KM: [(f64, f64); 5] = [
    (200.0, 400.0),
    (400.0, 700.0),
    (700.0, 1000.0),
    (1000.0, 1500.0),
    (1500.0, 2000.0),
];

fn map_by_key<'a>(maps: &'a [Map], key: &str) -> &'a Map {
    maps.iter()
        .find(|m| m.spec.key == key)
        .expect("map keys are fixed")
}

/// Every value the document quotes, by template key.
fn figures(maps: &[Map], secs: f64) -> BTreeMap<String, String> {
    let mut v = BTreeMap::new();
    let mut put = |k: &str, s: String| {
        v.insert(k.to_string(), s);
    };
    put("secs", format!("{secs:.1}"));
    put(
        "threads",
        std::thread::available_parallelism()
            .map_or(1, |n| n.get())
            .to_string(),
    );
    // How far rounding a 45 deg roll to f32 can move the line of sight.
    let roll_ulp = U_F32 * std::f64::consts::FRAC_PI_4;
    put("roll_round_rad", e2(roll_ulp));
    put("roll_round_deg", e2(roll_ulp.to_degrees()));
    put("u_f32", e2(U_F32));
    put("u_fixed", e2(U_FIXED));
    put("c_f32", format!("{C_F32}"));
    put("c_fixed", format!("{C_FIXED}"));
    let total: u64 = maps.iter().map(|m| m.samples()).sum();
    put("samples_total", total.to_string());

    // Summary: one row per map, and the whole.
    let mut rows = Vec::new();
    for m in maps {
        let letter = m.spec.letter;
        let a = m.aggregate(|_, _| true);
        put(&format!("{letter}.grid"), m.grid_text(a.n.into()));
        put(&format!("{letter}.others"), m.spec.others.into());
        cell_figures(&mut put, letter, &a);
        rows.push((format!("{letter}: {}", m.spec.title), a));
    }
    let whole: Cell = grid::merged(maps);
    cell_figures(&mut put, "all", &whole);
    put(
        "bound_line",
        format!(
            "max err/(kappa u): f32 {:.2} (unrounded inputs {:.2}), bound {C_F32}; fixed {:.2}, bound {C_FIXED}",
            whole.ratio_f32.max, whole.ratio_f32_in.max, whole.ratio_fixed.max
        ),
    );
    let v1_all = whole.v1_term_ratio;
    rows.push(("all maps".into(), whole));
    put("summary_table", grid::table("map", &COLUMNS, &rows));

    // Map A by limb margin and by altitude.
    let a_map = map_by_key(maps, "altitude-limb");
    let band_rows: Vec<(String, Cell)> = BUCKETS_DEG
        .iter()
        .enumerate()
        .map(|(b, (_, name))| {
            (
                name.to_string(),
                a_map.aggregate(|_, y| bucket(10f64.powf(y)) == b),
            )
        })
        .collect();
    put(
        "limb_table",
        grid::table("limb margin", &COLUMNS, &band_rows),
    );
    cell_figures(&mut put, "limb", &band_rows[BUCKETS_DEG.len() - 1].1);
    cell_figures(&mut put, "far", &band_rows[0].1);
    if let Some((slope, n)) = doc::limb_slope(a_map, 0.1) {
        put("limb.slope", format!("{slope:.3}"));
        put("limb.slope_n", n.to_string());
    }
    let alt_rows: Vec<(String, Cell)> = ALT_BANDS_KM
        .iter()
        .map(|&(lo, hi)| {
            (
                format!("{lo:.0} - {hi:.0} km"),
                a_map.aggregate(|h, y| h >= lo && h < hi && 10f64.powf(y) >= 1.0),
            )
        })
        .collect();
    let first = "altitude (limb margin >= 1 deg)";
    put("altitude_table", grid::table(first, &COLUMNS, &alt_rows));
    cell_figures(&mut put, "alt_lo", &alt_rows[0].1);
    cell_figures(&mut put, "alt_hi", &alt_rows[alt_rows.len() - 1].1);
    // The fixed backend's bracket scale: |b/c0| in its units of 2^-10 rad/s (i0 97.98 deg).
    for h_km in [200.0, 2000.0] {
        let g = Point::circular(0.0, 0.0, maps::I0_SSO_DEG, 0.0, h_km).g;
        let h = g.altitude_m / g.earth_radius_m;
        let b = g.earth_rate_rad_s * g.inclination_rad.cos() - g.orbit_rate_rad_s;
        put(
            &format!("bc0.{h_km:.0}"),
            format!("{:.1}", (b / (h * (2.0 + h))).abs() * 1024.0),
        );
    }
    // Where map A's fixed error peaks, and where the fixed backend switches to its
    // near-limb form there (m = 1 - k|sin eta| = 2^-12, i.e. delta ~ 2^-12 / sqrt(c0)).
    if let Some((ix, iy)) = a_map.argmax(|c| c.err.fixed_worst()) {
        let (h_km, y) = a_map.centre(ix, iy);
        let c = &a_map.cells[iy * a_map.nx + ix];
        put(
            "A.max_e_fixed.cell",
            format!("H {h_km:.0} km, limb margin {} deg", sig(10f64.powf(y))),
        );
        put("A.max_e_fixed", e2(c.err.fixed_worst()));
        let h = h_km / (point::EARTH_RADIUS_M / 1e3);
        let switch = (2f64.powi(-12) / (h * (2.0 + h)).sqrt()).to_degrees();
        put("A.max_e_fixed.switch_deg", sig(switch));
        let q2 = 2.0 * (h * (2.0 + h)).sqrt() * (switch.to_radians());
        put("A.max_e_fixed.switch_q", sig(q2.sqrt()));
        put("A.max_e_fixed.times_q", e2(c.err.fixed_worst() * q2.sqrt()));
    }

    // Map B: where the limb is (its cells' closest approach is `B.min_margin_deg`).
    let b_limb = (point::EARTH_RADIUS_M / (point::EARTH_RADIUS_M + 645e3)).asin();
    put("B.limb_deg", f2(b_limb.to_degrees()));

    // Map C: v1's two terms.
    let c_map = map_by_key(maps, "inclination-latitude");
    if let Some((ix, iy)) = c_map.argmax(|c| c.v1_term_ratio) {
        let (x, y) = c_map.centre(ix, iy);
        put(
            "v1.max",
            format!("{:.4}", c_map.cells[iy * c_map.nx + ix].v1_term_ratio),
        );
        put("v1.at", format!("i0 {x:.1} deg, g0 {y:.1} deg"));
    }
    // The bound on the ratio over the envelope: w sqrt(c0) / sqrt(Omega^2 - w^2) at
    // 2000 km (largest c0, smallest Omega), reached at the limb with cos(i0) = w/Omega.
    let g = point::Point::circular(0.0, 0.0, 0.0, 0.0, 2000.0).g;
    let h = g.altitude_m / g.earth_radius_m;
    let c0 = h * (2.0 + h);
    let (w, om) = (g.earth_rate_rad_s, g.orbit_rate_rad_s);
    put(
        "v1.bound",
        format!("{:.4}", w * c0.sqrt() / (om * om - w * w).sqrt()),
    );
    put(
        "v1.bound_i0",
        format!("{:.1}", (w / om).acos().to_degrees()),
    );
    put("v1.max_all", format!("{v1_all:.4}"));
    let c_cells_min = c_map
        .cells
        .iter()
        .filter(|c| c.n > 0)
        .map(|c| c.kappa.max)
        .fold(f64::INFINITY, f64::min);
    put("C.kappa_cells_min", sig(c_cells_min));
    put("v1.max_all_pct", format!("{:.1}", 100.0 * v1_all));
    put("v1.factor", format!("{:.3}", 1.0 / (1.0 - v1_all)));
    v
}

/// The values the document may quote about an aggregate of cells, as (`{p}.<what>`,
/// text), and about the sample behind each of its maxima (`{p}.<maximum>.<what>`: where
/// it is, kappa and its parts, the errors). Every aggregate gets the same set, so that
/// the template can quote any of them the same way; the keys it does not use are ignored
/// by [`doc::fill`].
fn cell_figures(put: &mut impl FnMut(&str, String), p: &str, a: &Cell) {
    let mut put = |what: &str, s: String| put(&format!("{p}.{what}"), s);
    put("ratio_f32", f2(a.ratio_f32.max));
    put("ratio_f32_in", f2(a.ratio_f32_in.max));
    put("ratio_fixed", f2(a.ratio_fixed.max));
    put("kappa_min", sig(a.kappa_min));
    put("kappa_max", sig(a.kappa.max));
    put("kappa_range", sig_range(a.kappa_min, a.kappa.max));
    put("kq", sig_range(a.kq.0, a.kq.1));
    put("min_margin_deg", sig(a.min_margin_rad.to_degrees()));
    put("e_f32", e2(a.err.f32));
    put("e_f32_in", e2(a.err.f32_in));
    put("e_fixed", e2(a.err.fixed_worst()));
    for (what, w) in [
        ("worst_f32", &a.ratio_f32),
        ("worst_fixed", &a.ratio_fixed),
        ("max_kappa", &a.kappa),
    ] {
        let Some((pt, o)) = &w.at else { continue };
        put(&format!("{what}.at"), describe(pt, o));
        put(&format!("{what}.kappa"), sig(o.kappa));
        put(&format!("{what}.parts"), parts(o));
        put(&format!("{what}.e_f32"), e2(o.err.f32));
        // In units of u, for the whole's worst f32 case.
        put(
            &format!("{what}.e_f32_u"),
            format!("{:.1}", o.err.f32 / U_F32),
        );
        put(&format!("{what}.e_fixed"), e2(o.err.fixed_worst()));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core_math::accuracy::{EARTH_F32_KAPPA_C, EARTH_F32_REL_TOLERANCE};

    /// A coarse version of the three maps (every dimension / 6, two sub-samples per
    /// cell) meets the document's bounds err <= C kappa u at every sample, and the
    /// check is not vacuous: the maps reach the limb, the backends' errors are real
    /// (not a comparison of the reference with itself), and the bounds are not loose
    /// by orders of magnitude.
    #[test]
    fn coarse_maps_stay_within_the_stated_bounds() {
        let maps: Vec<Map> = grid::sweep_all(&MAPS, 6, Some(2));
        let bad = grid::broken(&maps);
        assert!(bad.is_empty(), "{}", bad.join("\n"));
        let a: Cell = grid::merged(&maps);
        assert!(a.n > 2_000, "{} cases", a.n);
        assert_eq!(a.refused, 0);
        // The limb: map A's lowest row is within 1e-4 deg, where kappa is in the thousands.
        assert!(a.kappa.max > 1e3, "max kappa {}", a.kappa.max);
        // kappa >= 3 everywhere: altitude, radius and orbit rate contribute ~1 each.
        assert!(a.kappa_min > 2.5, "min kappa {}", a.kappa_min);
        // Real errors: several u for f32, the input rounding near the limb, a few LSB fixed.
        assert!(a.err.f32 > 3.0 * U_F32, "f32 err {}", a.err.f32);
        assert!(
            a.err.f32_in > 1e-5,
            "f32 err at unrounded inputs {}",
            a.err.f32_in
        );
        assert!(
            a.err.fixed_worst() > U_FIXED,
            "fixed err {}",
            a.err.fixed_worst()
        );
        // Tight enough to mean something.
        assert!(
            a.ratio_f32.max.max(a.ratio_f32_in.max) > 0.3 * C_F32,
            "{}",
            a.ratio_f32.max
        );
        assert!(a.ratio_fixed.max > 0.05 * C_FIXED, "{}", a.ratio_fixed.max);
    }

    /// The general model's maps, every dimension / 4 (all sub-samples): GENERAL_F32
    /// meets err <= EARTH_F32_KAPPA_C kappa u32 at every case at least 0.01 deg inside
    /// the limb, refuses nothing the reference accepts, and the check is not vacuous: the
    /// maps reach within 0.02 deg of the limb and the cancelling rates, kappa in the
    /// hundreds, errors past the 2e-6 bound, and a ratio that is a fair part of C.
    #[test]
    fn general_coarse_maps_stay_within_c_kappa_u() {
        let maps: Vec<general::GMap> = grid::sweep_all(&general::GMAPS, 4, None);
        let bad = grid::broken(&maps);
        assert!(bad.is_empty(), "{}", bad.join("\n"));
        let a: general::GCell = grid::merged(&maps);
        assert!(a.n > 5_000, "{} cases", a.n);
        assert_eq!(a.refused, 0);
        assert!(a.min_margin_rad.to_degrees() < 0.02, "{}", a.min_margin_rad);
        assert!(a.kappa.max > 300.0, "max kappa {}", a.kappa.max);
        // Real errors: past the 2e-6 bound where kappa is large, several u elsewhere.
        assert!(
            a.err.max > 5.0 * EARTH_F32_REL_TOLERANCE,
            "f32 err {}",
            a.err.max
        );
        assert!(a.over_tol > 0);
        assert!(
            a.ratio.max > 0.3 * EARTH_F32_KAPPA_C,
            "max err/(kappa u) {}",
            a.ratio.max
        );
        // The rate maps reach the cancellation: kappa there dwarfs the angle maps'.
        let rates = maps.iter().find(|m| m.spec.letter == "F'").unwrap();
        assert!(rates.aggregate(|_, _| true).kappa.max > 1e3);
    }

    /// EARTH_FIXED over the same five maps, every dimension / 4: within the issue's
    /// targets (2e-5 from 0.01 deg, 2e-6 from 1 deg where kappa <= 30), no refusal and no
    /// non-finite result; not vacuous: the maps reach 0.02 deg of the limb, the errors are
    /// real (the backend's Q25-Q33 roundings, not the reference against itself), and the
    /// far-field check is exercised at kappa <= 30.
    #[test]
    fn general_fixed_coarse_maps_meet_the_targets() {
        let maps: Vec<general_fixed::FMap> = grid::sweep_all(&general::GMAPS, 4, None);
        let bad = grid::broken(&maps);
        assert!(bad.is_empty(), "{}", bad.join("\n"));
        let a: general::GCell<general_fixed::Fixed> = grid::merged(&maps);
        assert!(a.n > 5_000, "{} cases", a.n);
        assert_eq!((a.refused, a.non_finite), (0, 0));
        assert!(a.min_margin_rad.to_degrees() < 0.02, "{}", a.min_margin_rad);
        assert!(a.err.max > 1e-8, "fixed err {}", a.err.max);
        assert!(a.near.at.is_some() && a.tame.at.is_some());
        assert!(a.tame.max > 1e-9, "far err {}", a.tame.max);
    }

    /// |v_P| = f x (angular rate) x a function of h = H/R and the angles: scaling H and R
    /// together changes nothing, so their parts of kappa must be equal (a check of the
    /// finite differences on the reference). And toward the limb kappa ~ 1/q.
    #[test]
    fn condition_number_parts_obey_the_scalings() {
        for (roll, field, h_km) in [
            (10.0, 5.0, 645.0),
            (40.0, 20.0, 700.0),
            (-30.0, -9.0, 200.0),
        ] {
            let pt = Point::circular(roll, field, 97.98, 60.0, h_km);
            let o = point::evaluate(&pt).unwrap();
            let (h, r) = (o.kappa_parts[4], o.kappa_parts[5]);
            assert!((h - r).abs() <= 1e-6 * h.max(1.0), "{h} vs {r}");
            assert!(o.kappa >= o.kappa_parts.iter().copied().fold(0.0, f64::max));
        }
        // Near the limb kappa ~ 1/q: kappa q stays of order one over a decade of q.
        let mut kq = Vec::new();
        for margin_deg in [1e-2, 1e-3, 1e-4] {
            let limb = (6371.0f64 / (6371.0 + 645.0)).asin().to_degrees();
            let pt = Point::circular(40.0, limb - margin_deg - 40.0, 97.98, 60.0, 645.0);
            let o = point::evaluate(&pt).unwrap();
            kq.push(o.kappa * o.q);
        }
        let (lo, hi) = kq
            .iter()
            .fold((f64::MAX, 0.0f64), |(l, h), &x| (l.min(x), h.max(x)));
        assert!(lo > 0.5 && hi < 2.0 * lo, "{kq:?}");
    }
}
