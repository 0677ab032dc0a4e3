//! The real-Earth controller on the target against the f64 reference of the same
//! update, computed on the host at build time (`controller::golden`: Kepler propagation,
//! the attitude at its rates in f64, the dual-number construction). Each case goes in
//! as the flight path takes it: NAV and TERRAIN frames encoded, decoded and accepted by
//! `Controller::on_frame`, then one `advance` to the update instant.
#![no_std]
#![no_main]

use hil_tests as _;

use core::convert::Infallible;

use controller::frame::{encode, kind, Decoder, Event, MAX_FRAME};
use controller::nav::Nav;
use controller::{Controller, Fault, LinePeriodSink, Mode, Terrain};
use hil_tests::controller_cases::{case, ControllerCase, CASE_COUNT};
use hil_tests::golden::{UpdateGolden, CONTROLLER_GOLDEN};

/// Ticks: the reference check of `cargo xtask run` (half a tick of rounding plus 1e-6).
#[cfg(not(feature = "mps2-an385"))]
const TICKS_REL_TOL: f64 = 1e-6;
/// Ticks on the Cortex-M3: the fixed-point pixels add their backend's 2e-6
/// (docs/fixed-point.md, "The error bound"), as the pass's reference check does there.
#[cfg(feature = "mps2-an385")]
const TICKS_REL_TOL: f64 = 3e-6;
/// Drift at each centre and the yaw request (rad): f32's rounding of angles of order
/// 0.1 rad through the general form (the host tests measure below 1e-7).
const ANGLE_TOL_RAD: f64 = 2e-6;

struct Registers {
    writes: u32,
}

impl LinePeriodSink for Registers {
    type Error = Infallible;
    fn write_period(&mut self, _index: u8, _ticks: u32) -> Result<(), Infallible> {
        self.writes += 1;
        Ok(())
    }
}

fn feed(c: &mut Controller, bytes: &[u8]) {
    Decoder::new().feed(bytes, |e| match e {
        Event::Frame(f) => c.on_frame(&f),
        Event::Rejected(r) => c.reject(Fault::from(r)),
    });
}

/// The controller of case `k` after its frames, advanced to its update instant.
fn run(k: usize, cc: &ControllerCase) -> Controller {
    let mut c = match Controller::new(hil_tests::controller_config(), cc.scene) {
        Ok(c) => c,
        Err(f) => defmt::panic!("case {=usize}: scene refused: {=str}", k, f.name()),
    };
    let mut payload = [0u8; 128];
    let mut frame = [0u8; MAX_FRAME];
    let n = Nav {
        state: cc.state,
        attitude: cc.attitude,
    }
    .encode(&mut payload)
    .unwrap_or(0);
    let len = encode(kind::NAV, 1, cc.nav_time_us, &payload[..n], &mut frame).unwrap_or(0);
    feed(&mut c, &frame[..len]);
    if let Some(h) = cc.terrain_m {
        let t = Terrain {
            heights_m: core::array::from_fn(|j| h.get(j).copied().unwrap_or(0.0)),
            count: h.len() as u8,
        };
        let n = t.encode(&mut payload).unwrap_or(0);
        // Tags must increase strictly (docs/telemetry.md); the update instant is then
        // still the case's (the clock's multiple of the update period at or below it).
        let tag = cc.update_time_us.max(cc.nav_time_us + 1);
        let len = encode(kind::TERRAIN, 2, tag, &payload[..n], &mut frame).unwrap_or(0);
        feed(&mut c, &frame[..len]);
    }
    defmt::assert_eq!(
        c.counters.total(),
        0,
        "case {=usize}: a frame was refused",
        k
    );
    let mut regs = Registers { writes: 0 };
    defmt::assert!(c.advance(cc.update_time_us, &mut regs), "no update ran");
    defmt::assert!(c.mode() == Mode::Nominal, "case {=usize}: not nominal", k);
    defmt::assert_eq!(regs.writes as usize, c.plan().active().len());
    c
}

/// Largest errors over the cases: relative ticks, drift (rad), yaw request (rad).
#[derive(Default)]
struct Worst {
    ticks_rel: f64,
    drift_rad: f64,
    yaw_rad: f64,
    segments: u32,
    failures: u32,
}

fn check(k: usize, c: &Controller, g: &UpdateGolden, w: &mut Worst) {
    let plan = c.plan().active();
    defmt::assert_eq!(plan.len(), g.segments.len(), "case {=usize}", k);
    for ((o, gold), seg) in c.outputs().zip(g.segments).zip(plan) {
        w.segments += 1;
        let ticks_err = libm::fabs(f64::from(o.ticks) - gold.ticks_exact);
        let drift_err = libm::fabs(f64::from(o.drift_rad) - gold.drift_rad);
        let ok = o.index == gold.index
            && seg.samples.len() == gold.samples
            && !o.held
            && ticks_err <= TICKS_REL_TOL * gold.ticks_exact + 0.5
            && drift_err <= ANGLE_TOL_RAD;
        if !ok {
            w.failures += 1;
            defmt::error!(
                "{=str} segment {=u8}: {=u32} ticks vs {=f64} exact, drift {=f32} vs {=f64} rad, samples {=usize} vs {=usize}, held {=bool}",
                g.name,
                o.index,
                o.ticks,
                gold.ticks_exact,
                o.drift_rad,
                gold.drift_rad,
                seg.samples.len(),
                gold.samples,
                o.held
            );
        }
        let rel = ticks_err / gold.ticks_exact;
        if rel > w.ticks_rel {
            w.ticks_rel = rel;
        }
        if drift_err > w.drift_rad {
            w.drift_rad = drift_err;
        }
        check_stages(g.name, c, o, w);
    }
    match (c.yaw_request_rad(), g.yaw_request_rad) {
        (Some(got), Some(want)) => {
            let e = libm::fabs(f64::from(got) - want);
            if e > w.yaw_rad {
                w.yaw_rad = e;
            }
            if e > ANGLE_TOL_RAD {
                w.failures += 1;
                defmt::error!("{=str}: yaw request {=f32} vs {=f64}", g.name, got, want);
            }
        }
        (None, None) => {}
        _ => {
            w.failures += 1;
            defmt::error!("{=str}: yaw request present on one side only", g.name);
        }
    }
}

/// The reported stage limit and MTF against the combined rule recomputed here in f64
/// from the segment's own worst mismatch and drift: the limit meets the floor and the
/// next count does not, and the MTF is the product at the configured stages.
fn check_stages(name: &str, c: &Controller, o: &controller::SegmentOutput, w: &mut Worst) {
    let floor = f64::from(c.scene().mtf_floor);
    let sinc = |x: f64| {
        if x == 0.0 {
            1.0
        } else {
            // Each factor the modulus |sin(x)/x|, as the controller reports it.
            libm::fabs(libm::sin(x) / x)
        }
    };
    let product = |m: u32| {
        let h = core::f64::consts::FRAC_PI_2 * f64::from(m);
        sinc(h * f64::from(o.worst_mismatch)) * sinc(h * libm::tan(f64::from(o.worst_drift_rad)))
    };
    let m = u32::from(o.max_stages);
    let limit = u32::from(c.scene().max_stages);
    let stages = c
        .scene()
        .segments
        .get(usize::from(o.index))
        .map_or(0, |s| u32::from(s.tdi_stages));
    let ok = product(m) >= floor - 1e-6
        && (m == limit || product(m + 1) < floor + 1e-6)
        && libm::fabs(product(stages) - f64::from(o.mtf)) < 1e-5;
    if !ok {
        w.failures += 1;
        defmt::error!(
            "{=str} segment {=u8}: stage limit {=u32} or MTF {=f32} off the rule",
            name,
            o.index,
            m,
            o.mtf
        );
    }
}

#[defmt_test::tests]
mod tests {
    use super::*;

    #[test]
    fn updates_match_the_f64_reference() {
        defmt::assert_eq!(CONTROLLER_GOLDEN.len(), CASE_COUNT);
        let mut w = Worst::default();
        for (k, g) in CONTROLLER_GOLDEN.iter().enumerate() {
            let Some(cc) = case(k) else {
                defmt::panic!("case {=usize} missing", k)
            };
            let c = run(k, &cc);
            check(k, &c, g, &mut w);
        }
        defmt::info!(
            "controller vs f64 reference: {=usize} updates, {=u32} segments, {=u32} failed; worst ticks {=f64} relative, drift {=f64} rad, yaw request {=f64} rad",
            CASE_COUNT,
            w.segments,
            w.failures,
            w.ticks_rel,
            w.drift_rad,
            w.yaw_rad
        );
        defmt::assert!(w.segments as usize >= CASE_COUNT * 10 / 2);
        defmt::assert_eq!(w.failures, 0, "see the errors above");
    }
}
