//! The plots of a played pass, from what the firmware sent (and the terrain the pass
//! uploaded): drift, MTF and the yaw request per segment over time, and the terrain.

use anyhow::{Context, Result};
use std::collections::BTreeMap;
use std::path::Path;

use crate::plot::{Legend, Plot, Series};

use super::check::Downlink;
use super::scenario::Pass;

/// One series per segment of `value` over the pass, from every record (only those not
/// held unless `with_held`).
fn per_segment(
    firmware: &Downlink,
    with_held: bool,
    value: impl Fn(&controller::SegmentOutput) -> f64,
) -> BTreeMap<u8, Vec<(f64, f64)>> {
    let mut series: BTreeMap<u8, Vec<(f64, f64)>> = BTreeMap::new();
    for (t_us, p) in firmware.decoded() {
        for r in p.records().iter().filter(|r| with_held || !r.held) {
            series
                .entry(r.index)
                .or_default()
                .push((t_us as f64 * 1e-6, value(r)));
        }
    }
    series
}

/// `plot` over the pass's time span, legend top right, 1100 x 650 pixels.
fn framed(pass: &Pass, plot: Plot) -> Plot {
    plot.legend(Legend::TopRight)
        .x_range(0.0, (pass.end_us as f64 * 1e-6).max(1.0))
        .size(1100, 650)
}

/// `plot` with one series per segment, written to `path`.
fn save(pass: &Pass, plot: Plot, series: BTreeMap<u8, Vec<(f64, f64)>>, path: &Path) -> Result<()> {
    let mut plot = framed(pass, plot);
    for (i, (index, points)) in series.into_iter().enumerate() {
        plot = plot.series(Series::line(&format!("segment {index}"), points).palette(i));
    }
    plot.save(path)
}

/// Writes the line periods programmed by the firmware to `periods` (and says so), and
/// drift.png, mtf.png, terrain.png and yaw.png beside it.
pub fn pass_plots(pass: &Pass, firmware: &Downlink, periods: &Path) -> Result<()> {
    let dir = periods.parent().unwrap_or(Path::new(""));
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    save(
        pass,
        Plot::new(
            &format!("Line periods programmed by the firmware, {}", pass.name),
            "time (s)",
            "line period (ms)",
        ),
        per_segment(firmware, true, |r| f64::from(r.ticks) * 1e-4),
        periods,
    )?;
    println!("plot: {}", periods.display());
    save(
        pass,
        Plot::new(
            &format!("Drift at each segment's centre, yaw steered, {}", pass.name),
            "time (s)",
            "drift atan(v2/v1) (mrad)",
        ),
        per_segment(firmware, false, |r| f64::from(r.drift_rad) * 1e3),
        &dir.join("drift.png"),
    )?;
    save(
        pass,
        Plot::new(
            &format!(
                "MTF at Nyquist, mismatch x drift smear, 16 stages, {}",
                pass.name
            ),
            "time (s)",
            "MTF",
        )
        .y_range(0.0, 1.05),
        per_segment(firmware, false, |r| f64::from(r.mtf)),
        &dir.join("mtf.png"),
    )?;
    let mut terrain: BTreeMap<u8, Vec<(f64, f64)>> = BTreeMap::new();
    for (t_us, heights) in &pass.terrain {
        for (k, h) in heights.iter().enumerate() {
            terrain
                .entry(k as u8)
                .or_default()
                .push((*t_us as f64 * 1e-6, f64::from(*h)));
        }
    }
    // A user's telemetry file carries NAV frames only: no terrain to draw, and an empty
    // plot must not cost the pass its verdict lines.
    if terrain.is_empty() {
        println!("terrain.png: not written, the pass uploads no TERRAIN frame");
    } else {
        save(
            pass,
            Plot::new(
                &format!("Ground height uploaded by TERRAIN frames, {}", pass.name),
                "time (s)",
                "height above WGS 84 (m)",
            ),
            terrain,
            &dir.join("terrain.png"),
        )?;
    }
    let yaw = Plot::new(
        &format!(
            "Yaw steering: the firmware's request and the yaw flown, {}",
            pass.name
        ),
        "time (s)",
        "yaw (mrad)",
    );
    let requests: Vec<(f64, f64)> = firmware
        .decoded()
        .iter()
        .filter_map(|(t, p)| {
            p.yaw_request_rad
                .map(|y| (*t as f64 * 1e-6, f64::from(y) * 1e3))
        })
        .collect();
    let flown: Vec<(f64, f64)> = match pass.truth.as_deref() {
        Some(truth) => truth
            .yaw
            .iter()
            .map(|&(t, y, _)| (t as f64 * 1e-6, y * 1e3))
            .collect(),
        None => super::scenario::navs(pass)
            .iter()
            .map(|(t, n)| (*t as f64 * 1e-6, f64::from(n.attitude.yaw_rad) * 1e3))
            .collect(),
    };
    framed(pass, yaw)
        .series(Series::line("yaw flown", flown).palette(0))
        .series(Series::line("correction requested", requests).palette(1))
        .save(&dir.join("yaw.png"))
}

#[cfg(test)]
mod tests {
    use super::super::{check, geotiff, scenario, stream};
    use super::*;
    use controller::Config;

    /// A user's telemetry (the short pass written as CSV and read back: NAV frames, no
    /// TERRAIN) played through the host's session gives every plot but the terrain's.
    #[test]
    fn a_users_telemetry_is_plotted_without_terrain() -> Result<()> {
        let tick_us = Config::default().update_period_us;
        let dem = geotiff::read(&crate::qemu::workspace_root().join(geotiff::PASS_DEM_PATH))?;
        let dir = std::env::temp_dir().join(format!("xtask-plots-{}", std::process::id()));
        std::fs::create_dir_all(&dir)?;
        let csv = dir.join("telemetry.csv");
        scenario::to_csv(&scenario::short_pass(dem, tick_us)?, &csv)?;
        let pass = scenario::from_csv(&csv, tick_us)?;
        assert!(pass.terrain.is_empty() && pass.truth.is_none());
        check::set_epoch(pass.epoch_us);
        let sent = check::HostRun::new(&stream::build(&pass)?.clean(), Config::default())?;
        let periods = dir.join("line-periods.png");
        let result = pass_plots(&pass, &sent.downlink(), &periods);
        let written: Vec<bool> = ["line-periods.png", "drift.png", "terrain.png"]
            .iter()
            .map(|f| dir.join(f).exists())
            .collect();
        std::fs::remove_dir_all(&dir)?;
        result?;
        assert_eq!(written, [true, true, false]);
        Ok(())
    }
}
