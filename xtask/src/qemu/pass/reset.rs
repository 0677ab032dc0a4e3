//! `cargo xtask run --reset-at SECONDS`: the firmware reset in the middle of a pass, as
//! its reset line would do it (QEMU's `system_reset`, through its QMP socket), and what
//! the reset cost: when the periods came back, until when they stayed held, and how many
//! updates after the recovery differ from a run without the reset (docs/target.md,
//! "Faults and resets").

use anyhow::{anyhow, bail, Context, Result};
use std::collections::BTreeMap;
use std::io::{BufRead, BufReader, Write};
use std::os::unix::net::UnixStream;
use std::path::{Path, PathBuf};

use controller::frame::{kind, Decoder, Event};
use controller::report::Periods;

use super::check::Downlink;

/// The reset to make: at which pass time, through which QMP socket.
pub struct Trigger {
    pub at_us: u64,
    pub qmp: PathBuf,
    decoder: Decoder,
    /// The time tag of the PERIODS frame after which the reset was asked for.
    pub done_after_us: Option<u64>,
}

impl Trigger {
    pub fn new(at_s: f64, qmp: PathBuf) -> Trigger {
        Trigger {
            at_us: (at_s * 1e6).round() as u64,
            qmp,
            decoder: Decoder::new(),
            done_after_us: None,
        }
    }

    /// QEMU's arguments for the QMP socket.
    pub fn qemu_args(&self) -> Vec<String> {
        vec![
            "-qmp".into(),
            format!("unix:{},server=on,wait=off", self.qmp.display()),
        ]
    }

    /// Watches the downlink: at the first PERIODS frame at or after the reset instant,
    /// resets the machine.
    pub fn watch(&mut self, bytes: &[u8]) -> Result<()> {
        if self.done_after_us.is_some() {
            return Ok(());
        }
        let at_us = self.at_us;
        let mut due = None;
        self.decoder.feed(bytes, |e| {
            if let Event::Frame(f) = e {
                if f.kind == kind::PERIODS && f.time_us >= at_us && due.is_none() {
                    due = Some(f.time_us);
                }
            }
        });
        if let Some(t_us) = due {
            system_reset(&self.qmp)?;
            self.done_after_us = Some(t_us);
        }
        Ok(())
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

/// What the reset cost, from the firmware's downlink and log against the twin's
/// downlink (the run without the reset).
pub struct Report {
    pub reset_after_us: u64,
    pub cause: String,
    pub restored_us: Option<u64>,
    /// The first update after the reset with every record fresh (not held).
    pub fresh_at_us: Option<u64>,
    /// Updates after `fresh_at_us` whose PERIODS differ from the twin's.
    pub changed: usize,
    pub examples: Vec<String>,
}

impl Report {
    pub fn new(
        reset_after_us: u64,
        firmware: &Downlink,
        twin: &Downlink,
        log: &[String],
    ) -> Report {
        // The first STATUS of the firmware after its reset (resets since power-on > 0).
        let cause = firmware
            .status
            .iter()
            .find(|(t, s)| *t > reset_after_us && s.resets > 0)
            .and_then(|(_, s)| Some((s.reset_cause?, s.resets)))
            .map_or("no STATUS reports it".into(), |(c, n)| {
                format!("{}, {n} since power-on", c.name())
            });
        // "restored after the reset: N periods programmed D us after the board came up"
        let restored_us = log.iter().find_map(|m| {
            let rest = m.strip_prefix("restored after the reset: ")?;
            let (_, after) = rest.split_once("programmed ")?;
            after.split_once(" us")?.0.trim().parse().ok()
        });
        let decoded = firmware.decoded();
        let fresh_at_us = decoded
            .iter()
            .filter(|(t, _)| *t > reset_after_us)
            .find(|(_, p)| !p.records().is_empty() && p.records().iter().all(|r| !r.held))
            .map(|(t, _)| *t);
        let twin: BTreeMap<u64, &Vec<u8>> = twin.periods.iter().map(|(t, p)| (*t, p)).collect();
        let mut changed = 0;
        let mut examples = Vec::new();
        if let Some(fresh) = fresh_at_us {
            for (t, p) in firmware.periods.iter().filter(|(t, _)| *t >= fresh) {
                if twin.get(t) != Some(&p) {
                    changed += 1;
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
        Report {
            reset_after_us,
            cause,
            restored_us,
            fresh_at_us,
            changed,
            examples,
        }
    }

    pub fn print(&self) {
        let restored = self.restored_us.map_or("not restored".into(), |d| {
            format!("periods restored after {d} us")
        });
        let fresh = self.fresh_at_us.map_or("never fresh again".into(), |t| {
            format!("held until fresh telemetry at {:.2} s", t as f64 * 1e-6)
        });
        println!(
            "reset: at {:.2} s ({}), {restored}, {fresh}; outputs changed by the reset {}",
            self.reset_after_us as f64 * 1e-6,
            self.cause,
            self.changed
        );
    }

    pub fn problems(&self) -> Vec<String> {
        let mut p = Vec::new();
        if self.restored_us.is_none() {
            p.push("the firmware did not restore its periods after the reset".into());
        }
        if self.fresh_at_us.is_none() {
            p.push("no fresh update after the reset".into());
        }
        p.extend(self.examples.iter().cloned());
        p
    }
}

/// The reset instant on the command line, checked against the pass.
pub fn check_instant(at_s: f64, end_us: u64) -> Result<()> {
    if !(at_s > 0.0 && at_s * 1e6 < end_us as f64) {
        return Err(anyhow!(
            "--reset-at {at_s}: the pass runs from 0 to {:.1} s",
            end_us as f64 * 1e-6
        ));
    }
    Ok(())
}
