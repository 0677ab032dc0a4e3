//! Kepler propagation (`core_math::earth::kepler`): the two-body invariants, a full
//! period, the circular case, and small steps against the Taylor series.

use core_math::earth::kepler::{Kepler, V3};
use core_math::vector::{add, cross, dot};
use core_math::GM_M3_S2;

/// Energy and angular momentum are conserved, a full period returns to the start,
/// and the circular orbit turns at its mean motion.
#[test]
fn two_body_invariants() {
    let r0 = [6_900e3, 1_200e3, -300e3];
    let v0 = [-900.0, 6_200.0, 4_100.0];
    let k = Kepler::new(r0, v0, GM_M3_S2).unwrap();
    let energy = |r: V3, v: V3| 0.5 * dot(v, v) - GM_M3_S2 / dot(r, r).sqrt();
    let (e0, h0) = (energy(r0, v0), cross(r0, v0));
    for dt in [-1000.0, -0.3, 0.1, 37.0, 2500.0] {
        let (dr, v) = k.at(dt);
        let r = add(r0, dr);
        assert!((energy(r, v) / e0 - 1.0).abs() < 1e-13, "dt {dt}");
        let h = cross(r, v);
        for i in 0..3 {
            assert!((h[i] - h0[i]).abs() < 1e-12 * dot(h0, h0).sqrt());
        }
    }
    let period = std::f64::consts::TAU / k.mean_motion_rad_s();
    let (dr, v) = k.at(period);
    assert!(dot(dr, dr).sqrt() < 1e-6 && (v[0] - v0[0]).abs() < 1e-9);
    // Circular: the position turns by n dt about the normal.
    let r = 7_016e3;
    let s = (GM_M3_S2 / r).sqrt();
    let c = Kepler::new([r, 0.0, 0.0], [0.0, s, 0.0], GM_M3_S2).unwrap();
    let (dr, _) = c.at(100.0);
    let th = c.mean_motion_rad_s() * 100.0;
    assert!((r + dr[0] - r * th.cos()).abs() < 1e-8 && (dr[1] - r * th.sin()).abs() < 1e-8);
    assert!(c.eccentricity() < 1e-15);
    assert!(Kepler::new([r, 0.0, 0.0], [0.0, 2.0 * s, 0.0], GM_M3_S2).is_none());
}

/// For small dt the displacement is r0 -> v0 dt + a0 dt^2 / 2 + j0 dt^3 / 6: the
/// Taylor series, to its next term, checks the small-angle forms.
#[test]
fn small_steps_follow_taylor() {
    let r0 = [6_900e3, 1_200e3, -300e3];
    let v0 = [-900.0, 6_200.0, 4_100.0];
    let k = Kepler::new(r0, v0, GM_M3_S2).unwrap();
    let rn = dot(r0, r0).sqrt();
    let acc = r0.map(|x| -GM_M3_S2 * x / rn.powi(3));
    // Jerk: -GM (v / r^3 - 3 (r . v) r / r^5).
    let rv = dot(r0, v0);
    let jerk: V3 =
        std::array::from_fn(|i| -GM_M3_S2 * (v0[i] / rn.powi(3) - 3.0 * rv * r0[i] / rn.powi(5)));
    let dt = 0.01;
    let (dr, _) = k.at(dt);
    for i in 0..3 {
        let t = v0[i] * dt + acc[i] * dt * dt / 2.0 + jerk[i] * dt.powi(3) / 6.0;
        // The jerk term is ~1.5e-9 m; the next, |r| n^4 dt^4 / 24, ~5e-15 m.
        assert!((dr[i] - t).abs() < 5e-14, "{i}: {} vs {t}", dr[i]);
    }
}
