//! The controller's telemetry path on the target: frames built on the target, fed byte
//! by byte through `controller::session::Session` (what the firmware runs), once clean
//! and once with faults mixed in. Every fault must be counted under its own counter and
//! the line periods sent must be identical to the clean run's.
#![no_std]
#![no_main]

use hil_tests as _;

use core::convert::Infallible;

use controller::frame::{encode, kind, MAX_FRAME};
use controller::nav::{Attitude, Nav};
use controller::session::Session;
use controller::{Controller, Counters, Fault, LinePeriodSink, Scene};
use core_math::{StateVector, GM_M3_S2};

struct Accept;

impl LinePeriodSink for Accept {
    type Error = Infallible;
    fn write_period(&mut self, _index: u8, _ticks: u32) -> Result<(), Infallible> {
        Ok(())
    }
}

/// ECI state on a 645 km circular orbit, i0 97.98 deg, at time `t_s`.
fn state(t_s: f64) -> StateVector {
    let (r_e, h) = (6_371_000.0, 645e3);
    let a = r_e + h;
    let speed = libm::sqrt(GM_M3_S2 / a);
    let u = 0.3 + core_math::sphere::orbital_rate_rad_s(r_e, h) * t_s;
    let i = 97.98f64.to_radians();
    let (si, ci) = (libm::sin(i), libm::cos(i));
    let (su, cu) = (libm::sin(u), libm::cos(u));
    let p = [1.0, 0.0, 0.0];
    let q = [0.0, ci, si];
    StateVector {
        position_m: core::array::from_fn(|k| a * (cu * p[k] + su * q[k])),
        velocity_mps: core::array::from_fn(|k| speed * (-su * p[k] + cu * q[k])),
    }
}

/// What a run sent: the number of PERIODS frames, an FNV-1a hash of their bytes, and
/// the fault counters at the end.
struct Run {
    periods: u32,
    hash: u32,
    counters: Counters,
}

/// Which fault to inject after the frame of tick `k`.
#[derive(Clone, Copy, PartialEq)]
enum Inject {
    None,
    BitFlip,
    Truncated,
    Noise,
    NaN,
    Backwards,
}

fn inject_at(k: u64) -> Inject {
    match k {
        10 => Inject::BitFlip,
        20 => Inject::Truncated,
        30 => Inject::Noise,
        40 => Inject::NaN,
        50 => Inject::Backwards,
        _ => Inject::None,
    }
}

fn play(faults: bool) -> Run {
    let controller = match Controller::new(hil_tests::controller_config(), Scene::paper_default()) {
        Ok(c) => c,
        Err(f) => defmt::panic!("default scene refused: {=str}", f.name()),
    };
    let mut session = Session::new(controller);
    let mut run = Run {
        periods: 0,
        hash: 0x811c_9dc5,
        counters: Counters::default(),
    };
    let mut feed = |session: &mut Session, bytes: &[u8]| {
        session.feed(bytes, &mut Accept, |f| {
            if f.get(3) == Some(&kind::PERIODS) {
                run.periods += 1;
                for &b in f {
                    run.hash = (run.hash ^ u32::from(b)).wrapping_mul(0x0100_0193);
                }
            }
        });
    };
    let mut buf = [0u8; MAX_FRAME];
    let mut payload = [0u8; 128];
    let att = Attitude {
        roll_rad: 10f32.to_radians(),
        roll_rate_rad_s: 0.5f32.to_radians(),
        ..Attitude::default()
    };
    let nav_at = |t_us: u64, payload: &mut [u8]| {
        let t_s = t_us as f64 * 1e-6;
        let nav = Nav {
            state: state(t_s),
            attitude: Attitude {
                roll_rad: att.roll_rad + att.roll_rate_rad_s * t_s as f32,
                ..att
            },
        };
        nav.encode(payload).unwrap_or(0)
    };
    let mut seq = 0u16;
    // Three seconds at 20 ms ticks, NAV every 250 ms.
    for k in 0..=150u64 {
        let t = k * 20_000;
        let (kind, n) = if t % 250_000 == 0 {
            (kind::NAV, nav_at(t, &mut payload))
        } else {
            (kind::TIME, 0)
        };
        let len = encode(kind, seq, t, &payload[..n], &mut buf).unwrap_or(0);
        seq = seq.wrapping_add(1);
        feed(&mut session, &buf[..len]);
        let what = if faults { inject_at(k) } else { Inject::None };
        let t_extra = t + 10_000;
        match what {
            Inject::None => {}
            Inject::BitFlip | Inject::Truncated => {
                let n = nav_at(t_extra, &mut payload);
                let len = encode(kind::NAV, seq, t_extra, &payload[..n], &mut buf).unwrap_or(0);
                if what == Inject::BitFlip {
                    buf[40] ^= 0x04;
                    feed(&mut session, &buf[..len]);
                } else {
                    feed(&mut session, &buf[..30]);
                }
            }
            Inject::Noise => feed(&mut session, &[0x00, 0x55, 0xAA, 0x12, 0xFF, 0x90]),
            Inject::NaN | Inject::Backwards => {
                let n = nav_at(t_extra, &mut payload);
                if what == Inject::NaN {
                    payload[8..16].copy_from_slice(&f64::NAN.to_le_bytes());
                }
                let tag = if what == Inject::NaN {
                    t_extra
                } else {
                    t - 100_000
                };
                let len = encode(kind::NAV, seq, tag, &payload[..n], &mut buf).unwrap_or(0);
                feed(&mut session, &buf[..len]);
            }
        }
    }
    run.counters = session.controller.counters;
    run
}

#[defmt_test::tests]
mod tests {
    use super::*;

    #[test]
    fn faults_are_counted_and_change_no_period() {
        let clean = play(false);
        let faulty = play(true);
        defmt::info!(
            "{=u32} updates; faults counted: {=u32}",
            clean.periods,
            faulty.counters.total()
        );
        defmt::assert_eq!(clean.counters.total(), 0);
        defmt::assert_eq!(clean.periods, 151);
        for (f, n) in [
            (Fault::BadCrc, 1),
            (Fault::Truncated, 1),
            (Fault::NonFinite, 1),
            (Fault::TimeWentBackwards, 1),
        ] {
            defmt::assert_eq!(faulty.counters.get(f), n, "{=str}", f.name());
        }
        defmt::assert_eq!(faulty.counters.total(), 4);
        defmt::assert_eq!(faulty.periods, clean.periods);
        defmt::assert_eq!(faulty.hash, clean.hash, "PERIODS differ with faults");
    }
}
