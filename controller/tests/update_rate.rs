//! The default update period against the budget it must meet: between two updates the
//! programmed period is held while the image speed moves, and that change may use at
//! most a tenth of each segment's mismatch budget (the same share as the sampling).
//!
//! The image speed moves with the orbit and, far faster, with the attitude: at the
//! scene's largest rate on roll and pitch together, over the whole envelope of angles,
//! every active segment's samples, the band's lowest and highest orbits, at the equator
//! and near the pole. |d ln |v1| / dt| by central differences in time of the f64
//! reference (the state carried by Kepler's equation, the angles at their rates).
//!
//! `cargo test -p controller --release --test update_rate -- --nocapture` prints the figure.

use controller::plan::{Plan, SAMPLING_SHARE};
use controller::{Config, Scene, EARTH};
use core_math::earth::kepler::Kepler;
use core_math::earth::{circular_state, Attitude, EarthGeometry};
use core_math::{Backend, EarthReference, EARTH_RATE_RAD_S, GM_M3_S2};

#[test]
fn default_update_period_meets_a_tenth_of_the_mtf_budget() {
    let config = Config::default();
    let scene = Scene::paper_default();
    let plan = Plan::new(&scene, &config).unwrap();
    let (h_lo, h_hi) = config.altitude_range_m;
    let e = scene.envelope;
    let rate = f64::from(e.max_rate_rad_s);
    let dt = 1e-3;
    let mut worst_rate = 0.0f64;
    let mut worst_at = String::new();
    for k in 0..=4 {
        let roll = f64::from(e.max_roll_rad) * (-1.0 + 0.5 * f64::from(k));
        for j in 0..=4 {
            let pitch = f64::from(e.max_pitch_rad) * (-1.0 + 0.5 * f64::from(j));
            for (h, u, radius) in [
                (h_lo, 0.0, EARTH.a_m),
                (h_hi, 0.0, EARTH.a_m),
                (h_lo, 1.5, EARTH.b_m()),
            ] {
                let s0 = circular_state(radius + h, 98f64.to_radians(), u);
                let kepler = Kepler::new(s0.position_m, s0.velocity_mps, GM_M3_S2).unwrap();
                for (roll_rate, pitch_rate) in
                    [(rate, rate), (rate, -rate), (-rate, rate), (-rate, -rate)]
                {
                    let at = |t: f64| EarthGeometry {
                        state: kepler.state_at(t),
                        attitude: Attitude {
                            roll_rad: roll + roll_rate * t,
                            pitch_rad: pitch + pitch_rate * t,
                            yaw_rad: 0.0,
                            roll_rate_rad_s: roll_rate,
                            pitch_rate_rad_s: pitch_rate,
                            yaw_rate_rad_s: 0.0,
                        },
                        ground_h_m: 0.0,
                        ellipsoid: EARTH,
                        earth_rate_rad_s: EARTH_RATE_RAD_S,
                    };
                    for seg in plan.active() {
                        let camera = scene.earth_camera(&scene.segments[usize::from(seg.index)]);
                        for n in seg.samples.iter().map(|s| s.px) {
                            let v = |t: f64| {
                                EarthReference
                                    .evaluate(&camera, &at(t), f64::from(n))
                                    .ok()
                                    .map(|m| m.v1_mps.abs())
                            };
                            if let (Some(a), Some(b), Some(c)) = (v(-dt), v(0.0), v(dt)) {
                                let r = ((c - a) / (2.0 * dt) / b).abs();
                                if r > worst_rate {
                                    worst_rate = r;
                                    worst_at = format!(
                                        "roll {:.1} deg, pitch {:.1} deg, rates {:+.1}/{:+.1} deg/s, H {:.0} km, pixel {n}, |v1| {b:.2e} m/s",
                                        roll.to_degrees(), pitch.to_degrees(), roll_rate.to_degrees(), pitch_rate.to_degrees(), h / 1e3
                                    );
                                }
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
        "update rate: worst |d ln |v1|/dt| = {worst_rate:.3e} /s at {worst_at}; \
         budget {budget:.3e} ({stages} stages, floor {}); longest update period {:.1} ms; default {:.1} ms",
        scene.mtf_floor,
        max_period_s * 1e3,
        default_s * 1e3
    );
    assert!(
        default_s <= max_period_s,
        "the default update period is too long"
    );
}
