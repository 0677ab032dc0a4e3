//! `cargo xtask paper`: the worked example of the paper's Section 5 (Figs. 5-8) from
//! the independent reference chain, as CSV and PNG under `docs/paper/`, with a summary
//! of the headline numbers next to the paper's and a table of candidate explanations
//! for where they differ. `docs/paper-reproduction.md` discusses the results.
//!
//! Everything is computed with [`core_math::sphere::Reference`] (the paper's transform chain,
//! Eqs. 1-13, on dual numbers). The only other formulas here are in [`Variant`]: the
//! paper's printed Eq. 14 with switches for the suspected mistakes, used only to explain
//! the differences, never to produce our numbers; with every switch off it is checked
//! against the reference before anything is written.
//!
//! Conventions: paper pixel p (0 = near point, 60 000 = far point, rolling left) is
//! array offset n = p - 30 000; velocities are reported as magnitudes in mm/s.

use anyhow::{anyhow, bail, Context, Result};
use std::path::PathBuf;

use core_math::sphere::{Geometry, Reference};
use core_math::{mtf_mismatch, Backend, Camera, ImageMotion, StageRule, EARTH_RATE_RAD_S};

use crate::csv::Writer;
use crate::markdown::f2;
use crate::plot::{Legend, Plot, Series};

/// Section 5's camera: f = 555 mm, A = 13 um.
const CAMERA: Camera = Camera {
    focal_m: 0.555,
    pixel_m: 13.0e-6,
};
const ALTITUDE_M: f64 = 645.0e3;
const EARTH_RADIUS_M: f64 = 6370.0e3;
/// Not given in the paper: sun-synchronous at 645 km.
const INCLINATION_DEG: f64 = 97.98;
/// Paper pixel of the array centre (60 000 pixels, |N| <= 30 000).
const CENTRE_PX: f64 = 30_000.0;
const NEAR_PX: f64 = 0.0;
const FAR_PX: f64 = 60_000.0;

/// Figs. 6-7 grid: roll 0..=25 deg by 0.5, gamma0 0..=90 deg by 5.
const ROLL_STEPS: usize = 50;
const ROLL_MAX_DEG: f64 = 25.0;
const G0_STEPS: usize = 18;
const G0_MAX_DEG: f64 = 90.0;
/// Fig. 8: gamma0 by 1 deg, these stage counts, this MTF floor.
const FIG8_STAGES: [u32; 6] = [8, 16, 24, 32, 48, 64];
const MTF_FLOOR: f64 = 0.95;
const STAGE_LIMIT: u32 = 512;

/// The paper's numbers (Section 5).
mod published {
    /// Min and max |v| (mm/s) and (max - min) / min (%), at the near and the far point.
    pub const NEAR: (f64, f64, f64) = (5.81, 7.26, 24.9);
    pub const FAR: (f64, f64, f64) = (3.65, 5.97, 63.5);
    pub const MTF_M48: f64 = 0.681;
    pub const MAX_STAGES: u32 = 16;
}

fn deg_steps(max_deg: f64, steps: usize) -> Vec<f64> {
    (0..=steps)
        .map(|k| max_deg * k as f64 / steps as f64)
        .collect()
}

fn geometry(roll_deg: f64, g0_deg: f64, i0_deg: f64) -> Geometry<f64> {
    Geometry::circular(
        roll_deg.to_radians(),
        i0_deg.to_radians(),
        g0_deg.to_radians(),
        ALTITUDE_M,
        EARTH_RADIUS_M,
    )
}

/// The reference image motion of paper pixel `paper_px` (m/s).
fn motion(paper_px: f64, roll_deg: f64, g0_deg: f64) -> Result<ImageMotion<f64>> {
    motion_i0(paper_px, roll_deg, g0_deg, INCLINATION_DEG)
}

fn motion_i0(paper_px: f64, roll_deg: f64, g0_deg: f64, i0_deg: f64) -> Result<ImageMotion<f64>> {
    Reference
        .evaluate(
            &CAMERA,
            &geometry(roll_deg, g0_deg, i0_deg),
            paper_px - CENTRE_PX,
        )
        .map_err(|e| {
            anyhow!(
                "reference at pixel {paper_px}, roll {roll_deg} deg, gamma0 {g0_deg} deg: {e:?}"
            )
        })
}

fn mm_s(x: f64) -> f64 {
    x * 1e3
}

/// min, max, (max - min)/min, (max - min)/max of a non-empty list.
#[derive(Clone, Copy, Debug)]
struct Range {
    min: f64,
    max: f64,
}

impl Range {
    fn of(values: impl IntoIterator<Item = f64>) -> Option<Range> {
        let mut r: Option<Range> = None;
        for v in values {
            if !v.is_finite() {
                return None;
            }
            r = Some(match r {
                None => Range { min: v, max: v },
                Some(r) => Range {
                    min: r.min.min(v),
                    max: r.max.max(v),
                },
            });
        }
        r
    }
    fn change_over_min_pct(&self) -> f64 {
        100.0 * (self.max - self.min) / self.min
    }
    fn change_over_max_pct(&self) -> f64 {
        100.0 * (self.max - self.min) / self.max
    }
}

/// The paper's Eq. 14 for v_P1 (from Eqs. 1-6), with a switch for each suspected
/// mistake; v_P2 is taken from the reference chain. Only for explaining differences.
#[derive(Clone, Copy, Debug)]
struct Variant {
    name: &'static str,
    /// g2 = H tan(eta), g3 = 0 (slant range H / cos eta) instead of the sphere.
    flat_earth: bool,
    /// The cross term f w g2 (cos(i0 + g0) - cos(i0 - g0)) as printed, rather than
    /// the half of it that differentiating the chain gives.
    printed_cross_term: bool,
    i0_deg: f64,
    /// alpha = N A / f instead of atan(N A / f) (Eq. 2).
    linear_field: bool,
    /// beta = asin(...) instead of pi - asin(...) in Eq. 1.
    acute_branch: bool,
}

const CHAIN: Variant = Variant {
    name: "chain, as derived (ours)",
    flat_earth: false,
    printed_cross_term: false,
    i0_deg: INCLINATION_DEG,
    linear_field: false,
    acute_branch: false,
};

const VARIANTS: [Variant; 8] = [
    CHAIN,
    Variant {
        name: "Eq. 14 as printed (cross term x2)",
        printed_cross_term: true,
        ..CHAIN
    },
    Variant {
        name: "flat Earth (slant range H/cos(eta))",
        flat_earth: true,
        ..CHAIN
    },
    Variant {
        name: "flat Earth + Eq. 14 as printed",
        flat_earth: true,
        printed_cross_term: true,
        ..CHAIN
    },
    Variant {
        name: "i0 = 90 deg",
        i0_deg: 90.0,
        ..CHAIN
    },
    Variant {
        name: "i0 = 82.02 deg (180 - 97.98)",
        i0_deg: 180.0 - INCLINATION_DEG,
        ..CHAIN
    },
    Variant {
        name: "alpha = N A / f (no atan)",
        linear_field: true,
        ..CHAIN
    },
    Variant {
        name: "beta = asin(..) (acute branch of Eq. 1)",
        acute_branch: true,
        ..CHAIN
    },
];

impl Variant {
    /// |v| in mm/s, or None where the line of sight misses the Earth.
    fn speed_mm_s(&self, paper_px: f64, roll_deg: f64, g0_deg: f64) -> Option<f64> {
        let v1 = self.v1(paper_px, roll_deg, g0_deg)?;
        // v_P2 of the reference chain at the same field angle and inclination.
        let x = (paper_px - CENTRE_PX) * CAMERA.pixel_m / CAMERA.focal_m;
        let n_ref = if self.linear_field {
            if x.abs() >= core::f64::consts::FRAC_PI_2 {
                return None;
            }
            x.tan() * CAMERA.focal_m / CAMERA.pixel_m
        } else {
            paper_px - CENTRE_PX
        };
        let v2 = motion_i0(n_ref + CENTRE_PX, roll_deg, g0_deg, self.i0_deg)
            .ok()?
            .v2_mps;
        Some(mm_s(v1.hypot(v2)))
    }

    /// v_P1 (m/s) from Eqs. 1-6 and Eq. 14.
    fn v1(&self, paper_px: f64, roll_deg: f64, g0_deg: f64) -> Option<f64> {
        let (r, h, f) = (EARTH_RADIUS_M, ALTITUDE_M, CAMERA.focal_m);
        let x = (paper_px - CENTRE_PX) * CAMERA.pixel_m / f;
        let alpha = if self.linear_field { x } else { x.atan() };
        let (phi, g0, i0) = (
            roll_deg.to_radians(),
            g0_deg.to_radians(),
            self.i0_deg.to_radians(),
        );
        let eta = phi + alpha;
        if eta.cos() <= 0.0 {
            return None;
        }
        let (g2, g3) = if self.flat_earth {
            (h * eta.tan(), 0.0)
        } else {
            let sin_beta = (h + r) * eta.sin() / r;
            if sin_beta.abs() >= 1.0 {
                return None;
            }
            let beta = if self.acute_branch {
                sin_beta.asin()
            } else {
                core::f64::consts::PI - sin_beta.asin()
            };
            let theta = core::f64::consts::PI - eta - beta;
            (r * theta.sin(), r * (theta.cos() - 1.0))
        };
        let g = geometry(roll_deg, g0_deg, self.i0_deg);
        let (w, big_omega) = (g.earth_rate_rad_s, g.orbit_rate_rad_s);
        let cross = if self.printed_cross_term { 1.0 } else { 0.5 };
        let num = f * (g3 + r) * (i0.cos() * w - big_omega)
            + cross * f * w * g2 * ((i0 + g0).cos() - (i0 - g0).cos());
        let den = phi.sin() * g2 - phi.cos() * g3 + phi.cos() * h;
        Some(num / den)
    }
}

/// Fig. 8's quantities at one point for one velocity model: relative mismatch
/// (v(g0) - v(0)) / v(0) over gamma0 with the line period held at gamma0 = 0.
struct MismatchSweep {
    g0_deg: Vec<f64>,
    speed_mm_s: Vec<f64>,
    rel: Vec<f64>,
}

impl MismatchSweep {
    fn new(speed: impl Fn(f64) -> Option<f64>) -> Option<Self> {
        let g0_deg = deg_steps(G0_MAX_DEG, 90);
        let speed_mm_s: Option<Vec<f64>> = g0_deg.iter().map(|&g| speed(g)).collect();
        let speed_mm_s = speed_mm_s?;
        let v_set = speed_mm_s[0];
        let rel = speed_mm_s.iter().map(|v| (v - v_set) / v_set).collect();
        Some(MismatchSweep {
            g0_deg,
            speed_mm_s,
            rel,
        })
    }

    fn worst_rel(&self) -> f64 {
        self.rel.iter().fold(0.0_f64, |a, &r| a.max(r.abs()))
    }

    /// The lowest MTF over the sweep for `stages`.
    fn min_mtf(&self, stages: u32) -> Result<f64> {
        let mut m = f64::INFINITY;
        for &r in &self.rel {
            m = m.min(mtf_mismatch(stages, r).map_err(|e| anyhow!("{e:?}"))?);
        }
        Ok(m)
    }

    /// Largest M with MTF >= floor everywhere on the sweep, from `StageRule`,
    /// cross-checked by trying every M.
    fn max_stages(&self) -> Result<u32> {
        let rule = StageRule::<f64>::new(MTF_FLOOR).map_err(|e| anyhow!("{e:?}"))?;
        let m = rule
            .max_stages(self.worst_rel(), STAGE_LIMIT)
            .map_err(|e| anyhow!("{e:?}"))?;
        let mut brute = 0;
        for k in 1..=STAGE_LIMIT {
            if self.min_mtf(k)? >= MTF_FLOOR {
                brute = k;
            } else {
                break;
            }
        }
        if brute != m {
            bail!("StageRule gives {m} stages, trying every M gives {brute}");
        }
        Ok(m)
    }
}

/// The Figs. 6-7 grid at one paper pixel: rows of (roll, gamma0, motion).
fn grid(paper_px: f64) -> Result<Vec<(f64, f64, ImageMotion<f64>)>> {
    let mut rows = Vec::new();
    for &phi in &deg_steps(ROLL_MAX_DEG, ROLL_STEPS) {
        for &g0 in &deg_steps(G0_MAX_DEG, G0_STEPS) {
            rows.push((phi, g0, motion(paper_px, phi, g0)?));
        }
    }
    Ok(rows)
}

struct Out {
    dir: PathBuf,
    written: Vec<PathBuf>,
}

impl Out {
    fn write(&mut self, name: &str, bytes: &[u8]) -> Result<()> {
        let path = self.dir.join(name);
        std::fs::write(&path, bytes).with_context(|| format!("writing {}", path.display()))?;
        self.written.push(path);
        Ok(())
    }
}

const GENERATED: &str = "# generated by `cargo xtask paper`; do not edit\n";

#[derive(clap::Args)]
pub struct Args {
    /// Where to write the CSV and PNG files [default: docs/paper]
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
}

pub fn run(args: &Args) -> Result<()> {
    let dir = match &args.out {
        Some(dir) => dir.clone(),
        None => crate::qemu::workspace_root().join("docs").join("paper"),
    };
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    let mut out = Out {
        dir,
        written: Vec::new(),
    };

    self_check()?;
    fig5(&mut out)?;
    let near = fig67(
        &mut out,
        "fig6_near_point",
        NEAR_PX,
        "Fig. 6: near point (paper pixel 0)",
    )?;
    let far = fig67(
        &mut out,
        "fig7_far_point",
        FAR_PX,
        "Fig. 7: far point (paper pixel 60000)",
    )?;
    let (mtf48, max_m, worst) = fig8(&mut out)?;
    summary(&mut out, near, far, mtf48, max_m, worst)?;
    hypotheses(&mut out)?;

    for p in &out.written {
        println!("wrote {}", p.display());
    }
    Ok(())
}

/// The Eq. 14 route with every switch off must be the chain's v_P1.
fn self_check() -> Result<()> {
    for &px in &[NEAR_PX, 15_000.0, CENTRE_PX + 1.0, 45_000.0, FAR_PX] {
        for &phi in &[0.0, 15.0, 25.0] {
            for &g0 in &[0.0, 37.0, 90.0] {
                let want = motion(px, phi, g0)?.v1_mps;
                let got = CHAIN.v1(px, phi, g0).context("Eq. 14 route failed")?;
                if (got - want).abs() > 1e-9 * want.abs() {
                    bail!(
                        "Eq. 14 route disagrees with the chain at pixel {px}, roll {phi}, \
                         gamma0 {g0}: {got} vs {want}"
                    );
                }
            }
        }
    }
    Ok(())
}

fn fig5(out: &mut Out) -> Result<()> {
    let rolls = [0.0, 15.0, 25.0];
    let g0s = deg_steps(G0_MAX_DEG, 90);
    let mut header = ["paper_pixel", "n_px", "field_angle_deg"]
        .map(String::from)
        .to_vec();
    for phi in rolls {
        header.extend(["g0_0", "g0_90", "min", "max"].map(|q| format!("phi{phi}_{q}_mm_s")));
    }
    let mut csv = Writer::new(
        &format!("{GENERATED}# |v| in mm/s; min/max over gamma0 in [0, 90] deg by 1 deg\n"),
        &header,
    )?;
    let mut plot = Plot::new(
        "Fig. 5: image-motion speed across the array (rolling left)",
        "paper pixel (0 = near point, 60000 = far point)",
        "speed v_P (mm/s)",
    )
    .x_range(0.0, 60_000.0)
    .legend(Legend::BottomLeft);
    for (j, phi) in rolls.iter().enumerate() {
        let label = |g0: &str| format!("phi = {phi} deg, gamma0 = {g0}");
        let gamma0_0 = Series::line(&label("0"), Vec::new()).palette(j);
        let gamma0_90 = Series::line(&label("90 deg"), Vec::new()).palette(j);
        plot = plot.series(gamma0_0).series(gamma0_90.dashed());
    }
    for k in 0..=240 {
        let px = 250.0 * k as f64;
        let n = px - CENTRE_PX;
        let field = (n * CAMERA.pixel_m / CAMERA.focal_m).atan().to_degrees();
        let mut row = vec![format!("{px:.0}"), format!("{n:.0}"), format!("{field:.6}")];
        for (j, &phi) in rolls.iter().enumerate() {
            let speeds: Vec<f64> = g0s
                .iter()
                .map(|&g| motion(px, phi, g).map(|m| mm_s(m.speed_mps())))
                .collect::<Result<_, _>>()?;
            let r = Range::of(speeds.iter().copied()).context("non-finite speed")?;
            let (s0, s90) = (speeds[0], speeds[speeds.len() - 1]);
            row.extend([s0, s90, r.min, r.max].map(|v| format!("{v:.6}")));
            plot.series[2 * j].points.push((px, s0));
            plot.series[2 * j + 1].points.push((px, s90));
        }
        csv.row(&row)?;
    }
    out.write("fig5_velocity_across_array.csv", &csv.into_bytes()?)?;
    out.write("fig5_velocity_across_array.png", &plot.to_png()?)
}

fn fig67(out: &mut Out, stem: &str, paper_px: f64, title: &str) -> Result<Range> {
    let rows = grid(paper_px)?;
    let mut csv = Writer::new(
        &format!(
            "{GENERATED}# paper pixel {paper_px:.0} (n = {:.0}); v1 = dP1/dt (along track), v2 = dP2/dt (along the array), signed, mm/s\n",
            paper_px - CENTRE_PX
        ),
        &["phi_deg", "gamma0_deg", "v1_mm_s", "v2_mm_s", "speed_mm_s"],
    )?;
    for (phi, g0, m) in &rows {
        let speeds = [m.v1_mps, m.v2_mps, m.speed_mps()].map(|v| format!("{:.6}", mm_s(v)));
        csv.row(
            &[
                [format!("{phi:.1}"), format!("{g0:.1}")].as_slice(),
                &speeds,
            ]
            .concat(),
        )?;
    }
    out.write(&format!("{stem}.csv"), &csv.into_bytes()?)?;
    let range =
        Range::of(rows.iter().map(|r| mm_s(r.2.speed_mps()))).context("non-finite speed")?;

    let mut plot = Plot::new(title, "roll angle phi (deg)", "speed v_P (mm/s)")
        .x_range(0.0, ROLL_MAX_DEG)
        .legend(if paper_px == NEAR_PX {
            Legend::BottomRight
        } else {
            Legend::TopRight
        });
    for (j, g0) in [0.0, 30.0, 60.0, 90.0].iter().enumerate() {
        let pts: Vec<(f64, f64)> = rows
            .iter()
            .filter(|r| r.1 == *g0)
            .map(|r| (r.0, mm_s(r.2.speed_mps())))
            .collect();
        plot = plot.series(Series::line(&format!("gamma0 = {g0} deg"), pts).palette(j));
    }
    out.write(&format!("{stem}.png"), &plot.to_png()?)?;
    Ok(range)
}

/// Returns (min MTF at M = 48, largest M for the floor, worst relative mismatch).
fn fig8(out: &mut Out) -> Result<(f64, u32, f64)> {
    let sweep = MismatchSweep::new(|g| motion(FAR_PX, 25.0, g).ok().map(|m| mm_s(m.speed_mps())))
        .context("far point at 25 deg misses the Earth")?;
    let mut header = ["gamma0_deg", "speed_mm_s", "rel_mismatch"]
        .map(String::from)
        .to_vec();
    header.extend(FIG8_STAGES.map(|m| format!("mtf_M{m}")));
    let mut csv = Writer::new(
        &format!(
            "{GENERATED}# far point, phi = 25 deg; line period set for |v| at gamma0 = 0 and held;\n\
             # rel_mismatch = (v - v(0)) / v(0); MTF = sinc(pi M rel / 2) (Eq. 19)\n"
        ),
        &header,
    )?;
    let mut plot = Plot::new(
        "Fig. 8: MTF_mismatch, far point, phi = 25 deg",
        "gamma0, argument of latitude (deg)",
        "MTF_mismatch at Nyquist",
    )
    .x_range(0.0, 90.0)
    .y_range(0.5, 1.0)
    .legend(Legend::BottomLeft);
    for (j, m) in FIG8_STAGES.iter().enumerate() {
        plot = plot.series(Series::line(&format!("M = {m}"), Vec::new()).palette(j));
    }
    for (k, &g) in sweep.g0_deg.iter().enumerate() {
        let rel = sweep.rel[k];
        let mut row = vec![
            format!("{g:.0}"),
            format!("{:.6}", sweep.speed_mm_s[k]),
            format!("{rel:.8}"),
        ];
        for (j, &m) in FIG8_STAGES.iter().enumerate() {
            let mtf = mtf_mismatch(m, rel).map_err(|e| anyhow!("{e:?}"))?;
            row.push(format!("{mtf:.6}"));
            plot.series[j].points.push((g, mtf));
        }
        csv.row(&row)?;
    }
    out.write("fig8_mtf_mismatch.csv", &csv.into_bytes()?)?;
    plot = plot.series(
        Series::line(
            &format!("MTF floor {MTF_FLOOR}"),
            vec![(0.0, MTF_FLOOR), (90.0, MTF_FLOOR)],
        )
        .colour([0, 0, 0])
        .width(1.5)
        .dashed(),
    );
    out.write("fig8_mtf_mismatch.png", &plot.to_png()?)?;
    Ok((sweep.min_mtf(48)?, sweep.max_stages()?, sweep.worst_rel()))
}

fn summary(
    out: &mut Out,
    near: Range,
    far: Range,
    mtf48: f64,
    max_m: u32,
    worst: f64,
) -> Result<()> {
    let mut csv = Writer::new(
        &format!(
            "{GENERATED}# H = 645 km, f = 555 mm, A = 13 um, R = 6370 km, i0 = {INCLINATION_DEG} deg, GM = 3.986004418e14, omega = {EARTH_RATE_RAD_S}; reference chain\n"
        ),
        &["quantity", "paper", "ours", "unit", "definition"],
    )?;
    let mut row = |q: &str, p: String, o: String, u: &str, d: &str| csv.row(&[q, &p, &o, u, d]);
    for (side, r, (min, max, change), pixel) in [
        ("near", near, published::NEAR, 0),
        ("far", far, published::FAR, 60000),
    ] {
        let over = format!("pixel {pixel}, phi 0..25, gamma0 0..90");
        row(
            &format!("{side}_min"),
            f2(min),
            format!("{:.3}", r.min),
            "mm/s",
            &format!("min |v|, {over}"),
        )?;
        row(
            &format!("{side}_max"),
            f2(max),
            format!("{:.3}", r.max),
            "mm/s",
            &format!("max |v|, {over}"),
        )?;
        let (p, o) = (format!("{change:.1}"), f2(r.change_over_min_pct()));
        row(&format!("{side}_change"), p, o, "%", "(max - min) / min")?;
        let o = f2(r.change_over_max_pct());
        row(
            &format!("{side}_change_over_max"),
            String::new(),
            o,
            "%",
            "(max - min) / max (not the paper's)",
        )?;
    }
    row(
        "far_phi25_worst_rel_mismatch",
        format!("{:.3}", 100.0 * implied_rel(published::MTF_M48, 48)?),
        format!("{:.3}", 100.0 * worst),
        "%",
        "max |v(g0) - v(0)| / v(0), g0 0..90; paper's value implied by its 0.681 at M = 48",
    )?;
    row(
        "mtf_mismatch_M48",
        format!("{:.3}", published::MTF_M48),
        format!("{mtf48:.4}"),
        "",
        "min over g0 0..90, far point, phi 25, line period held at g0 = 0",
    )?;
    row(
        "max_stages_mtf_0.95",
        published::MAX_STAGES.to_string(),
        max_m.to_string(),
        "stages",
        "largest M with MTF_mismatch >= 0.95 over g0 0..90 (any M)",
    )?;
    out.write("summary.csv", &csv.into_bytes()?)?;
    println!(
        "near [{:.3}, {:.3}] mm/s, {:.2} %; far [{:.3}, {:.3}] mm/s, {:.2} %; MTF(M=48) {:.4}; max M {}",
        near.min,
        near.max,
        near.change_over_min_pct(),
        far.min,
        far.max,
        far.change_over_min_pct(),
        mtf48,
        max_m
    );
    Ok(())
}

/// The relative mismatch dv/v with sinc(pi M dv/v / 2) = `mtf` on the first lobe: the
/// budget of [`StageRule`] for that floor, shared by `stages` stages.
fn implied_rel(mtf: f64, stages: u32) -> Result<f64> {
    let rule = StageRule::<f64>::new(mtf).map_err(|e| anyhow!("{e:?}"))?;
    Ok(rule.mismatch_budget() / f64::from(stages))
}

/// Each candidate explanation on the Figs. 6-8 quantities.
fn hypotheses(out: &mut Out) -> Result<()> {
    let mut csv = Writer::new(
        &format!("{GENERATED}# what the paper's numbers would be under each suspected mistake (Eq. 14 route, v2 from the chain); empty = the line of sight misses the Earth somewhere\n"),
        &[
            "variant",
            "near_min_mm_s",
            "near_max_mm_s",
            "near_change_pct",
            "far_min_mm_s",
            "far_max_mm_s",
            "far_change_pct",
            "far_phi25_worst_rel_pct",
            "mtf_M48",
            "max_stages",
        ],
    )?;
    let (near, far) = (published::NEAR, published::FAR);
    csv.row(&[
        "paper".to_string(),
        f2(near.0),
        f2(near.1),
        format!("{:.1}", near.2),
        f2(far.0),
        f2(far.1),
        format!("{:.1}", far.2),
        format!("{:.3}", 100.0 * implied_rel(published::MTF_M48, 48)?),
        format!("{:.3}", published::MTF_M48),
        published::MAX_STAGES.to_string(),
    ])?;
    let rolls = deg_steps(ROLL_MAX_DEG, ROLL_STEPS);
    let g0s = deg_steps(G0_MAX_DEG, G0_STEPS);
    for v in VARIANTS {
        let range_at = |px: f64| {
            let all: Option<Vec<f64>> = rolls
                .iter()
                .flat_map(|&phi| g0s.iter().map(move |&g| (phi, g)))
                .map(|(phi, g)| v.speed_mm_s(px, phi, g))
                .collect();
            all.and_then(Range::of)
        };
        // Empty fields where the line of sight misses the Earth.
        let mut row = vec![v.name.to_string()];
        for r in [range_at(NEAR_PX), range_at(FAR_PX)] {
            row.extend(match r {
                Some(r) => [
                    format!("{:.3}", r.min),
                    format!("{:.3}", r.max),
                    f2(r.change_over_min_pct()),
                ],
                None => Default::default(),
            });
        }
        row.extend(
            match MismatchSweep::new(|g| v.speed_mm_s(FAR_PX, 25.0, g)) {
                Some(s) => [
                    format!("{:.3}", 100.0 * s.worst_rel()),
                    format!("{:.4}", s.min_mtf(48)?),
                    s.max_stages()?.to_string(),
                ],
                None => Default::default(),
            },
        );
        csv.row(&row)?;
    }
    out.write("hypotheses.csv", &csv.into_bytes()?)
}
