//! State vector to orbit quantities, against states built from known elements by
//! rotation matrices (an independent route), including the degenerate orbits.

use core_math::sphere::OrbitState;
use core_math::{ModelError, StateVector};
use proptest::prelude::*;
use std::f64::consts::PI;

const R: f64 = 6_371e3;
const GM: f64 = core_math::GM_M3_S2;

fn rot_z(a: f64, v: [f64; 3]) -> [f64; 3] {
    let (s, c) = (libm::sin(a), libm::cos(a));
    [c * v[0] - s * v[1], s * v[0] + c * v[1], v[2]]
}

fn rot_x(a: f64, v: [f64; 3]) -> [f64; 3] {
    let (s, c) = (libm::sin(a), libm::cos(a));
    [v[0], c * v[1] - s * v[2], s * v[1] + c * v[2]]
}

/// ECI state on a circular orbit: node longitude `raan`, inclination `i`, argument of
/// latitude `u`, altitude `h`; `radial_mps` added along r.
fn state(raan: f64, i: f64, u: f64, h: f64, radial_mps: f64) -> StateVector {
    let a = R + h;
    let speed = libm::sqrt(GM / a);
    let to_eci = |p: [f64; 3]| rot_z(raan, rot_x(i, rot_z(u, p)));
    let r = to_eci([a, 0.0, 0.0]);
    let v = to_eci([radial_mps, speed, 0.0]);
    StateVector {
        position_m: r,
        velocity_mps: v,
    }
}

fn wrap(a: f64) -> f64 {
    let t = a.rem_euclid(std::f64::consts::TAU);
    if t > std::f64::consts::PI {
        t - std::f64::consts::TAU
    } else {
        t
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 4000, ..ProptestConfig::default() })]

    #[test]
    fn recovers_the_elements(raan in 0f64..6.3, i in 0.001f64..(PI - 0.001), u in -PI..PI, h in 200e3f64..2000e3) {
        let o = OrbitState::from_state(&state(raan, i, u, h, 0.0), R).unwrap();
        prop_assert!((o.altitude_m - h).abs() < 1e-6, "{}", o.altitude_m);
        prop_assert!((o.inclination_rad - i).abs() < 1e-12);
        prop_assert!(wrap(o.arg_latitude_rad - u).abs() < 1e-9 / libm::sin(i).max(1e-3));
        let mean_motion = libm::sqrt(GM / ((R + h) * (R + h) * (R + h)));
        prop_assert!((o.orbit_rate_rad_s - mean_motion).abs() < 1e-12 * mean_motion);
        prop_assert!(o.radial_rate_per_s.abs() < 1e-15);
    }

    /// What the model actually uses: the Earth's spin axis in the orbital frame
    /// (forward, normal, up) = (sin i cos u, cos i, sin i sin u), checked against the
    /// axis projected on the frame built from r and v directly.
    #[test]
    fn spin_axis_in_the_orbital_frame(raan in 0f64..6.3, i in 0f64..=PI, u in -PI..PI, h in 200e3f64..2000e3) {
        let sv = state(raan, i, u, h, 0.0);
        let o = OrbitState::from_state(&sv, R).unwrap();
        let (r, v) = (sv.position_m, sv.velocity_mps);
        let norm = |a: [f64; 3]| libm::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        let hv = [r[1] * v[2] - r[2] * v[1], r[2] * v[0] - r[0] * v[2], r[0] * v[1] - r[1] * v[0]];
        let up_z = r[2] / norm(r);
        let normal_z = hv[2] / norm(hv);
        // forward = normal x up; its z component:
        let (nx, ny) = (hv[0] / norm(hv), hv[1] / norm(hv));
        let (ux, uy) = (r[0] / norm(r), r[1] / norm(r));
        let forward_z = nx * uy - ny * ux;
        let (si, ci) = (libm::sin(o.inclination_rad), libm::cos(o.inclination_rad));
        let (su, cu) = (libm::sin(o.arg_latitude_rad), libm::cos(o.arg_latitude_rad));
        prop_assert!((si * cu - forward_z).abs() < 1e-12);
        prop_assert!((ci - normal_z).abs() < 1e-12);
        prop_assert!((si * su - up_z).abs() < 1e-12);
    }
}

#[test]
fn equatorial_and_polar_orbits() {
    // Prograde and retrograde equatorial: no node, gamma0 = 0, no NaN.
    for (i, expect) in [(0.0, 0.0), (std::f64::consts::PI, std::f64::consts::PI)] {
        let o = OrbitState::from_state(&state(0.7, i, 1.1, 645e3, 0.0), R).unwrap();
        assert!(
            (o.inclination_rad - expect).abs() < 1e-12,
            "{}",
            o.inclination_rad
        );
        assert!(o.arg_latitude_rad.is_finite());
    }
    // Exactly equatorial state (z components exactly 0): atan2(0, 0) = 0.
    let sv = StateVector {
        position_m: [R + 645e3, 0.0, 0.0],
        velocity_mps: [0.0, 7_500.0, 0.0],
    };
    let o = OrbitState::from_state(&sv, R).unwrap();
    assert_eq!(o.inclination_rad, 0.0);
    assert_eq!(o.arg_latitude_rad, 0.0);
    // Polar, over the pole.
    let o = OrbitState::from_state(
        &state(
            0.3,
            std::f64::consts::FRAC_PI_2,
            std::f64::consts::FRAC_PI_2,
            645e3,
            0.0,
        ),
        R,
    )
    .unwrap();
    assert!((o.inclination_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    assert!((o.arg_latitude_rad - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
}

#[test]
fn radial_rate_is_reported() {
    let o = OrbitState::from_state(&state(0.1, 1.7, 0.4, 645e3, 10.0), R).unwrap();
    assert!((o.radial_rate_per_s - 10.0 / (R + 645e3)).abs() < 1e-15);
}

#[test]
fn bad_states_are_refused() {
    let good = state(0.1, 1.7, 0.4, 645e3, 0.0);
    let mut s = good;
    s.position_m[1] = f64::NAN;
    assert!(matches!(
        OrbitState::from_state(&s, R),
        Err(ModelError::NonFinite(_))
    ));
    let mut s = good;
    s.velocity_mps[0] = f64::INFINITY;
    assert!(matches!(
        OrbitState::from_state(&s, R),
        Err(ModelError::NonFinite(_))
    ));
    // Inside the Earth.
    let s = StateVector {
        position_m: [R * 0.5, 0.0, 0.0],
        velocity_mps: [0.0, 7e3, 0.0],
    };
    assert_eq!(
        OrbitState::from_state(&s, R),
        Err(ModelError::NonPositiveAltitude)
    );
    // Purely radial motion: no orbital plane.
    let s = StateVector {
        position_m: [R + 645e3, 0.0, 0.0],
        velocity_mps: [100.0, 0.0, 0.0],
    };
    assert!(matches!(
        OrbitState::from_state(&s, R),
        Err(ModelError::OutOfDomain(_))
    ));
    let s = StateVector {
        position_m: [1e300, 0.0, 0.0],
        velocity_mps: [0.0, 1e300, 0.0],
    };
    assert!(matches!(
        OrbitState::from_state(&s, R),
        Err(ModelError::OutOfDomain(_))
    ));
}
