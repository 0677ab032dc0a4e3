//! `cargo xtask run`: a pass played through the firmware under QEMU.
//!
//! The host builds the telemetry of a pass (NAV frames at 4 Hz from its f64 model,
//! TIME frames at every tick of the controller's update period that has no NAV frame,
//! injected faults, END), sends it to the firmware's UART0 through a unix socket (QEMU
//! `-chardev socket` + `-serial chardev:`; stdout stays the defmt stream), collects
//! the PERIODS and STATUS frames the firmware sends back, and checks them:
//!
//! - against the f64 reference (`core_math::sphere::Reference`) at the same instants: per
//!   segment, |v| at the plan's sample points, period A (1/v_min + 1/v_max) / 2, in
//!   ticks; the firmware's ticks must be within 1e-6 relative plus half a tick;
//! - against a twin run: the same `controller::session::Session` on the host, fed the
//!   stream without the injected faults: every update's PERIODS must be identical;
//! - the final STATUS: every injected fault counted under its own counter, and the
//!   whole STATUS identical to a host run of the faulty stream.
//!
//! Protocol and file format: docs/telemetry.md.

mod bus;
mod check;
mod geotiff;
mod plots;
mod reset;
mod scenario;
mod stream;
mod truth;

use anyhow::{anyhow, bail, Context, Result};
use std::collections::BTreeMap;
use std::io::{Read, Write};
use std::os::unix::net::UnixListener;
use std::path::{Path, PathBuf};
use std::sync::mpsc::Receiver;
use std::time::{Duration, Instant};

use controller::report::{mode_from_u8, Periods, Status};
use controller::{Config, Fault, Mode};
use core_math::earth::dem::{DemGrid, DemTile};

use check::{Downlink, EARTH_FIXED_REL_TOLERANCE, F32_REL_TOLERANCE};
use scenario::Pass;

use super::board::{Board, BoardArg};
use super::{build_firmware, ensure_target_tools, exit_like, runner, workspace_root};

/// Segments shown in the table by default (first, one of the two central ones, last).
pub const TABLE_SEGMENTS: [u8; 3] = [0, 5, 9];
/// Table row spacing by default (simulated seconds).
pub const TABLE_EVERY_S: u64 = 10;

/// `cargo xtask run`'s options.
#[derive(clap::Args)]
pub struct RunArgs {
    #[command(flatten)]
    board: BoardArg,
    /// The default-scene demo (one synthetic NAV frame, no UART) instead of a pass
    #[arg(long)]
    demo: bool,
    /// The firmware's dev profile instead of release
    #[arg(long)]
    debug: bool,
    /// The release profile (the default)
    #[arg(long, hide = true, conflicts_with = "debug")]
    release: bool,
    /// The end-to-end test's 1-minute pass instead of the 10-minute default
    #[arg(long)]
    short: bool,
    /// Play this NAV telemetry (docs/telemetry.md) instead of the default pass
    #[arg(long, value_name = "FILE.csv")]
    telemetry: Option<PathBuf>,
    /// Write the line-period plot here [default: target/pass/line-periods.png]
    #[arg(long, value_name = "FILE.png")]
    plot: Option<PathBuf>,
    /// Seconds between the table's rows
    #[arg(long, value_name = "SECONDS", default_value_t = TABLE_EVERY_S,
          value_parser = clap::value_parser!(u64).range(1..))]
    every: u64,
    /// The table's segments: indices, or all [default: 0,5,9]
    #[arg(long, value_name = "0,5,9|all", value_parser = parse_segments)]
    segments: Option<Segments>,
    /// The built-in pass's DEM tile from this GeoTIFF [default: xtask/data/pass-dem.tif]
    #[arg(long, value_name = "FILE.tif")]
    dem: Option<PathBuf>,
    /// Only write the built-in passes' synthetic DEM tile as a GeoTIFF
    #[arg(long, value_name = "FILE.tif", hide = true)]
    write_dem: Option<PathBuf>,
    /// Only write the default pass's NAV samples as telemetry CSV
    #[arg(long, value_name = "FILE.csv")]
    export_telemetry: Option<PathBuf>,
    /// Reset the firmware (QEMU's system_reset, as its reset line) after its first
    /// update at or after this pass time, and report what the reset cost
    #[arg(long, value_name = "SECONDS")]
    reset_at: Option<f64>,
    /// With --reset-at: the frames of this many seconds after the reset never reach
    /// the firmware (a live link while the board reboots), on the host's model too
    #[arg(
        long,
        value_name = "SECONDS",
        requires = "reset_at",
        default_value_t = 0.0
    )]
    reset_loses: f64,
}

/// Segment indices given on the command line (one value, not a list of arguments).
#[derive(Clone, Debug)]
pub struct Segments(Vec<u8>);

fn parse_segments(v: &str) -> Result<Segments> {
    if v == "all" {
        return Ok(Segments((0..16).collect()));
    }
    v.split(',')
        .map(|x| x.trim().parse::<u8>())
        .collect::<Result<_, _>>()
        .map(Segments)
        .map_err(|_| anyhow!("`{v}` is not a list of segment indices like 0,5,9"))
}

/// `cargo xtask run [--telemetry FILE]`: the default pass (or the file) through the
/// firmware, table, plot, checks; or the default-scene demo, or the export of the
/// default pass's telemetry.
pub fn run(args: &RunArgs) -> Result<()> {
    let (board, release) = (args.board.board, !args.debug);
    if let Some(path) = &args.write_dem {
        return geotiff::write(path);
    }
    let dem = || {
        let default = workspace_root().join(geotiff::PASS_DEM_PATH);
        geotiff::read(args.dem.as_ref().unwrap_or(&default))
    };
    if let Some(path) = &args.export_telemetry {
        return export(path, dem()?);
    }
    if args.demo {
        ensure_target_tools()?;
        let elf = build_firmware(board, "demo", release, &[], &[])?;
        let outcome = runner::run_elf(&elf, &runner::Options::default())?;
        return exit_like(outcome.status);
    }
    let started = Instant::now();
    let tick_us = Config::default().update_period_us;
    let pass = match &args.telemetry {
        Some(path) => scenario::from_csv(path, tick_us)?,
        None if args.short => scenario::short_pass(dem()?, tick_us)?,
        None => scenario::default_pass(dem()?, tick_us)?,
    };
    let reset = match args.reset_at {
        Some(at_s) => Some(reset::Plan::new(at_s, args.reset_loses, pass.end_us)?),
        None => None,
    };
    ensure_target_tools()?;
    let elf = build_firmware(board, "firmware", release, &[], &[])?;
    let result = play(&elf, &pass, reset)?;
    let segments = args.segments.as_ref().map_or(&TABLE_SEGMENTS[..], |s| &s.0);
    print_table(&pass, &result, args.every, segments);
    let plot = args
        .plot
        .clone()
        .unwrap_or_else(|| workspace_root().join("target/pass/line-periods.png"));
    plots::pass_plots(&pass, &result.firmware, &plot)?;
    println!(
        "wall time {:.1} s for {:.0} s of orbit",
        started.elapsed().as_secs_f64(),
        pass.end_us as f64 * 1e-6
    );
    result.verdict.finish()
}

/// `cargo xtask run --export-telemetry FILE`: the default pass's NAV samples as CSV.
pub fn export(path: &Path, dem: (core_math::earth::dem::DemGrid, Vec<i16>)) -> Result<()> {
    let pass = scenario::default_pass(dem, Config::default().update_period_us)?;
    scenario::to_csv(&pass, path)?;
    println!(
        "wrote {} NAV samples of the {} to {} (faults are not part of the file)",
        pass.samples.len(),
        pass.name,
        path.display()
    );
    Ok(())
}

/// When the end-to-end test resets the firmware: in the short pass, roll held at 20 deg
/// after a SCENE upload, before the pitch slew.
const RESET_TEST_AT_S: f64 = 30.0;
/// Frames the end-to-end test's reset loses on the mps2 boards (a live link during a
/// slow reboot: NAV frames and a TERRAIN frame); the STM32F405's reset loses none, so
/// that one run shows a recovery equal to the run without the reset.
const RESET_TEST_LOSES_S: f64 = 1.0;

/// The end-to-end test (`cargo xtask test`): a one-minute pass with every kind of
/// fault through the firmware (release) under QEMU; every period against the
/// reference, every fault counted, no output changed by a fault.
pub fn e2e_test(board: Board) -> Result<()> {
    let started = Instant::now();
    let dem = geotiff::read(&workspace_root().join(geotiff::PASS_DEM_PATH))?;
    let pass = scenario::short_pass(dem, Config::default().update_period_us)?;
    let elf = build_firmware(board, "firmware", true, &[], &[])?;
    let result = play(&elf, &pass, None)?;
    result.verdict.finish()?;
    // The same pass with a reset (docs/target.md, "Faults and resets").
    let loses_s = match board {
        Board::Stm32f405 => 0.0,
        Board::Mps2An386 | Board::Mps2An385 => RESET_TEST_LOSES_S,
    };
    let plan = reset::Plan::new(RESET_TEST_AT_S, loses_s, pass.end_us)?;
    let reset = play(&elf, &pass, Some(plan))?;
    reset.verdict.finish()?;
    eprintln!(
        "xtask: end-to-end pass test (and with a reset at {RESET_TEST_AT_S} s losing {loses_s} s of frames) passed on {} in {:.1} s",
        board.name(),
        started.elapsed().as_secs_f64()
    );
    Ok(())
}

/// What a pass says after its table: its report lines and its failed checks, in the
/// order printed (a failure as `FAILED: ...`).
#[derive(Default)]
struct Verdict(Vec<(bool, String)>);

impl Verdict {
    fn say(&mut self, line: String) {
        self.0.push((false, line));
    }

    fn fail(&mut self, failure: String) {
        self.0.push((true, failure));
    }

    /// Prints every line; an error if a check failed.
    fn finish(&self) -> Result<()> {
        for (failed, text) in &self.0 {
            println!("{}{text}", if *failed { "FAILED: " } else { "" });
        }
        match self.0.iter().filter(|(failed, _)| *failed).count() {
            0 => Ok(()),
            n => Err(anyhow!("{n} check(s) failed (see above)")),
        }
    }
}

/// What a played pass gave: the firmware's downlink, the bytes each way, the verdict.
struct Played {
    firmware: Downlink,
    tx_bytes: usize,
    rx_bytes: usize,
    verdict: Verdict,
}

/// Plays `pass` through the firmware `elf` and runs every check; with a reset `plan`,
/// resets the firmware at its pass time and checks the recovery instead of the fault
/// counters (which start afresh at the reset).
fn play(elf: &Path, pass: &Pass, plan: Option<reset::Plan>) -> Result<Played> {
    check::set_epoch(pass.epoch_us);
    let stream = stream::build(pass)?;
    let uplink = stream.faulty();
    println!(
        "{}: {} telemetry frames, {} bytes up ({} injected faults), firmware {}",
        pass.name,
        pass.samples.len(),
        uplink.len(),
        stream.injected.len(),
        elf.display()
    );
    // The twin runs the controller as the board's firmware configures it.
    let board = Board::of_elf(&std::fs::read(elf).with_context(|| format!("{}", elf.display()))?)?;
    let config = board.controller_config();
    let t_qemu = Instant::now();
    let trigger = match plan {
        Some(plan) => Some(reset::Trigger::new(
            plan,
            std::env::temp_dir().join(format!("tdi-qmp-{}.sock", std::process::id())),
            &uplink,
            elf,
            config,
        )?),
        None => None,
    };
    let run = run_qemu(elf, &uplink, trigger)?;
    let firmware = Downlink::decode(&run.downlink);
    let t_twin = Instant::now();

    // The twin: the stream without the injected faults, and a host run of the faulty
    // stream (whose STATUS must equal the firmware's: same code, same bytes).
    let clean = stream.clean();
    let twin_run = check::HostRun::new(&clean, config)?;
    let twin = twin_run.downlink();
    let faulty_twin = check::HostRun::new(&uplink, config)?.downlink();
    let twin_s = t_twin.elapsed().as_secs_f64();
    let (navs, (changed, changed_examples), reset) = match plan {
        None => (twin_run.inputs, compare_with_twin(&firmware, &twin), None),
        Some(plan) => {
            let (verdict, inputs, changed) =
                reset::check(plan, &run, &firmware, &twin, &uplink, &clean, config)?;
            (inputs, changed, Some(verdict))
        }
    };
    // The scene of the checks: the one the pass uploads at its start.
    let mut controller = check::new_controller(config)?;
    controller
        .set_scene(scenario::pass_scene(pass.truth.as_deref().is_some()))
        .map_err(|f| anyhow!("the pass's scene was refused: {}", f.name()))?;
    let t_check = Instant::now();
    // The truth check beside the reference check: each evaluates the f64 reference of
    // every update.
    let (reference, truth) = std::thread::scope(|s| {
        let truth = s.spawn(|| {
            pass.truth
                .as_deref()
                .map(|a| {
                    let dem = pass.dem.as_ref();
                    truth::check(a, &firmware, &controller, dem, &pass.terrain, &navs)
                })
                .transpose()
        });
        let dem = pass.dem.as_ref();
        let fixed = config.fixed_point_pixels;
        let reference = reference_check(&firmware, &navs, &controller, fixed, dem);
        (reference, truth.join())
    });
    let reference = reference?;
    let truth = truth.map_err(|_| anyhow!("the truth check panicked"))??;
    println!(
        "QEMU run {:.1} s; twin runs and reference check {:.1} s",
        t_check.duration_since(t_qemu).as_secs_f64() - twin_s,
        twin_s + t_check.elapsed().as_secs_f64()
    );

    let mut v = Verdict::default();
    let final_status = firmware.final_status().copied();
    let counted = stream.injected.iter().flatten().count();
    let noise = stream.injected.len() - counted;
    if noise > 0 {
        let skipped = final_status.as_ref().map_or(0, |s| s.skipped_bytes);
        v.say(format!(
            "noise: {} bytes in {noise} burst(s) injected; the decoder skipped {skipped} bytes (the noise and the remains of the rejected frames)",
            stream.noise_bytes()
        ));
    }
    v.0.extend(reference.0);
    if run.status != 0 {
        v.fail(format!("the firmware exited with status {}", run.status));
    }
    // A reset comes between two frames, when the firmware has sent all it owed: it cuts
    // none.
    if firmware.bad_frames > 0 || firmware.skipped_bytes > 0 {
        v.fail(format!(
            "the downlink had {} bad frames and {} stray bytes",
            firmware.bad_frames, firmware.skipped_bytes
        ));
    }
    if let Some(n) = final_status.map(|s| s.downlink_dropped).filter(|&n| n > 0) {
        v.fail(format!(
            "the firmware dropped {n} downlink frames whole (its transmit queue had no room: STATUS)"
        ));
    }
    changed_examples.into_iter().take(5).for_each(|e| v.fail(e));
    match (&final_status, faulty_twin.final_status()) {
        // The counters start afresh at a reset: the recovery's own checks replace these.
        _ if reset.is_some() => {}
        (Some(fw), Some(host)) => {
            for f in Fault::ALL {
                let expected = stream.injected.iter().filter(|e| **e == Some(f)).count() as u32;
                if fw.count(f) != expected {
                    v.fail(format!(
                        "fault counter {}: {} in the firmware's STATUS, {expected} injected",
                        f.name(),
                        fw.count(f)
                    ));
                }
            }
            if fw != host {
                v.fail(format!(
                    "the firmware's final STATUS differs from the host run of the same bytes: {fw:?} vs {host:?}"
                ));
            }
            // The built-in passes upload a DEM tile at their start (stream.rs).
            if let Some((g, _)) = &pass.dem {
                let d = fw.dem;
                println!(
                    "DEM upload: tile {} in force, {} committed, upload in progress {} ({} x {} nodes from the GeoTIFF)",
                    d.in_force_id, d.tiles_committed, d.upload_id, g.nrows, g.ncols
                );
                if d.in_force_id != scenario::PASS_DEM_ID || d.tiles_committed != 1 {
                    v.fail(format!(
                        "the DEM tile uploaded at the start is not in force: {d:?}"
                    ));
                }
            }
        }
        _ => v.fail("no final STATUS frame".into()),
    }
    // Issues 23 and 24's stack budget, against the firmware's own high-water mark (its
    // last log line; after a reset, the one since the reset).
    match run
        .log
        .iter()
        .filter_map(|m| stack_high_water_bytes(m))
        .max()
    {
        None => v.fail("the firmware logged no stack high-water mark".into()),
        Some(b) if b > STACK_BUDGET_BYTES => v.fail(format!(
            "stack high-water mark {b} bytes, over the budget of {STACK_BUDGET_BYTES}"
        )),
        Some(_) => {}
    }
    if let Some(t) = &truth {
        t.verdict(&mut v);
    }
    v.0.extend(reset.into_iter().flat_map(|r| r.0));
    v.say(format!(
        "faults: injected {counted}, rejected {}, outputs changed by faults {changed}",
        final_status.as_ref().map_or(0, Status::total)
    ));
    Ok(Played {
        tx_bytes: uplink.len(),
        rx_bytes: run.downlink.len(),
        firmware,
        verdict: v,
    })
}

/// The stack the firmware may use (bytes): issue 23's and 24's budget.
const STACK_BUDGET_BYTES: usize = 12 * 1024;

/// The text of a firmware log line between `after` and the next `before`, parsed (the
/// figures the checks read from the log).
fn log_field<T: std::str::FromStr>(message: &str, after: &str, before: &str) -> Option<T> {
    let rest = message.split_once(after)?.1;
    rest.split_once(before)?.0.trim().parse().ok()
}

/// N of the firmware's log line "stack high-water mark: N bytes ..." (firmware/src/main.rs).
fn stack_high_water_bytes(message: &str) -> Option<usize> {
    log_field(message, "stack high-water mark: ", " bytes")
}

/// Updates whose PERIODS payload differs between the firmware and the twin, matched by
/// update instant.
fn compare_with_twin(firmware: &Downlink, twin: &Downlink) -> (usize, Vec<String>) {
    let fw: BTreeMap<u64, &Vec<u8>> = firmware.periods.iter().map(|(t, p)| (*t, p)).collect();
    let tw: BTreeMap<u64, &Vec<u8>> = twin.periods.iter().map(|(t, p)| (*t, p)).collect();
    let mut changed = 0;
    let mut examples = Vec::new();
    let instants: std::collections::BTreeSet<u64> = fw.keys().chain(tw.keys()).copied().collect();
    for t in instants {
        let (a, b) = (fw.get(&t), tw.get(&t));
        if a != b {
            changed += 1;
            if examples.len() < 5 {
                examples.push(format!(
                    "update at {:.3} s: firmware {}, twin {}",
                    t as f64 * 1e-6,
                    describe(a.copied()),
                    describe(b.copied())
                ));
            }
        }
    }
    if fw.len() != firmware.periods.len() || tw.len() != twin.periods.len() {
        changed += 1;
        examples.push("two PERIODS frames with the same update instant".into());
    }
    (changed, examples)
}

fn describe(p: Option<&Vec<u8>>) -> String {
    match p.and_then(|p| Periods::decode(p)) {
        None => "no update".into(),
        Some(p) => {
            let ticks: Vec<String> = p
                .records()
                .iter()
                .map(|r| format!("{}{}", r.ticks, if r.held { "h" } else { "" }))
                .collect();
            format!("mode {} ticks [{}]", p.mode, ticks.join(" "))
        }
    }
}

/// Every fresh (not held) period of the firmware against the f64 reference of the same
/// update on the firmware's own inputs (`controller::golden`: the NAV frame and terrain
/// in force, as the host twin had them), within the tolerance of the f32 update (and of
/// the `fixed_point_pixels`): the largest differences, the periods compared, how many of
/// them matched only the reference turned by the firmware's f32 attitude rounding (a jump
/// of the reference between two grounds), the failures.
fn reference_check(
    firmware: &Downlink,
    inputs: &check::Inputs,
    controller: &controller::Controller,
    fixed_point_pixels: bool,
    dem: Option<&(DemGrid, Vec<i16>)>,
) -> Result<Verdict> {
    let (rel_tolerance, tolerance_note) = if fixed_point_pixels {
        (
            F32_REL_TOLERANCE + EARTH_FIXED_REL_TOLERANCE,
            "the f32 update and the fixed-point pixels",
        )
    } else {
        (F32_REL_TOLERANCE, "the f32 closed form")
    };
    let dem = match dem {
        Some((g, h)) => {
            Some(DemTile::new(*g, h).map_err(|e| anyhow!("the pass's DEM: {}", e.name()))?)
        }
        None => None,
    };
    let mut max_rel = 0.0f64;
    let mut max_ticks = 0.0f64;
    let mut compared = 0;
    let mut failures = Vec::new();
    let mut at_jumps = 0;
    for (t_us, periods) in firmware.decoded() {
        if !periods.records().iter().any(|r| !r.held) {
            continue;
        }
        let Some(input) = inputs.get(&t_us) else {
            failures.push(format!(
                "update at {:.3} s: no state to compare with",
                t_us as f64 * 1e-6
            ));
            continue;
        };
        let golden = input
            .reference(controller, t_us, dem.as_ref(), None)
            .map_err(|e| anyhow!("reference at {t_us} us: {}", e.name()))?;
        for r in periods.records().iter().filter(|r| !r.held) {
            let Some(exact) = golden
                .segments
                .iter()
                .flatten()
                .find(|g| g.index == r.index)
                .map(|g| g.ticks_exact)
            else {
                failures.push(format!("segment {} is not in the plan", r.index));
                continue;
            };
            let allowed = rel_tolerance * exact + 0.5;
            let mut diff = (f64::from(r.ticks) - exact).abs();
            if diff > allowed {
                // Where a sample's line of sight grazes a ridge, the reference itself
                // jumps between two grounds for an attitude change far below the
                // firmware's f32 rounding: compare with the reference turned by that.
                let turned = match &input.source {
                    check::Source::Bus(_, a, _) => turned_attitudes(a),
                    check::Source::Nav(_) => Vec::new(),
                };
                let turned = turned.iter().filter_map(|a| {
                    input
                        .reference(controller, t_us, dem.as_ref(), Some(a))
                        .ok()
                });
                let nearest = turned
                    .filter_map(|u| {
                        u.segments
                            .into_iter()
                            .flatten()
                            .find(|g| g.index == r.index)
                    })
                    .map(|g| (f64::from(r.ticks) - g.ticks_exact).abs())
                    .fold(f64::INFINITY, f64::min);
                if nearest <= allowed {
                    diff = nearest;
                    at_jumps += 1;
                }
            }
            let rel = diff / exact;
            max_rel = max_rel.max(rel);
            max_ticks = max_ticks.max(diff);
            compared += 1;
            if diff > allowed {
                failures.push(format!(
                    "update at {:.3} s, segment {}: {} ticks, reference {exact:.3} (relative {rel:.2e})",
                    t_us as f64 * 1e-6,
                    r.index,
                    r.ticks
                ));
            }
        }
    }
    let mut v = Verdict::default();
    v.say(format!(
        "reference: largest |ticks - reference| {max_ticks:.4} ticks (allowed: 0.5 for the rounding to whole ticks + {rel_tolerance:.0e} x ticks for {tolerance_note})"
    ));
    if compared == 0 {
        v.fail("no period was compared with the reference".into());
    }
    failures.into_iter().take(5).for_each(|f| v.fail(f));
    v.say(format!(
        "reference check: max relative difference {max_rel:.3e} over {compared} periods ({at_jumps} at a jump of the reference between two grounds, compared with it turned by the firmware's f32 attitude rounding, {F32_ATTITUDE_RAD:.0e} rad)"
    ));
    Ok(v)
}

/// The f32 rounding of the attitude the firmware carries (rad): the quaternion
/// (components to 6e-8), B rounded to f32 and turned in f32.
const F32_ATTITUDE_RAD: f64 = 3e-7;

/// `a` turned by +-[`F32_ATTITUDE_RAD`] about each body axis.
fn turned_attitudes(a: &controller::bus::StarAttitude) -> Vec<controller::bus::StarAttitude> {
    (0..6)
        .map(|k| {
            let mut e = [0.0f64; 3];
            e[k / 2] = if k % 2 == 0 { 0.5 } else { -0.5 } * F32_ATTITUDE_RAD;
            let q = bus::q_mul(a.q.map(f64::from), [1.0, e[0], e[1], e[2]]);
            let n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
            controller::bus::StarAttitude {
                q: q.map(|x| (x / n) as f32),
                ..*a
            }
        })
        .collect()
}

/// What a QEMU run of a pass gave.
struct QemuRun {
    /// The firmware's exit status.
    status: i32,
    /// Everything it sent.
    downlink: Vec<u8>,
    /// Its decoded log.
    log: Vec<String>,
    /// With a reset trigger: the update instant after which the machine was reset.
    reset_after_us: Option<u64>,
    /// With a reset trigger: instructions from the reset vector to the first period
    /// written.
    boot_instructions: Option<u64>,
}

/// Starts QEMU with UART0 on a unix socket, sends `uplink`, and returns what the run
/// gave ([`QemuRun`]).
fn run_qemu(
    elf: &Path,
    uplink: &[u8],
    trigger: Option<(reset::Trigger, Receiver<()>)>,
) -> Result<QemuRun> {
    let (mut trigger, reset_made) = trigger.unzip();
    let socket = std::env::temp_dir().join(format!(
        "tdi-pass-{}-{}.sock",
        std::process::id(),
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.subsec_nanos())
    ));
    let _ = std::fs::remove_file(&socket);
    let listener = UnixListener::bind(&socket)
        .with_context(|| format!("cannot listen on {}", socket.display()))?;
    let (link_ready, ready) = std::sync::mpsc::channel();
    let mut extra_args = vec![
        "-chardev".into(),
        format!("socket,id=telemetry,path={}", socket.display()),
    ];
    if let Some(t) = &trigger {
        let _ = std::fs::remove_file(&t.qmp);
        extra_args.extend(t.qemu_args());
    }
    let options = runner::Options {
        extra_args,
        serial: Some("chardev:telemetry".into()),
        capture: true,
        log_to_stderr: false,
        link_ready: Some(link_ready),
    };
    let elf_owned = elf.to_path_buf();
    let emulator = std::thread::spawn(move || runner::run_elf(&elf_owned, &options));

    // QEMU connects as soon as it starts; give up if it ends first or takes too long.
    listener.set_nonblocking(true).context("socket")?;
    let t0 = Instant::now();
    let conn = loop {
        match listener.accept() {
            Ok((conn, _)) => break Ok(conn),
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {
                if emulator.is_finished() || t0.elapsed() > Duration::from_secs(30) {
                    break Err(anyhow!("QEMU did not connect to the telemetry socket"));
                }
                std::thread::sleep(Duration::from_millis(10));
            }
            Err(e) => break Err(anyhow!("accepting QEMU's connection: {e}")),
        }
    };
    let _ = std::fs::remove_file(&socket);
    let conn = match conn {
        Ok(c) => c,
        Err(e) => {
            let outcome = emulator.join();
            return Err(match outcome {
                Ok(Err(q)) => anyhow!("{e}: {q:#}"),
                _ => e,
            });
        }
    };
    conn.set_nonblocking(false).context("socket")?;
    // Not a byte before the firmware says its link is enabled: the STM32F405's USART
    // drops what arrives earlier (docs/target.md, "Boards").
    ready
        .recv_timeout(Duration::from_secs(30))
        .map_err(|_| anyhow!("the firmware never said that its telemetry link was ready"))?;
    let mut writer = conn.try_clone().context("socket")?;
    let data = uplink.to_vec();
    let (cut, resume) = trigger
        .as_ref()
        .map_or((data.len(), data.len()), |t| (t.cut, t.resume));
    // The firmware reads as fast as it computes; the writer blocks when QEMU's side is
    // full, while this thread drains the downlink so that the firmware never waits.
    // With a reset: the bytes before the cut, then, once the reset is made and the
    // firmware's link is up again, the rest after the frames the reset loses.
    let sender = std::thread::spawn(move || -> Result<()> {
        let before = data.get(..cut).unwrap_or_default();
        let after = data.get(resume..).unwrap_or_default();
        let mut send = |bytes: &[u8]| -> Result<()> {
            for chunk in bytes.chunks(4096) {
                writer.write_all(chunk).context("sending telemetry")?;
            }
            writer.flush().context("sending telemetry")
        };
        send(before)?;
        if let Some(made) = reset_made {
            if made.recv().is_err() {
                // No reset was made and the downlink ended: nothing more to send.
                return Ok(());
            }
            ready.recv_timeout(Duration::from_secs(30)).map_err(|_| {
                anyhow!("the firmware never said its link was ready after the reset")
            })?;
        }
        send(after)
    });
    let mut downlink = Vec::new();
    let mut reader = conn;
    let read = match &mut trigger {
        None => reader.read_to_end(&mut downlink).map(|_| ()),
        Some(t) => read_watching(&mut reader, &mut downlink, t),
    };
    // A reset not made by now never will be: the sender must not wait for it.
    let reset_made = trigger.take().map(|t| {
        let _ = std::fs::remove_file(&t.qmp);
        (t.done_after_us, t.boot_count)
    });
    let outcome = emulator
        .join()
        .map_err(|_| anyhow!("the QEMU thread panicked"))??;
    let sent = sender
        .join()
        .map_err(|_| anyhow!("the sender thread panicked"))?;
    read.context("reading the downlink")?;
    if let Err(e) = sent {
        bail!("{e:#} (the firmware exited with status {})", outcome.status);
    }
    let (reset_after_us, boot_instructions) = match reset_made {
        Some((after, count)) => (after, count.read()),
        None => (None, None),
    };
    Ok(QemuRun {
        boot_instructions,
        status: outcome.status,
        downlink,
        log: outcome.messages,
        reset_after_us,
    })
}

/// Reads the downlink to its end, showing each chunk to `trigger` as it comes.
fn read_watching(
    reader: &mut impl Read,
    downlink: &mut Vec<u8>,
    trigger: &mut reset::Trigger,
) -> std::io::Result<()> {
    let mut chunk = [0u8; 4096];
    loop {
        let n = reader.read(&mut chunk)?;
        if n == 0 {
            return Ok(());
        }
        let bytes = chunk.get(..n).unwrap_or_default();
        downlink.extend_from_slice(bytes);
        trigger
            .watch(bytes)
            .map_err(|e| std::io::Error::other(format!("{e:#}")))?;
    }
}

fn mode_name(m: u8) -> &'static str {
    match mode_from_u8(m) {
        Some(Mode::WaitingForNav) => "waiting",
        Some(Mode::Nominal) => "nominal",
        Some(Mode::Stale) => "STALE",
        None => "?",
    }
}

/// One row per `every_s` simulated seconds: the update at (or first after) that
/// instant, the chosen segments' period (us), MTF and TDI stage limit, and the faults
/// counted since the previous row.
fn print_table(pass: &Pass, played: &Played, every_s: u64, segments: &[u8]) {
    let decoded = played.firmware.decoded();
    // Only segments the firmware reported.
    let segments: Vec<u8> = segments
        .iter()
        .copied()
        .filter(|s| {
            decoded
                .iter()
                .any(|(_, p)| p.records().iter().any(|r| r.index == *s))
        })
        .collect();
    println!(
        "\nfirmware downlink: {} PERIODS and {} STATUS frames, {} bytes ({} bytes up)",
        played.firmware.periods.len(),
        played.firmware.status.len(),
        played.rx_bytes,
        played.tx_bytes
    );
    let mut header = format!(
        "{:>6} {:>8} {:>6} {:>6} {:>6}",
        "t_s", "mode", "roll", "pitch", "yaw"
    );
    for &s in &segments {
        header.push_str(&format!(
            " | seg {s}: {:>9} {:>6} {:>3}",
            "period_us", "MTF", "M"
        ));
    }
    header.push_str(" | faults since last row");
    println!("{header}");
    let mut last_counts = [0u32; Fault::COUNT];
    let mut next = 0u64;
    let mut k = 0;
    while next <= pass.end_us {
        while k < decoded.len() && decoded[k].0 < next {
            k += 1;
        }
        let Some((t_us, p)) = decoded.get(k) else {
            break;
        };
        let t_s = *t_us as f64 * 1e-6;
        let angles = telemetry_attitude_deg(pass, *t_us)
            .map_or(["-".to_string(), "-".into(), "-".into()], |a| {
                a.map(|x| format!("{x:.2}"))
            });
        let mut line = format!(
            "{t_s:>6.1} {:>8} {:>6} {:>6} {:>6}",
            mode_name(p.mode),
            angles[0],
            angles[1],
            angles[2]
        );
        for &s in &segments {
            match p.records().iter().find(|r| r.index == s) {
                Some(r) => line.push_str(&format!(
                    " | {:>16.1}{} {:>6.4} {:>3}",
                    f64::from(r.ticks) * 0.1,
                    if r.held { "h" } else { " " },
                    r.mtf,
                    r.max_stages
                )),
                None => line.push_str(&format!(" | {:>16} {:>6} {:>3}", "-", "-", "-")),
            }
        }
        // Faults counted up to this row (the last STATUS not after it).
        let counts = played
            .firmware
            .status
            .iter()
            .take_while(|(ts, _)| *ts <= *t_us)
            .last()
            .map_or([0; Fault::COUNT], |(_, s)| s.counts);
        let new: Vec<String> = Fault::ALL
            .iter()
            .filter(|f| counts[**f as usize] > last_counts[**f as usize])
            .map(|f| {
                let n = counts[*f as usize] - last_counts[*f as usize];
                if n > 1 {
                    format!("{} x{n}", f.name())
                } else {
                    f.name().to_string()
                }
            })
            .collect();
        last_counts = counts;
        line.push_str(" | ");
        line.push_str(&new.join(", "));
        println!("{}", line.trim_end());
        next += every_s * 1_000_000;
    }
    println!("(attitude in deg flown, or from the last NAV frame propagated at its rates; period in us of the 10 MHz line clock; h: held over a fault; MTF: mismatch x drift smear with the segment's 16 stages; M: largest TDI stage count meeting MTF 0.95)");
}

/// Roll, pitch and yaw flown at `t_us` (a built-in pass), or of the last NAV sample at
/// or before it, propagated at their rates (deg).
fn telemetry_attitude_deg(pass: &Pass, t_us: u64) -> Option<[f64; 3]> {
    if let Some(truth) = pass.truth.as_deref() {
        let a = truth.attitude(t_us as f64 * 1e-6);
        return Some([a.roll_rad, a.pitch_rad, a.yaw_rad].map(f64::to_degrees));
    }
    let (t0_us, a) = pass.samples.iter().rev().find_map(|s| match s.msg {
        scenario::Msg::Nav(n) if s.t_us <= t_us => Some((s.t_us, n.attitude.to_f64())),
        _ => None,
    })?;
    let dt = (t_us - t0_us) as f64 * 1e-6;
    Some([
        (a.roll_rad + a.roll_rate_rad_s * dt).to_degrees(),
        (a.pitch_rad + a.pitch_rate_rad_s * dt).to_degrees(),
        (a.yaw_rad + a.yaw_rate_rad_s * dt).to_degrees(),
    ])
}
