//! The comparisons, one function per test. Each runs its cases on the target, logs
//! every failure (case, quantity, expected, actual) and returns a [`Summary`]; the test
//! asserts that nothing failed.

use core::hint::black_box;

use core_math::sphere::speed_line_period_s;
use core_math::sphere::CLOSED_F32;
use core_math::{line_period_ticks, mtf_mismatch, Backend, ModelError};

use crate::golden::{
    Expected, HostF32, MotionCase, LINE_CLOCK_HZ, MOTION_CASES, MTF_CASES, TICK_CASES,
};
use crate::{rel_err, report_mismatch, within};

/// Outcome of one test's cases.
#[derive(Clone, Copy, Debug, Default)]
pub struct Summary {
    pub cases: u32,
    pub failures: u32,
    /// Largest relative error seen (of v1, |v|, the period; or absolute for the MTF).
    pub max_err: f64,
}

impl Summary {
    /// Logs the summary and fails the test (a panic: nonzero exit) on any failure or
    /// on an empty case list.
    pub fn assert_passed(self, what: &str) {
        defmt::info!(
            "{=str}: {=u32} cases, {=u32} failed, max error {=f64}",
            what,
            self.cases,
            self.failures,
            self.max_err
        );
        defmt::assert!(self.cases > 0, "no cases in {=str}", what);
        defmt::assert_eq!(self.failures, 0, "{=str}: failures (see above)", what);
    }

    fn fail(&mut self) {
        self.failures += 1;
    }

    fn err(&mut self, e: f64) {
        if e > self.max_err {
            self.max_err = e;
        }
    }
}

/// Everything the target computes for one case, as the firmware does.
struct TargetMotion {
    v1: f32,
    v2: f32,
    speed: f32,
    period: Result<f32, ModelError>,
    ticks: Result<u32, ModelError>,
}

fn target_motion(c: &MotionCase) -> Result<TargetMotion, ModelError> {
    let camera = black_box(c.camera);
    let geometry = black_box(c.geometry);
    let n_px = black_box(c.n_px);
    let m = CLOSED_F32.evaluate(&camera, &geometry, n_px)?;
    let speed = m.speed_mps();
    let period = speed_line_period_s(camera.pixel_m as f32, speed);
    let ticks =
        period.and_then(|p| line_period_ticks(p, black_box(LINE_CLOCK_HZ)).map(|t| t.ticks));
    Ok(TargetMotion {
        v1: m.v1_mps,
        v2: m.v2_mps,
        speed,
        period,
        ticks,
    })
}

fn report_error_mismatch(
    case: &str,
    expected: Result<(), ModelError>,
    actual: Result<(), ModelError>,
) {
    let name = |r: Result<(), ModelError>| match r {
        Ok(()) => "a value",
        Err(e) => e.name(),
    };
    defmt::error!(
        "FAIL {=str}: expected {=str}, actual {=str}",
        case,
        name(expected),
        name(actual)
    );
}

/// CLOSED_F32 on the target against the f64 reference, for the cases of `group`.
pub fn motion_vs_reference(group: &str) -> Summary {
    let mut s = Summary::default();
    for c in MOTION_CASES.iter().filter(|c| c.group == group) {
        s.cases += 1;
        let target = target_motion(c);
        match (c.expected, target) {
            (Expected::Motion(e), Ok(t)) => {
                let mut ok = true;
                let checks = [
                    ("v1 (m/s)", e.v1_mps, f64::from(t.v1), e.rel_tol, e.v1_mps),
                    (
                        "|v| (m/s)",
                        e.speed_mps,
                        f64::from(t.speed),
                        e.rel_tol,
                        e.speed_mps,
                    ),
                    (
                        "v2 (m/s)",
                        e.v2_mps,
                        f64::from(t.v2),
                        e.v2_tol_of_speed,
                        e.speed_mps,
                    ),
                ];
                for (what, expected, actual, tol, scale) in checks {
                    if within(actual, expected, tol, scale) {
                        if what != "v2 (m/s)" {
                            s.err(rel_err(actual, expected));
                        }
                    } else {
                        report_mismatch(c.name, what, expected, actual, tol * scale.abs());
                        ok = false;
                    }
                }
                match t.period {
                    Ok(p) if within(f64::from(p), e.period_s, e.period_rel_tol, e.period_s) => {
                        s.err(rel_err(f64::from(p), e.period_s));
                    }
                    Ok(p) => {
                        report_mismatch(
                            c.name,
                            "line period (s)",
                            e.period_s,
                            f64::from(p),
                            e.period_rel_tol * e.period_s,
                        );
                        ok = false;
                    }
                    Err(err) => {
                        report_error_mismatch(c.name, Ok(()), Err(err));
                        ok = false;
                    }
                }
                // The nearest whole tick of the exact period, give or take the tolerance.
                let slack = 0.5 + e.exact_ticks * e.ticks_rel_tol;
                match t.ticks {
                    Ok(n) if within(f64::from(n), e.exact_ticks, 1.0, slack) => {}
                    Ok(n) => {
                        report_mismatch(
                            c.name,
                            "line period (ticks)",
                            e.exact_ticks,
                            f64::from(n),
                            slack,
                        );
                        ok = false;
                    }
                    Err(err) => {
                        report_error_mismatch(c.name, Ok(()), Err(err));
                        ok = false;
                    }
                }
                if ok {
                    defmt::debug!("ok {=str}", c.name);
                } else {
                    s.fail();
                }
            }
            (Expected::Err(e), Err(a)) if e == a => {
                defmt::debug!("ok {=str}: refused with {=str}", c.name, a.name());
            }
            (Expected::Err(e), Err(a)) => {
                report_error_mismatch(c.name, Err(e), Err(a));
                s.fail();
            }
            (Expected::Err(e), Ok(_)) => {
                report_error_mismatch(c.name, Err(e), Ok(()));
                s.fail();
            }
            (Expected::Motion(_), Err(a)) => {
                report_error_mismatch(c.name, Ok(()), Err(a));
                s.fail();
            }
        }
    }
    s
}

fn same_bits(case: &str, what: &str, host: f32, target: f32) -> bool {
    if host.to_bits() == target.to_bits() {
        true
    } else {
        defmt::error!(
            "FAIL {=str}: {=str} host f32 {=f32} ({=u32:#010x}), target {=f32} ({=u32:#010x})",
            case,
            what,
            host,
            host.to_bits(),
            target,
            target.to_bits()
        );
        false
    }
}

/// CLOSED_F32 on the target against CLOSED_F32 on the host: every bit of v1, v2, |v|,
/// the period and the ticks, and the same refusals. Covers every motion case.
pub fn motion_bits_vs_host() -> Summary {
    let mut s = Summary::default();
    for c in MOTION_CASES {
        s.cases += 1;
        let ok = match (c.host_f32, target_motion(c)) {
            (
                HostF32::Motion {
                    v1_mps,
                    v2_mps,
                    speed_mps,
                    period_s,
                    ticks,
                },
                Ok(t),
            ) => {
                let mut ok = same_bits(c.name, "v1", v1_mps, t.v1);
                ok &= same_bits(c.name, "v2", v2_mps, t.v2);
                ok &= same_bits(c.name, "|v|", speed_mps, t.speed);
                ok &= match (period_s, t.period) {
                    (Ok(h), Ok(a)) => same_bits(c.name, "period", h, a),
                    (h, a) => h == a,
                };
                ok &= ticks == t.ticks;
                if ticks != t.ticks {
                    defmt::error!("FAIL {=str}: ticks differ from the host's", c.name);
                }
                ok
            }
            (HostF32::Err(h), Err(a)) if h == a => true,
            (HostF32::Err(h), a) => {
                report_error_mismatch(c.name, Err(h), a.map(|_| ()));
                false
            }
            (HostF32::Motion { .. }, Err(a)) => {
                report_error_mismatch(c.name, Ok(()), Err(a));
                false
            }
        };
        if !ok {
            s.fail();
        }
    }
    s
}

/// mtf_mismatch::<f32> on the target against the f64 function on the host.
pub fn mtf_vs_f64() -> Summary {
    let mut s = Summary::default();
    for c in MTF_CASES {
        s.cases += 1;
        let actual = mtf_mismatch::<f32>(black_box(c.stages), black_box(c.rel_mismatch));
        match (c.expected, actual) {
            (Ok(e), Ok(a)) => {
                let err = f64::from(a) - e;
                let err = if err < 0.0 { -err } else { err };
                if err <= c.abs_tol {
                    s.err(err);
                } else {
                    defmt::error!(
                        "FAIL mtf M={=u32} dv/v={=f32}: expected {=f64}, actual {=f32} (abs err {=f64}, tol {=f64})",
                        c.stages,
                        c.rel_mismatch,
                        e,
                        a,
                        err,
                        c.abs_tol
                    );
                    s.fail();
                }
            }
            (Err(e), Err(a)) if e == a => {}
            (e, a) => {
                report_error_mismatch("mtf", e.map(|_| ()), a.map(|_| ()));
                s.fail();
            }
        }
    }
    s
}

/// mtf_mismatch::<f32> on the target against the same on the host, bit for bit.
pub fn mtf_bits_vs_host() -> Summary {
    let mut s = Summary::default();
    for c in MTF_CASES {
        s.cases += 1;
        let actual = mtf_mismatch::<f32>(black_box(c.stages), black_box(c.rel_mismatch));
        let ok = match (c.host_f32, actual) {
            (Ok(h), Ok(a)) => same_bits("mtf", "MTF", h, a),
            (h, a) => h == a,
        };
        if !ok {
            s.fail();
        }
    }
    s
}

/// line_period_ticks::<f32> on the target against the exact f64 tick count.
pub fn ticks_vs_f64() -> Summary {
    let mut s = Summary::default();
    for c in TICK_CASES {
        s.cases += 1;
        let actual = line_period_ticks::<f32>(black_box(c.period_s), black_box(c.clock_hz));
        match (c.exact_ticks, actual) {
            (Ok(exact), Ok(t)) => {
                let slack = 0.5 + exact * c.rel_tol;
                if within(f64::from(t.ticks), exact, 1.0, slack) {
                    // Recorded in ticks: the distance to the exact, unrounded count.
                    let d = f64::from(t.ticks) - exact;
                    s.err(if d < 0.0 { -d } else { d });
                } else {
                    defmt::error!(
                        "FAIL ticks of {=f32} s at {=f32} Hz: expected {=f64} +- {=f64}, actual {=u32}",
                        c.period_s,
                        c.clock_hz,
                        exact,
                        slack,
                        t.ticks
                    );
                    s.fail();
                }
            }
            (Err(e), Err(a)) if e == a => {}
            (e, a) => {
                report_error_mismatch("ticks", e.map(|_| ()), a.map(|_| ()));
                s.fail();
            }
        }
    }
    s
}

/// line_period_ticks::<f32> on the target against the host's f32 result, bit for bit.
pub fn ticks_bits_vs_host() -> Summary {
    let mut s = Summary::default();
    for c in TICK_CASES {
        s.cases += 1;
        let actual = line_period_ticks::<f32>(black_box(c.period_s), black_box(c.clock_hz))
            .map(|t| (t.ticks, t.rounding_error_s.to_bits()));
        let host = c.host_f32.map(|(n, e)| (n, e.to_bits()));
        if actual != host {
            defmt::error!(
                "FAIL ticks of {=f32} s at {=f32} Hz differ from the host's",
                c.period_s,
                c.clock_hz
            );
            s.fail();
        }
    }
    s
}
