//! The default update period against the budget it must meet: between two updates the
//! programmed period is held while the image speed drifts, and that drift may use at
//! most a tenth of each segment's mismatch budget (the same share as the sampling).
//!
//! `cargo test -p controller --release --test update_rate -- --nocapture` prints the figure.

mod common;

use common::R;
use controller::plan::{Plan, SAMPLING_SHARE};
use controller::{Config, Scene};
use core_math::{Backend, Geometry, Reference};

/// Fastest roll manoeuvre the default is sized for (rad/s): 1 deg/s.
const ROLL_RATE_RAD_S: f64 = 0.017_453_292_519_943_295;

#[test]
fn default_update_period_meets_a_tenth_of_the_mtf_budget() {
    let config = Config::default();
    let scene = Scene::paper_default();
    let plan = Plan::new(&scene, &config.envelope()).unwrap();
    let (h_lo, h_hi) = config.altitude_range_m;
    let max_roll = f64::from(scene.max_roll_rad);
    // Largest |d ln v / dt| at any sample point, from the reference by central
    // differences in time (orbit position and roll both move).
    let dt = 1e-3;
    let mut worst_rate = 0.0f64;
    let mut worst_at = (0.0, 0.0, 0);
    for k in 0..=10 {
        let roll = -max_roll + 2.0 * max_roll * f64::from(k) / 10.0;
        for h in [h_lo, h_hi] {
            for g0_deg in (0..360).step_by(30) {
                let v_at = |t: f64, n: i32| {
                    let mut g = Geometry::circular(
                        roll + ROLL_RATE_RAD_S * t,
                        97.98f64.to_radians(),
                        f64::from(g0_deg).to_radians(),
                        h,
                        R,
                    );
                    g.arg_latitude_rad += g.orbit_rate_rad_s * t;
                    Reference
                        .evaluate(&scene.camera, &g, f64::from(n))
                        .ok()
                        .map(|m| m.speed_mps())
                };
                for seg in plan.active() {
                    for &n in seg.sample_px() {
                        if let (Some(a), Some(b), Some(c)) =
                            (v_at(-dt, n), v_at(0.0, n), v_at(dt, n))
                        {
                            let rate = ((c - a) / (2.0 * dt) / b).abs();
                            if rate > worst_rate {
                                worst_rate = rate;
                                worst_at = (roll.to_degrees(), h, n);
                            }
                        }
                    }
                }
            }
        }
    }
    let stages = plan.active().iter().map(|s| s.tdi_stages).max().unwrap();
    let budget = SAMPLING_SHARE * f64::from(plan.stage_rule.mismatch_budget()) / f64::from(stages);
    let max_period_s = budget / worst_rate;
    let default_s = config.update_period_us as f64 * 1e-6;
    eprintln!(
        "update rate: worst |d ln v/dt| = {worst_rate:.3e} /s (roll {:.1} deg, H {:.0} km, n {}) at 1 deg/s roll; \
         budget {budget:.3e} ({stages} stages, floor {}); longest update period {:.1} ms; default {:.1} ms",
        worst_at.0, worst_at.1 / 1e3, worst_at.2, scene.mtf_floor, max_period_s * 1e3, default_s * 1e3
    );
    assert!(
        default_s <= max_period_s,
        "the default update period is too long"
    );
}
