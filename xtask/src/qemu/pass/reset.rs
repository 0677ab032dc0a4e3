//! `cargo xtask run --reset-at SECONDS`: the firmware reset in the middle of a pass, as
//! its reset line would do it (QEMU's `system_reset`, through its QMP socket), and what
//! the reset cost: when the periods came back, until when they stayed held, and how many
//! updates after the recovery differ from a run without the reset (docs/target.md,
//! "Faults and resets").

use anyhow::{bail, Context, Result};
use std::collections::BTreeMap;
use std::io::{BufRead, BufReader, Write};
use std::os::unix::net::UnixStream;
use std::path::{Path, PathBuf};
use std::sync::mpsc::{channel, Receiver, Sender};

use controller::frame::{kind, Decoder, Event};
use controller::report::Periods;
use controller::Config;

use super::check::{self, Downlink, HostRun, Inputs};
use super::{QemuRun, Verdict};
use crate::qemu::bench;

/// When to reset, and how much of the uplink the reset loses.
#[derive(Clone, Copy, Debug)]
pub struct Plan {
    pub at_s: f64,
    /// Frames tagged in `at_s .. at_s + loses_s` never reach the firmware.
    pub loses_s: f64,
}

impl Plan {
    /// A reset at `at_s` losing `loses_s` of frames, checked against a pass ending at
    /// `end_us`.
    pub fn new(at_s: f64, loses_s: f64, end_us: u64) -> Result<Plan> {
        if !(at_s > 0.0 && at_s * 1e6 < end_us as f64) {
            bail!(
                "--reset-at {at_s}: the pass runs from 0 to {:.1} s",
                end_us as f64 * 1e-6
            );
        }
        if !(loses_s >= 0.0 && (at_s + loses_s) * 1e6 < end_us as f64) {
            bail!(
                "--reset-loses {loses_s}: the frames lost must end before the pass does ({:.1} s)",
                end_us as f64 * 1e-6
            );
        }
        Ok(Plan { at_s, loses_s })
    }

    /// Where `uplink` is cut for the reset and where it resumes after it.
    pub fn cuts(&self, uplink: &[u8]) -> (usize, usize) {
        let cut = check::cut_before(uplink, (self.at_s * 1e6).round() as u64);
        let resume = if self.loses_s > 0.0 {
            let until_us = ((self.at_s + self.loses_s) * 1e6).round() as u64;
            check::cut_before(uplink, until_us).max(cut)
        } else {
            cut
        };
        (cut, resume)
    }
}

/// The uplink around a reset: what the firmware gets before it, what the reset loses,
/// what it gets after.
pub struct Uplink<'a> {
    pub before: &'a [u8],
    pub lost: &'a [u8],
    pub rest: &'a [u8],
}

impl<'a> Uplink<'a> {
    pub fn split(uplink: &'a [u8], cut: usize, resume: usize) -> Uplink<'a> {
        let (before, after) = uplink.split_at(cut.min(uplink.len()));
        let (lost, rest) = after.split_at(resume.saturating_sub(cut).min(after.len()));
        Uplink { before, lost, rest }
    }
}

/// The reset to make: between two frames of the uplink, once the firmware has answered
/// every frame before the cut, through QEMU's QMP socket.
pub struct Trigger {
    pub qmp: PathBuf,
    /// Uplink bytes sent before the reset; the rest follows once the firmware is up.
    pub cut: usize,
    /// Where the uplink resumes after the reset: `cut` plus the bytes the reset loses.
    pub resume: usize,
    /// Frames the firmware sends for those bytes (a host run of them says how many).
    after_frames: usize,
    decoder: Decoder,
    seen: usize,
    last_periods_us: Option<u64>,
    /// Told once the reset is made: the sender then waits for the link to come up.
    made: Option<Sender<()>>,
    /// The time tag of the last PERIODS frame before the reset.
    pub done_after_us: Option<u64>,
    pub boot_count: BootCount,
}

impl Trigger {
    /// A reset after the frames of `uplink` tagged before the plan's instant; the
    /// receiver hears when it is made.
    pub fn new(
        plan: Plan,
        qmp: PathBuf,
        uplink: &[u8],
        elf: &Path,
        config: Config,
    ) -> Result<(Trigger, Receiver<()>)> {
        let at_s = plan.at_s;
        let (cut, resume) = plan.cuts(uplink);
        let before = HostRun::new(uplink.get(..cut).unwrap_or_default(), config)?;
        let after_frames = check::frame_count(&before.sent);
        if after_frames == 0 {
            bail!("--reset-at {at_s}: the firmware sends nothing before that instant");
        }
        let (made, heard) = channel();
        let trigger = Trigger {
            qmp,
            cut,
            resume,
            after_frames,
            decoder: Decoder::new(),
            seen: 0,
            last_periods_us: None,
            made: Some(made),
            done_after_us: None,
            boot_count: BootCount::new(elf)?,
        };
        Ok((trigger, heard))
    }

    /// QEMU's arguments: the QMP socket, the boot count's plugin.
    pub fn qemu_args(&self) -> Vec<String> {
        vec![
            "-qmp".into(),
            format!("unix:{},server=on,wait=off", self.qmp.display()),
            "-plugin".into(),
            self.boot_count.plugin_args.clone(),
        ]
    }

    /// Watches the downlink: once the firmware has sent every frame it owes the bytes
    /// before the cut, resets the machine.
    pub fn watch(&mut self, bytes: &[u8]) -> Result<()> {
        if self.done_after_us.is_some() {
            return Ok(());
        }
        let (seen, last) = (&mut self.seen, &mut self.last_periods_us);
        self.decoder.feed(bytes, |e| {
            if let Event::Frame(f) = e {
                *seen += 1;
                if f.kind == kind::PERIODS {
                    *last = Some(check::pass_us(f.time_us));
                }
            }
        });
        if self.seen >= self.after_frames {
            // The last frame can reach the host while the firmware, past sending it,
            // still writes the snapshot of that update to retained RAM (its transmit
            // queue drains by interrupt): a reset then would find the snapshot torn and
            // rightly refuse it, which the host's model of the reset does not do. The
            // uplink waits at the cut, so the firmware is idle once that write is done:
            // a quarter second of host time covers it on a loaded host.
            std::thread::sleep(std::time::Duration::from_millis(250));
            system_reset(&self.qmp)?;
            self.done_after_us = Some(self.last_periods_us.unwrap_or(0));
            if let Some(made) = self.made.take() {
                // The sender may have stopped already; then nothing waits for this.
                let _ = made.send(());
            }
        }
        Ok(())
    }
}

/// Counts, with the stopwatch plugin of `cargo xtask bench`, the guest instructions
/// from the reset vector (`Reset`) to the first period the restore writes (the entry
/// of the flight binary's `FirstWrite::write_period`).
pub struct BootCount {
    pub plugin_args: String,
    out: PathBuf,
}

impl BootCount {
    pub fn new(elf: &Path) -> Result<BootCount> {
        let out = elf.with_file_name("reset-boot-counts.txt");
        let first_write = |n: &str| n.contains("FirstWrite") && n.contains("write_period");
        let plugin_args = bench::stopwatch(elf, |n| n == "Reset", first_write, &out)?;
        Ok(BootCount { plugin_args, out })
    }

    /// The count of the last reset that wrote a period (None: no restore wrote one).
    pub fn read(&self) -> Option<u64> {
        let text = std::fs::read_to_string(&self.out).ok()?;
        text.lines().rev().find_map(|l| l.trim().parse().ok())
    }
}

/// `system_reset` through QEMU's QMP socket at `path`: the greeting, the capabilities
/// handshake, the command, each answered on a line of its own.
fn system_reset(path: &Path) -> Result<()> {
    let stream = UnixStream::connect(path)
        .with_context(|| format!("cannot connect to QEMU's QMP socket {}", path.display()))?;
    let mut writer = stream.try_clone().context("QMP socket")?;
    let mut reader = BufReader::new(stream);
    let mut line = String::new();
    reader.read_line(&mut line).context("QMP greeting")?;
    for command in ["qmp_capabilities", "system_reset"] {
        writeln!(writer, "{{\"execute\":\"{command}\"}}").context("QMP command")?;
        // Events (e.g. RESET) may come before the answer: read up to the "return".
        loop {
            line.clear();
            if reader.read_line(&mut line).context("QMP answer")? == 0 {
                bail!("QEMU closed its QMP socket during `{command}`");
            }
            if line.contains("\"return\"") {
                break;
            }
            if line.contains("\"error\"") {
                bail!("QMP `{command}`: {}", line.trim());
            }
        }
    }
    Ok(())
}

/// What the reset cost, from the firmware's downlink and the log of its `run` against
/// the `twin`'s downlink (the run without the reset), and whether the firmware recovered
/// as the host's model of the same reset does ([`HostRun::reset`]). Returns the report's
/// lines, the inputs the firmware had in force at each update (none of the lost frames,
/// the attitude blend restarted by the reset), and the updates whose PERIODS differ from
/// the host's model of the reset on the `clean` uplink (without its injected faults),
/// with examples: what the faults changed.
pub fn check(
    plan: Plan,
    run: &QemuRun,
    firmware: &Downlink,
    twin: &Downlink,
    uplink: &[u8],
    clean: &[u8],
    config: Config,
) -> Result<(Verdict, Inputs, (usize, Vec<String>))> {
    let Some(reset_after_us) = run.reset_after_us else {
        bail!("the pass never reached {} s: no reset was made", plan.at_s);
    };
    let split = |bytes| {
        let (cut, resume) = plan.cuts(bytes);
        Uplink::split(bytes, cut, resume)
    };
    let (Uplink { before, lost, rest }, clean) = (split(uplink), split(clean));
    let log = &run.log;
    // The first STATUS of the firmware after its reset (resets since power-on > 0).
    let boot = firmware
        .status
        .iter()
        .find(|(t, s)| *t > reset_after_us && s.resets > 0)
        .and_then(|(_, s)| Some((s.reset_cause?, s.resets)));
    let cause = boot.map_or("no STATUS reports it".into(), |(c, n)| {
        format!("{}, {n} since power-on", c.name())
    });
    // "restored after the reset: N periods programmed D us after the board came up"
    let restored_us: Option<u64> = log.iter().find_map(|m| {
        let rest = m.strip_prefix("restored after the reset: ")?;
        super::log_field(rest, "programmed ", " us")
    });
    // "boot: reset cause C, N resets since power-on, core clock F Hz"
    let core_clock_hz: Option<f64> = log
        .iter()
        .rev()
        .find_map(|m| super::log_field(m.strip_prefix("boot: ")?, "core clock ", " Hz"));
    // The first update after the reset with every record fresh (not held).
    let fresh_at_us = firmware
        .decoded()
        .into_iter()
        .filter(|(t, _)| *t > reset_after_us)
        .find(|(_, p)| !p.records().is_empty() && p.records().iter().all(|r| !r.held))
        .map(|(t, _)| t);
    // Updates after `fresh_at_us` whose PERIODS differ from the twin's, and the largest
    // relative change of a period among them.
    let twin: BTreeMap<u64, &Vec<u8>> = twin.periods.iter().map(|(t, p)| (*t, p)).collect();
    let mut changed = 0;
    let mut largest_change = 0.0f64;
    let mut examples = Vec::new();
    // The attitude blend was in force: the reset keeps its estimate, not the change of
    // the rates it carries (made again from the next GNSS fix), so the first frames
    // after it may round a period otherwise.
    let mut attitude_frames = false;
    Decoder::new().feed(before, |e| {
        attitude_frames |= matches!(e, Event::Frame(f) if f.kind == kind::ATTITUDE);
    });
    let blend_in_force = attitude_frames && config.attitude_blend.gain < 1.0;
    if let Some(fresh) = fresh_at_us {
        // Mode, ticks and held flags: the drift and yaw request may differ in their
        // last bits on the bus's frames, whose C2T pole (kept up to a minute by
        // `controller::track`) is recomputed after a reset.
        for (t, p) in firmware.periods.iter().filter(|(t, _)| *t >= fresh) {
            if super::describe(twin.get(t).copied()) != super::describe(Some(p)) {
                changed += 1;
                if let (Some(a), Some(b)) = (
                    twin.get(t).and_then(|q| Periods::decode(q)),
                    Periods::decode(p),
                ) {
                    for (x, y) in a.records().iter().zip(b.records()) {
                        let rel = (f64::from(y.ticks) / f64::from(x.ticks) - 1.0).abs();
                        if x.index == y.index && rel.is_finite() {
                            largest_change = largest_change.max(rel);
                        }
                    }
                }
                if examples.len() < 5 {
                    let held = Periods::decode(p)
                        .map_or(0, |p| p.records().iter().filter(|r| r.held).count());
                    examples.push(format!(
                        "update at {:.3} s after the recovery differs from the run without the reset ({held} held)",
                        *t as f64 * 1e-6
                    ));
                }
            }
        }
    }
    let mut lost_kinds = BTreeMap::new();
    let mut lost_until_us = None;
    Decoder::new().feed(lost, |e| {
        if let Event::Frame(f) = e {
            *lost_kinds.entry(f.kind).or_insert(0) += 1;
            lost_until_us = Some(check::pass_us(f.time_us));
        }
    });
    let mut unlike_model = Vec::new();
    // The host's model of the reset on the uplink without its injected faults: the
    // inputs the firmware had (none of the lost frames, the attitude blend restarted
    // by the reset), and the updates the faults changed. A cause and count only
    // change STATUS, which this does not compare.
    let (boot_cause, resets) = boot.unwrap_or((controller::fault::ResetCause::ALL[0], 1));
    let clean_model = HostRun::reset(
        clean.before,
        clean.rest,
        boot_cause,
        u32::from(resets),
        config,
    )?;
    let changed_by_faults = super::compare_with_twin(firmware, &clean_model.downlink());
    let model = HostRun::reset(before, rest, boot_cause, u32::from(resets), config)?.downlink();
    if boot.is_none() {
        unlike_model.push("no STATUS after the reset: nothing to model".into());
    } else {
        if let Some(k) = (0..firmware.periods.len().max(model.periods.len()))
            .find(|&k| firmware.periods.get(k) != model.periods.get(k))
        {
            let at = |d: &Downlink| {
                d.periods
                    .get(k)
                    .map_or("none".into(), |(t, _)| format!("{:.3} s", *t as f64 * 1e-6))
            };
            unlike_model.push(format!(
                "PERIODS frame {k} ({} in the firmware, {} in the host's model of the reset) differs",
                at(firmware),
                at(&model)
            ));
        }
        if firmware.status != model.status {
            unlike_model.push(format!(
                "the STATUS frames differ from the host's model of the reset ({} vs {})",
                firmware.status.len(),
                model.status.len()
            ));
        }
    }
    // The time is that of the instructions at one a cycle, the core's clock rate: QEMU
    // counts instructions exactly, not cycles (docs/target.md).
    let restored = match (restored_us, run.boot_instructions, core_clock_hz) {
        (None, ..) => "not restored".into(),
        (Some(_), Some(n), Some(hz)) => format!(
            "periods restored after {:.0} us ({n} instructions from the reset vector at {:.0} MHz)",
            n as f64 / hz * 1e6,
            hz * 1e-6
        ),
        (Some(d), ..) => format!("periods restored after {d} us of QEMU's host time"),
    };
    let fresh = fresh_at_us.map_or("never fresh again".into(), |t| {
        format!("held until fresh telemetry at {:.2} s", t as f64 * 1e-6)
    });
    let blend = if blend_in_force {
        format!(
            " (the attitude blend in force: its estimate kept, taken up again by a frame within its largest gap: largest period change {largest_change:.1e})"
        )
    } else {
        String::new()
    };
    let mut verdict = Verdict::default();
    verdict.say(format!(
        "reset: at {:.2} s ({cause}), {restored}, {fresh}; outputs changed by the reset {changed}{blend}",
        reset_after_us as f64 * 1e-6
    ));
    if let Some(until_us) = lost_until_us {
        let kinds: Vec<String> = lost_kinds
            .iter()
            .map(|(k, n)| format!("{n} {}", kind_name(*k)))
            .collect();
        verdict.say(format!(
            "reset loss: the firmware never got {} (tagged up to {:.2} s); the host's model of the reset loses the same",
            kinds.join(", "),
            until_us as f64 * 1e-6
        ));
    }
    let (periods, status) = (model.periods.len(), model.status.len());
    let equal = if unlike_model.is_empty() {
        "equal"
    } else {
        "differ from"
    };
    verdict.say(format!(
        "reset model: the firmware's frames {equal} the host's run of the same reset between the same frames ({periods} PERIODS, {status} STATUS)"
    ));
    if restored_us.is_none() {
        verdict.fail("the firmware did not restore its periods after the reset".into());
    }
    if fresh_at_us.is_none() {
        verdict.fail("no fresh update after the reset".into());
    }
    // A reset keeps the attitude blend's estimate but not its rates' change (until the
    // next fix), and one that loses frames loses them as a link would: either may change
    // later outputs, and the host's model of the same reset is the check. Without a
    // blend in force (NAV, or the blend off) and without a loss, nothing may change.
    if lost_kinds.is_empty() && !blend_in_force {
        examples.into_iter().for_each(|e| verdict.fail(e));
    }
    unlike_model.into_iter().for_each(|e| verdict.fail(e));
    Ok((verdict, clean_model.inputs, changed_by_faults))
}

/// A frame kind's name in the reset's loss line.
fn kind_name(k: u8) -> String {
    match k {
        kind::NAV => "NAV".into(),
        kind::SCENE => "SCENE".into(),
        kind::TERRAIN => "TERRAIN".into(),
        kind::TIME => "TIME".into(),
        kind::GNSS => "GNSS".into(),
        kind::ATTITUDE => "ATTITUDE".into(),
        kind::TIME_SCALES => "TIME_SCALES".into(),
        other => format!("kind {other:#04x}"),
    }
}
