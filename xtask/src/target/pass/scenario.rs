//! What a pass is: NAV telemetry samples, the truth the reference check uses, and the
//! faults to inject. The default pass is built here from a circular Keplerian orbit and
//! a roll manoeuvre; a user's pass comes from a CSV file.

use controller::nav::{Attitude, Nav};
use core_math::{Geometry, StateVector, GM_M3_S2};

use crate::csv::Table;

/// One NAV frame's content and time tag.
#[derive(Clone, Copy, Debug)]
pub struct Sample {
    pub t_us: u64,
    pub nav: Nav,
}

/// A circular Keplerian orbit over a round Earth (ECI, z along the spin axis).
#[derive(Clone, Copy, Debug)]
pub struct CircularOrbit {
    pub earth_radius_m: f64,
    pub altitude_m: f64,
    pub inclination_rad: f64,
    /// Right ascension of the ascending node.
    pub raan_rad: f64,
    /// Argument of latitude at t = 0.
    pub u0_rad: f64,
}

impl CircularOrbit {
    /// Mean motion sqrt(GM / a^3) (rad/s).
    pub fn rate_rad_s(&self) -> f64 {
        core_math::orbital_rate_rad_s(self.earth_radius_m, self.altitude_m)
    }

    pub fn arg_latitude_rad(&self, t_s: f64) -> f64 {
        self.u0_rad + self.rate_rad_s() * t_s
    }

    /// ECI position and velocity at `t_s`.
    pub fn state(&self, t_s: f64) -> StateVector {
        let a = self.earth_radius_m + self.altitude_m;
        let speed = (GM_M3_S2 / a).sqrt();
        let (si, ci) = self.inclination_rad.sin_cos();
        let (su, cu) = self.arg_latitude_rad(t_s).sin_cos();
        let (sn, cn) = self.raan_rad.sin_cos();
        // In-plane unit vectors: towards the node, and 90 deg ahead of it.
        let p = [cn, sn, 0.0];
        let q = [-sn * ci, cn * ci, si];
        StateVector {
            position_m: std::array::from_fn(|k| a * (cu * p[k] + su * q[k])),
            velocity_mps: std::array::from_fn(|k| speed * (-su * p[k] + cu * q[k])),
        }
    }
}

/// Roll as a piecewise-linear function of time through `corners` (t_s, roll_rad),
/// constant before the first and after the last.
#[derive(Clone, Debug)]
pub struct RollProfile {
    pub corners: Vec<(f64, f64)>,
}

impl RollProfile {
    /// Roll (rad) and its rate (rad/s; the rate of the piece starting at `t_s`).
    pub fn at(&self, t_s: f64) -> (f64, f64) {
        let c = &self.corners;
        let Some(&(t_first, r_first)) = c.first() else {
            return (0.0, 0.0);
        };
        if t_s < t_first {
            return (r_first, 0.0);
        }
        for w in c.windows(2) {
            let ((t0, r0), (t1, r1)) = (w[0], w[1]);
            if t_s >= t0 && t_s < t1 {
                let rate = (r1 - r0) / (t1 - t0);
                return (r0 + rate * (t_s - t0), rate);
            }
        }
        (c.last().map_or(r_first, |l| l.1), 0.0)
    }
}

/// The state the reference check holds the firmware to.
#[derive(Clone, Debug)]
pub enum Truth {
    /// The default pass: the orbit and the roll profile, exact at any instant.
    Circular {
        orbit: CircularOrbit,
        roll: RollProfile,
    },
    /// A user's file: the last NAV sample the controller accepted, propagated to the
    /// update instant in f64 (argument of latitude at the orbit rate, roll at its rate).
    Telemetry,
}

impl Truth {
    /// The f64 geometry at `t_s`, when known from the truth alone.
    pub fn geometry(&self, t_s: f64) -> Option<Geometry<f64>> {
        match self {
            Truth::Circular { orbit, roll } => Some(Geometry::circular(
                roll.at(t_s).0,
                orbit.inclination_rad,
                orbit.arg_latitude_rad(t_s),
                orbit.altitude_m,
                orbit.earth_radius_m,
            )),
            Truth::Telemetry => None,
        }
    }

    /// Roll (deg) at `t_s` for the table, when known.
    pub fn roll_deg(&self, t_s: f64) -> Option<f64> {
        match self {
            Truth::Circular { roll, .. } => Some(roll.at(t_s).0.to_degrees()),
            Truth::Telemetry => None,
        }
    }
}

/// A fault to inject, at a time in seconds.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FaultSpec {
    /// One bit of the NAV frame at `t_s` flipped in its payload (the frame is lost).
    BitFlip { t_s: f64 },
    /// The NAV frame at `t_s` cut short after its header and 20 payload bytes.
    Truncate { t_s: f64 },
    /// `bytes` bytes of line noise (never a sync byte) after the frame at `t_s`.
    Noise { t_s: f64, bytes: usize },
    /// After the frame at `t_s`, a good NAV frame time-tagged `back_s` earlier.
    Backwards { t_s: f64, back_s: f64 },
    /// An extra NAV frame at `t_s` with a NaN velocity component.
    NaN { t_s: f64 },
    /// An extra NAV frame at `t_s` placing the spacecraft at `altitude_m`.
    Altitude { t_s: f64, altitude_m: f64 },
    /// No NAV frame strictly between `from_s` and `from_s + len_s` (TIME goes on).
    Gap { from_s: f64, len_s: f64 },
    /// After the frame at `t_s`, a TIME frame (valid CRC) tagged `tag_us`: beyond the
    /// time window, so refused as `time_jump` (issue 13's first defect).
    TimeTag { t_s: f64, tag_us: u64 },
    /// An extra SCENE frame at `t_s` that the camera cannot use: refused as
    /// `invalid_scene` (issue 13's third defect).
    BadScene { t_s: f64, probe: SceneProbe },
}

/// The SCENE uploads an outside client found accepted before issue 13.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SceneProbe {
    /// A segment's `active` byte is 2.
    ActiveByte2,
    /// Largest stage count and a segment's stages 65 535.
    Stages65535,
    /// Every segment inactive.
    NoneActive,
    /// Two segments overlap.
    Overlap,
    /// 17 segments (a length that matches the count).
    Segments17,
}

impl SceneProbe {
    pub const ALL: [SceneProbe; 5] = [
        SceneProbe::ActiveByte2,
        SceneProbe::Stages65535,
        SceneProbe::NoneActive,
        SceneProbe::Overlap,
        SceneProbe::Segments17,
    ];

    pub fn label(&self) -> &'static str {
        match self {
            SceneProbe::ActiveByte2 => "active byte 2",
            SceneProbe::Stages65535 => "65 535 TDI stages",
            SceneProbe::NoneActive => "no active segment",
            SceneProbe::Overlap => "overlapping segments",
            SceneProbe::Segments17 => "17 segments",
        }
    }

    /// The SCENE payload: the paper's scene, then the edit.
    pub fn payload(&self) -> Vec<u8> {
        use controller::scene::{SCENE_HEADER_LEN, SEGMENT_LEN};
        let mut scene = controller::Scene::paper_default();
        match self {
            SceneProbe::Stages65535 => {
                scene.max_stages = u16::MAX;
                scene.segments[0].tdi_stages = u16::MAX;
            }
            SceneProbe::NoneActive => scene.segments.iter_mut().for_each(|s| s.active = false),
            SceneProbe::Overlap => scene.segments[4].first_px = scene.segments[3].last_px - 999,
            SceneProbe::ActiveByte2 | SceneProbe::Segments17 => {}
        }
        let mut p = vec![0u8; controller::frame::MAX_PAYLOAD];
        let n = scene.encode(&mut p).unwrap_or(0);
        p.truncate(n);
        let seg = |k: usize| SCENE_HEADER_LEN + k * SEGMENT_LEN;
        match self {
            SceneProbe::ActiveByte2 => p[seg(3) + 10] = 2,
            SceneProbe::Segments17 => {
                // 17 chips of 3 529 pixels across the same array.
                p[34] = 17;
                let template = p[seg(0)..seg(1)].to_vec();
                p.truncate(SCENE_HEADER_LEN);
                for k in 0..17i32 {
                    let mut s = template.clone();
                    let first = -30_000 + 3_529 * k;
                    s[0..4].copy_from_slice(&first.to_le_bytes());
                    s[4..8].copy_from_slice(&(first + 3_528).to_le_bytes());
                    p.extend_from_slice(&s);
                }
            }
            _ => {}
        }
        p
    }
}

impl FaultSpec {
    pub fn label(&self) -> String {
        match self {
            FaultSpec::BitFlip { t_s } => format!("bit flip in NAV at {t_s} s"),
            FaultSpec::Truncate { t_s } => format!("truncated NAV at {t_s} s"),
            FaultSpec::Noise { t_s, bytes } => format!("{bytes} noise bytes at {t_s} s"),
            FaultSpec::Backwards { t_s, back_s } => {
                format!("NAV time-tagged {back_s} s back at {t_s} s")
            }
            FaultSpec::NaN { t_s } => format!("NaN velocity in NAV at {t_s} s"),
            FaultSpec::Altitude { t_s, altitude_m } => {
                format!("altitude {} km in NAV at {t_s} s", altitude_m / 1e3)
            }
            FaultSpec::Gap { from_s, len_s } => format!("{len_s} s NAV gap from {from_s} s"),
            FaultSpec::TimeTag { t_s, tag_us } => format!("TIME tagged {tag_us} us at {t_s} s"),
            FaultSpec::BadScene { t_s, probe } => {
                format!("SCENE with {} at {t_s} s", probe.label())
            }
        }
    }
}

/// A pass: telemetry, truth, faults.
#[derive(Clone, Debug)]
pub struct Pass {
    pub name: String,
    /// NAV samples in sending order (the gaps already cut out).
    pub samples: Vec<Sample>,
    /// Cadence of TIME frames (us): the controller's update period.
    pub tick_us: u64,
    /// Last instant of the pass (us): TIME frames run up to it.
    pub end_us: u64,
    pub truth: Truth,
    pub faults: Vec<FaultSpec>,
}

pub fn us(t_s: f64) -> u64 {
    (t_s * 1e6).round().max(0.0) as u64
}

/// NAV rate of the built-in passes.
pub const NAV_PERIOD_US: u64 = 250_000;

/// The paper's orbit: sun-synchronous, 645 km, i0 97.98 deg; node and start position
/// arbitrary (the round-Earth model does not depend on the node).
pub fn paper_orbit(earth_radius_m: f64) -> CircularOrbit {
    CircularOrbit {
        earth_radius_m,
        altitude_m: 645e3,
        inclination_rad: 97.98f64.to_radians(),
        raan_rad: 0.4,
        u0_rad: (-20f64).to_radians(),
    }
}

/// A pass over `orbit` with `roll`, NAV at 4 Hz from 0 to `duration_s`, the `gaps`
/// among `faults` cut out of the samples.
pub fn synthetic(
    name: &str,
    orbit: CircularOrbit,
    roll: RollProfile,
    duration_s: f64,
    tick_us: u64,
    faults: Vec<FaultSpec>,
) -> Pass {
    let end_us = us(duration_s);
    let in_gap = |t_us: u64| {
        faults.iter().any(|f| match *f {
            FaultSpec::Gap { from_s, len_s } => t_us > us(from_s) && t_us < us(from_s + len_s),
            _ => false,
        })
    };
    let samples = (0..=end_us / NAV_PERIOD_US)
        .map(|k| k * NAV_PERIOD_US)
        .filter(|&t| !in_gap(t))
        .map(|t_us| Sample {
            t_us,
            nav: true_nav(&orbit, &roll, t_us as f64 * 1e-6),
        })
        .collect();
    Pass {
        name: name.to_string(),
        samples,
        tick_us,
        end_us,
        truth: Truth::Circular { orbit, roll },
        faults,
    }
}

/// The NAV content the spacecraft would send at `t_s`: orbit state, roll and its rate.
pub fn true_nav(orbit: &CircularOrbit, roll: &RollProfile, t_s: f64) -> Nav {
    let (r, rate) = roll.at(t_s);
    Nav {
        state: orbit.state(t_s),
        attitude: Attitude {
            roll_rad: r as f32,
            roll_rate_rad_s: rate as f32,
            ..Attitude::default()
        },
    }
}

/// The link probes of issue 13 from `t0_s` on: a TIME frame tagged 2^64 - 1, one an
/// hour ahead, then each SCENE the camera cannot use; every one must be refused under
/// its own counter and change nothing.
pub fn link_probes(t0_s: f64) -> Vec<FaultSpec> {
    let mut out = vec![
        FaultSpec::TimeTag {
            t_s: t0_s,
            tag_us: u64::MAX,
        },
        FaultSpec::TimeTag {
            t_s: t0_s + 0.5,
            tag_us: us(t0_s + 0.5 + 3600.0),
        },
    ];
    for (k, probe) in SceneProbe::ALL.into_iter().enumerate() {
        out.push(FaultSpec::BadScene {
            t_s: t0_s + 1.005 + 0.001 * k as f64,
            probe,
        });
    }
    out
}

/// The default pass: ten minutes of the paper's orbit; roll 0, then 0 -> 25 deg at
/// 1 deg/s (60-85 s), held, and back at 1 deg/s (400-425 s); faults spread over it,
/// none at a corner of the roll profile (a lost frame there would leave the controller
/// extrapolating the old rate, which is the telemetry's loss, not an error).
pub fn default_pass(earth_radius_m: f64, tick_us: u64) -> Pass {
    let roll = RollProfile {
        corners: vec![
            (60.0, 0.0),
            (85.0, 25f64.to_radians()),
            (400.0, 25f64.to_radians()),
            (425.0, 0.0),
        ],
    };
    let mut faults = vec![
        FaultSpec::BitFlip { t_s: 30.0 },
        FaultSpec::BitFlip { t_s: 70.5 },
        FaultSpec::Truncate { t_s: 120.25 },
        FaultSpec::Noise {
            t_s: 150.0,
            bytes: 48,
        },
        FaultSpec::Backwards {
            t_s: 200.0,
            back_s: 1.0,
        },
        FaultSpec::NaN { t_s: 250.125 },
        FaultSpec::Altitude {
            t_s: 300.125,
            altitude_m: 100e3,
        },
        FaultSpec::BitFlip { t_s: 410.0 },
        FaultSpec::Gap {
            from_s: 500.0,
            len_s: 2.0,
        },
    ];
    faults.extend(link_probes(160.0));
    synthetic(
        "default pass (600 s)",
        paper_orbit(earth_radius_m),
        roll,
        600.0,
        tick_us,
        faults,
    )
}

/// The end-to-end test's pass: one minute, a faster manoeuvre (0 -> 25 deg at 2 deg/s
/// and back), every kind of fault.
pub fn short_pass(earth_radius_m: f64, tick_us: u64) -> Pass {
    let roll = RollProfile {
        corners: vec![
            (10.0, 0.0),
            (22.5, 25f64.to_radians()),
            (35.0, 25f64.to_radians()),
            (47.5, 0.0),
        ],
    };
    let mut faults = vec![
        FaultSpec::BitFlip { t_s: 5.0 },
        FaultSpec::Truncate { t_s: 8.0 },
        FaultSpec::Noise {
            t_s: 12.0,
            bytes: 40,
        },
        FaultSpec::Backwards {
            t_s: 15.0,
            back_s: 0.5,
        },
        FaultSpec::NaN { t_s: 18.125 },
        FaultSpec::Altitude {
            t_s: 25.125,
            altitude_m: 100e3,
        },
        FaultSpec::BitFlip { t_s: 40.0 },
        FaultSpec::Gap {
            from_s: 50.0,
            len_s: 2.0,
        },
    ];
    faults.extend(link_probes(28.0));
    synthetic(
        "short pass (60 s)",
        paper_orbit(earth_radius_m),
        roll,
        60.0,
        tick_us,
        faults,
    )
}

/// The CSV columns of a telemetry file, in this order when written.
pub const CSV_COLUMNS: [&str; 13] = [
    "t_s",
    "rx_m",
    "ry_m",
    "rz_m",
    "vx_mps",
    "vy_mps",
    "vz_mps",
    "roll_rad",
    "pitch_rad",
    "yaw_rad",
    "roll_rate",
    "pitch_rate",
    "yaw_rate",
];

/// Reads a telemetry CSV file (header naming [`CSV_COLUMNS`] in any order, `#` lines
/// ignored); the rows are sent in file order.
pub fn from_csv(path: &std::path::Path, tick_us: u64) -> Result<Pass, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("cannot read telemetry {}: {e}", path.display()))?;
    let text: String = text
        .lines()
        .filter(|l| !l.trim_start().starts_with('#'))
        .map(|l| format!("{l}\n"))
        .collect();
    let table = Table::parse(&text).map_err(|e| format!("{}: {e}", path.display()))?;
    let cols = table.columns(&CSV_COLUMNS)?;
    let mut samples = Vec::with_capacity(table.rows.len());
    for (i, row) in table.rows.iter().enumerate() {
        let line = i + 2;
        let field = |k: usize| -> Result<f64, String> {
            let text = row
                .get(cols[k])
                .ok_or_else(|| format!("{}: line {line}: too few fields", path.display()))?;
            text.parse::<f64>().map_err(|_| {
                format!(
                    "{}: line {line}: `{text}` is not a number ({})",
                    path.display(),
                    CSV_COLUMNS[k]
                )
            })
        };
        let t_s = field(0)?;
        if !(0.0..1e9).contains(&t_s) {
            return Err(format!(
                "{}: line {line}: time {t_s} s out of range",
                path.display()
            ));
        }
        let v = |k: usize| field(k);
        samples.push(Sample {
            t_us: us(t_s),
            nav: Nav {
                state: StateVector {
                    position_m: [v(1)?, v(2)?, v(3)?],
                    velocity_mps: [v(4)?, v(5)?, v(6)?],
                },
                attitude: Attitude {
                    roll_rad: v(7)? as f32,
                    pitch_rad: v(8)? as f32,
                    yaw_rad: v(9)? as f32,
                    roll_rate_rad_s: v(10)? as f32,
                    pitch_rate_rad_s: v(11)? as f32,
                    yaw_rate_rad_s: v(12)? as f32,
                },
            },
        });
    }
    let end_us = samples
        .iter()
        .map(|s| s.t_us)
        .max()
        .ok_or_else(|| format!("{}: no telemetry rows", path.display()))?;
    Ok(Pass {
        name: format!("telemetry from {}", path.display()),
        samples,
        tick_us,
        end_us,
        truth: Truth::Telemetry,
        faults: Vec::new(),
    })
}

/// Writes the pass's NAV samples as a telemetry CSV file.
pub fn to_csv(pass: &Pass, path: &std::path::Path) -> Result<(), String> {
    let preamble = format!("# {} (see docs/telemetry.md)\n", pass.name);
    let mut out = crate::csv::Writer::new(&preamble, &CSV_COLUMNS)?;
    for s in &pass.samples {
        let (r, v, a) = (
            s.nav.state.position_m,
            s.nav.state.velocity_mps,
            s.nav.attitude,
        );
        let state = [r[0], r[1], r[2], v[0], v[1], v[2]].map(|x| format!("{x:?}"));
        let attitude = [
            a.roll_rad,
            a.pitch_rad,
            a.yaw_rad,
            a.roll_rate_rad_s,
            a.pitch_rate_rad_s,
            a.yaw_rate_rad_s,
        ]
        .map(|x| format!("{x:?}"));
        let t = (s.t_us as f64 * 1e-6).to_string();
        out.row(&[[t].as_slice(), &state, &attitude].concat())?;
    }
    std::fs::write(path, out.into_bytes()?).map_err(|e| format!("writing {}: {e}", path.display()))
}
