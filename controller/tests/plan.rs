//! The planner's sampling bound, proved against dense evaluations of the f64 reference.

mod common;

use common::R;
use controller::plan::{Envelope, Plan, SegmentPlan};
use controller::scene::{Scene, SegmentSpec, MAX_SEGMENTS};
use core_math::{Backend, Camera, Geometry, Reference};
use proptest::prelude::*;

const ENV: Envelope = Envelope {
    earth_radius_m: R,
    altitude_range_m: (500e3, 800e3),
};

/// Relative errors of the extremes of |v| estimated from the plan's samples, against
/// the extremes over every 10th pixel of the segment, all from the reference.
fn sampling_error(scene: &Scene, seg: &SegmentPlan, g: &Geometry<f64>) -> Option<f64> {
    let spec = scene.segments[usize::from(seg.index)];
    let v = |n: i32| {
        Reference
            .evaluate(&scene.camera, g, f64::from(n))
            .ok()
            .map(|m| m.speed_mps())
    };
    let mut dense = Vec::new();
    let mut n = spec.first_px;
    while n <= spec.last_px {
        dense.push(v(n)?);
        n += 10;
    }
    dense.push(v(spec.last_px)?);
    let sampled: Option<Vec<f64>> = seg.sample_px().iter().map(|&n| v(n)).collect();
    let sampled = sampled?;
    let max = |x: &[f64]| x.iter().cloned().fold(0.0, f64::max);
    let min = |x: &[f64]| x.iter().cloned().fold(f64::INFINITY, f64::min);
    Some((max(&dense) / max(&sampled) - 1.0).max(min(&sampled) / min(&dense) - 1.0))
}

#[test]
fn the_default_scene_plan() {
    let scene = Scene::paper_default();
    let plan = Plan::new(&scene, &ENV).unwrap();
    assert_eq!(plan.count, 10);
    for s in plan.active() {
        eprintln!(
            "segment {}: {} samples, bound {:.2e}, budget {:.2e}",
            s.index, s.n_samples, s.sampling_bound, s.sampling_budget
        );
        assert!(s.n_samples >= 2);
        assert!(
            s.sampling_bound <= s.sampling_budget,
            "segment {}: {} > {}",
            s.index,
            s.sampling_bound,
            s.sampling_budget
        );
        assert_eq!(
            s.sample_px()[0],
            scene.segments[usize::from(s.index)].first_px
        );
        assert_eq!(
            *s.sample_px().last().unwrap(),
            scene.segments[usize::from(s.index)].last_px
        );
    }
}

fn scene_strategy() -> impl Strategy<Value = Scene> {
    (
        0.3f64..1.5,
        7e-6f64..2e-5,
        1usize..=MAX_SEGMENTS,
        500i32..12_000,
        0f32..0.5,
        1u16..=96,
    )
        .prop_filter_map(
            "field beyond 40 deg",
            |(f, a, count, width, roll, stages)| {
                let total = width as i64 * count as i64;
                let first = -(total / 2) as i32;
                if (total as f64 / 2.0 * a / f).atan() > 40f64.to_radians() {
                    return None;
                }
                let mut s = Scene::paper_default();
                s.camera = Camera {
                    focal_m: f,
                    pixel_m: a,
                };
                s.count = count as u8;
                s.max_roll_rad = roll;
                for (k, seg) in s.segments.iter_mut().enumerate() {
                    *seg = if k < count {
                        let lo = first + width * k as i32;
                        SegmentSpec {
                            first_px: lo,
                            last_px: lo + width - 1,
                            tdi_stages: stages,
                            active: true,
                        }
                    } else {
                        SegmentSpec::default()
                    };
                }
                Some(s)
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    /// For any scene and any geometry the plan was built for, the sampled extremes are
    /// within the segment's sampling budget of the true ones (where the bound is claimed).
    #[test]
    fn sampling_bound_holds_against_the_reference(
        scene in scene_strategy(), frac in -1f64..1.0, h in 500e3f64..800e3, i0 in 0f64..180.0, g0 in 0f64..360.0,
    ) {
        let plan = Plan::new(&scene, &ENV).unwrap();
        let g = Geometry::circular(f64::from(scene.max_roll_rad) * frac, i0.to_radians(), g0.to_radians(), h, R);
        for seg in plan.active() {
            if seg.sampling_bound > seg.sampling_budget {
                continue;
            }
            if let Some(e) = sampling_error(&scene, seg, &g) {
                prop_assert!(e <= f64::from(seg.sampling_budget), "segment {} ({} samples): error {e:e} > budget {:e}", seg.index, seg.n_samples, seg.sampling_budget);
            }
        }
    }
}

/// The scene kinds of the issue, and what each plan leaves out.
#[test]
fn terms_left_out_per_scene_kind() {
    let all = Scene::paper_default();
    let p = Plan::new(&all, &ENV).unwrap();
    // Roll up to 25 deg: the far point comes within 2.6 deg of the 800 km limb.
    assert!(
        p.terms.limb && p.terms.drift,
        "{:?} margin {} drift {}",
        p.terms,
        p.limb_margin_rad,
        p.drift_bound
    );
    let mut nadir = all;
    nadir.max_roll_rad = 0.0;
    let p = Plan::new(&nadir, &ENV).unwrap();
    assert!(
        !p.terms.limb,
        "nadir only: at least {} rad from the limb",
        p.limb_margin_rad
    );
    let mut few_stages = all;
    for s in few_stages.segments.iter_mut() {
        s.tdi_stages = 2;
    }
    let p = Plan::new(&few_stages, &ENV).unwrap();
    assert!(
        !p.terms.drift,
        "2 stages: drift bound {} is within the budget",
        p.drift_bound
    );
    let mut one = all;
    for (k, s) in one.segments.iter_mut().enumerate() {
        s.active = k == 4;
    }
    let p = Plan::new(&one, &ENV).unwrap();
    assert_eq!(p.count, 1);
    let e = Plan::exhaustive(&one, &ENV).unwrap();
    assert_eq!(e.count, 10, "the baseline evaluates every segment");
    assert!(e
        .active()
        .iter()
        .all(|s| usize::from(s.n_samples) == controller::plan::MAX_SAMPLES));
    assert_eq!(e.terms, controller::plan::Terms::ALL);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

    /// The bounds behind leaving terms out hold against the reference: every sample's
    /// line of sight is at least `limb_margin_rad` from the limb, and (|v| - |v1|) / |v|
    /// is at most `drift_bound`, anywhere in the envelope.
    #[test]
    fn term_bounds_hold_against_the_reference(
        scene in scene_strategy(), frac in -1f64..1.0, h in 500e3f64..800e3, i0 in 0f64..180.0, g0 in 0f64..360.0,
    ) {
        let plan = Plan::new(&scene, &ENV).unwrap();
        let g = Geometry::circular(f64::from(scene.max_roll_rad) * frac, i0.to_radians(), g0.to_radians(), h, R);
        let limb = libm::asin(R / (R + h));
        for seg in plan.active() {
            for &n in seg.sample_px() {
                let alpha = libm::atan(f64::from(n) * scene.camera.pixel_m / scene.camera.focal_m);
                prop_assert!(limb - (g.roll_rad + alpha).abs() >= f64::from(plan.limb_margin_rad) - 1e-9);
                if let Ok(m) = Reference.evaluate(&scene.camera, &g, f64::from(n)) {
                    let change = (m.speed_mps() - m.v1_mps.abs()) / m.speed_mps();
                    prop_assert!(change <= f64::from(plan.drift_bound), "{change:e} > {:e}", plan.drift_bound);
                }
            }
        }
    }
}
