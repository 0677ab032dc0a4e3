//! The planner's sampling bound, proved against dense evaluations of the f64 reference:
//! every worst mismatch the controller reports bounds the true worst mismatch over
//! every pixel of its segment (issue 12, "honest sampling").
//!
//! `cargo test --release -p controller --test plan -- --nocapture` prints the figures.

mod common;

use common::{nav_frame, state, Accept};
use controller::frame::{Decoder, Event};
use controller::nav::Attitude;
use controller::plan::Plan;
use controller::scene::{Scene, SegmentSpec, MAX_SEGMENTS};
use controller::{Config, Controller, Fault, EARTH};
use core_math::earth::EarthGeometry;
use core_math::sample::SplitMix64;
use core_math::{Backend, EarthReference, EARTH_RATE_RAD_S};

/// Pixels evaluated per segment by the dense reference (at least 1 000, the ends
/// included).
const DENSE: i32 = 1_000;
/// What the f32 form may differ from the reference by (relative) on a v1 of the
/// envelope's conditioning (core_math::accuracy, EARTH_F32_REL_TOLERANCE): the report is
/// allowed to fall short of the truth by that, and no more.
const F32_SLACK: f64 = 2e-6;

#[test]
fn the_default_scene_plan() {
    let scene = Scene::paper_default();
    let plan = Plan::new(&scene, &Config::default()).unwrap();
    assert_eq!(plan.active().len(), 10);
    for s in plan.active() {
        eprintln!(
            "segment {}: {} pixels (the centre and the samples), interpolation {:.2e} m/s, bound {:.2e} at the slowest image, budget {:.2e}",
            s.index, s.samples.len(), s.interpolation_mps, s.sampling_bound, s.sampling_budget
        );
        assert!(s.samples.len() >= 2);
        assert!(
            s.sampling_bound <= s.sampling_budget,
            "segment {}: {} > {}",
            s.index,
            s.sampling_bound,
            s.sampling_budget
        );
        let spec = scene.segments[usize::from(s.index)];
        // The centre first, then the samples from the first pixel to the last, equally
        // spaced, an odd count's middle one being the centre.
        assert_eq!(f64::from(s.samples[0].px), spec.centre_px());
        assert_eq!(s.samples[1].px, spec.first_px as f32);
        assert_eq!(s.samples.last().unwrap().px, spec.last_px as f32);
        // Equally spaced from the first pixel to the last: the samples alone (an even
        // count), or with the centre in the middle (an odd one).
        let spaced = |xs: &[f64]| {
            let h = (xs[xs.len() - 1] - xs[0]) / (xs.len() - 1) as f64;
            xs.iter()
                .enumerate()
                .all(|(j, x)| (x - (xs[0] + h * j as f64)).abs() < 4e-3)
        };
        let rest: Vec<f64> = s.samples[1..].iter().map(|p| f64::from(p.px)).collect();
        let mut all = rest.clone();
        all.push(spec.centre_px());
        all.sort_by(f64::total_cmp);
        assert!(
            (rest.len().is_multiple_of(2) && spaced(&rest))
                || (!all.len().is_multiple_of(2) && spaced(&all)),
            "segment {}: {:?}",
            s.index,
            s.samples
        );
        assert!(s.samples[1..].windows(2).all(|w| w[0].px < w[1].px));
    }
}

/// A scene of `kind`: the paper's (16 stages), the same at 96 stages (a budget six times
/// smaller: more samples), a staggered mosaic of 16 narrow chips at 64 stages over
/// mountains.
fn scene(kind: usize) -> Scene {
    let mut s = Scene::paper_default();
    match kind {
        0 => {}
        1 => s
            .segments
            .iter_mut()
            .take(10)
            .for_each(|g| g.tdi_stages = 96),
        _ => {
            s.count = MAX_SEGMENTS as u8;
            for (k, g) in s.segments.iter_mut().enumerate() {
                let first = -30_000 + 3_750 * k as i32;
                *g = SegmentSpec {
                    first_px: first,
                    last_px: first + 3_749,
                    tdi_stages: 64,
                    active: k % 5 != 3,
                    p1_m: if k % 2 == 0 { 4e-3 } else { -4e-3 },
                    ground_h_m: 300.0 * k as f32,
                };
            }
        }
    }
    s
}

struct Worst {
    compared: usize,
    /// Smallest margin reported - true (relative), and the largest ratio true/reported.
    margin: f64,
    ratio: f64,
    samples: usize,
}

#[test]
fn the_reported_worst_mismatch_bounds_the_truth_over_every_pixel() {
    let mut rng = SplitMix64(0x5A3F_2026_1124_0012);
    let config = Config::default();
    let mut w = Worst {
        compared: 0,
        margin: f64::INFINITY,
        ratio: 0.0,
        samples: 0,
    };
    for draw in 0..60 {
        let scene = scene(draw % 3);
        let mut c = Controller::new(config, scene).unwrap();
        // An orbit in the band (e up to ~0.02), an attitude anywhere in the envelope at
        // rates up to a third of its limit, yaw steered within 0.1 rad.
        let h = rng.uniform(510e3, 790e3);
        let mut sv = state(
            rng.uniform(0.0, 3.1),
            rng.uniform(0.0, std::f64::consts::TAU),
            h,
        );
        let speed = rng.uniform(0.99, 1.01);
        sv.velocity_mps = sv.velocity_mps.map(|v| v * speed);
        let e = scene.envelope;
        let rate = f64::from(e.max_rate_rad_s) / 3.0;
        let att = Attitude {
            roll_rad: rng.uniform(-0.9, 0.9) * f64::from(e.max_roll_rad),
            pitch_rad: rng.uniform(-0.9, 0.9) * f64::from(e.max_pitch_rad),
            yaw_rad: rng.uniform(-0.1, 0.1),
            roll_rate_rad_s: rng.uniform(-rate, rate),
            pitch_rate_rad_s: rng.uniform(-rate, rate),
            yaw_rate_rad_s: rng.uniform(-rate, rate),
        }
        .to::<f32>();
        let mut d = Decoder::new();
        d.feed(&nav_frame(1, 1_000_000, sv, att), |ev| match ev {
            Event::Frame(f) => c.on_frame(&f),
            Event::Rejected(r) => c.reject(Fault::from(r)),
        });
        assert_eq!(c.counters.total(), 0, "draw {draw}: {:?}", c.last_fault);
        c.advance(1_000_000, &mut Accept);
        let g = EarthGeometry {
            state: sv,
            attitude: att.to_f64(),
            ground_h_m: 0.0,
            ellipsoid: EARTH,
            earth_rate_rad_s: EARTH_RATE_RAD_S,
        };
        for o in c.outputs().filter(|o| !o.held) {
            let spec = scene.segments[usize::from(o.index)];
            let camera = scene.earth_camera(&spec);
            let g = EarthGeometry {
                ground_h_m: f64::from(spec.ground_h_m),
                ..g
            };
            let v_line = scene.camera.pixel_m * scene.line_clock_hz / f64::from(o.ticks);
            let width = spec.last_px - spec.first_px;
            let mut truth = 0.0f64;
            for j in 0..=DENSE {
                let n = spec.first_px + (i64::from(width) * i64::from(j) / i64::from(DENSE)) as i32;
                let m = EarthReference.evaluate(&camera, &g, f64::from(n)).unwrap();
                truth = truth.max((v_line / m.v1_mps.abs() - 1.0).abs());
            }
            let reported = f64::from(o.worst_mismatch);
            assert!(
                reported >= truth * (1.0 - F32_SLACK) - F32_SLACK,
                "draw {draw}, segment {}: reported {reported:e} < true {truth:e}",
                o.index
            );
            w.compared += 1;
            w.margin = w.margin.min(reported - truth);
            w.ratio = w.ratio.max(truth / reported);
        }
        w.samples += c
            .plan()
            .active()
            .iter()
            .map(|s| s.samples.len())
            .sum::<usize>();
    }
    assert!(w.compared >= 500, "only {} segments compared", w.compared);
    eprintln!(
        "honest sampling: {} segment updates against {} reference pixels each; smallest reported - true {:.2e}, largest true/reported {:.3} ({} samples per update on average)",
        w.compared,
        DENSE + 1,
        w.margin,
        w.ratio,
        w.samples / 60
    );
}
