//! The yaw steering request when no segment contains pixel 0 (issue 25, item 4): the
//! request is still formed at the boresight, over the ground of the table entry nearest
//! to pixel 0 (by pixel distance; on a tie the one at negative pixels, the lower
//! index), and flagged valid. Checked against the f64 reference at the boresight over
//! the ground the rule picks, with the neighbours' heights far enough apart that the
//! other one's ground would miss the tolerance.

mod common;

use common::{feed, nav_frame, state, Accept, H, I0};
use controller::frame::MAX_FRAME;
use controller::nav::Attitude;
use controller::report::{encode_periods, Periods};
use controller::{Config, Controller, Scene, EARTH};
use core_math::earth::{EarthCamera, EarthGeometry};
use core_math::{Backend, EarthReference};

fn attitude() -> Attitude<f32> {
    Attitude {
        roll_rad: 8f32.to_radians(),
        pitch_rad: -5f32.to_radians(),
        yaw_rad: 1f32.to_radians(),
        ..Attitude::default()
    }
}

/// atan(v2/v1) at the boresight over ground at `h_m`, in f64 (the NAV instant: no
/// propagation).
fn reference_request(scene: &Scene, h_m: f64) -> f64 {
    let camera = EarthCamera {
        focal_m: scene.camera.focal_m,
        pixel_m: scene.camera.pixel_m,
        p1_m: 0.0,
    };
    let g = EarthGeometry {
        state: state(I0.to_radians(), 0.7, H),
        attitude: attitude().to_f64(),
        ground_h_m: h_m,
        ellipsoid: EARTH,
        earth_rate_rad_s: core_math::EARTH_RATE_RAD_S,
    };
    let m = EarthReference.evaluate(&camera, &g, 0.0).unwrap();
    libm::atan(m.v2_mps / m.v1_mps)
}

/// The paper's camera with segments 4 and 5 ending `gap_neg` pixels before and starting
/// `gap_pos` pixels after pixel 0, over ground at 0 m and 9 000 m.
fn gapped_scene(gap_neg: i32, gap_pos: i32, neg_active: bool) -> Scene {
    let mut scene = Scene::paper_default();
    scene.segments[4].last_px = -gap_neg;
    scene.segments[5].first_px = gap_pos;
    scene.segments[4].active = neg_active;
    scene.segments[4].ground_h_m = 0.0;
    scene.segments[5].ground_h_m = 9_000.0;
    scene
}

fn request(scene: Scene) -> (f32, Periods) {
    let mut c = Controller::new(Config::default(), scene).unwrap();
    feed(
        &mut c,
        &nav_frame(1, 1_000_000, state(I0.to_radians(), 0.7, H), attitude()),
    );
    assert!(c.advance(1_000_000, &mut Accept));
    let mut buf = [0u8; MAX_FRAME];
    let n = encode_periods(&c, &mut buf).unwrap();
    let p = Periods::decode(&buf[..n]).unwrap();
    (c.yaw_request_rad().expect("no yaw request"), p)
}

#[test]
fn with_no_segment_on_pixel_0_the_request_uses_the_nearest_ground() {
    // (gap below 0, gap above 0, segment 4 active, the height the rule picks)
    let cases = [
        (1, 500, true, 0.0),       // segment 4 ends at -1: nearest
        (600, 200, true, 9_000.0), // segment 5 starts at 200: nearest
        (300, 300, true, 0.0),     // a tie: the one at negative pixels
        (1, 500, false, 0.0),      // inactive, still the nearest table entry
    ];
    let tol = 1e-7;
    for (gap_neg, gap_pos, active, h) in cases {
        let scene = gapped_scene(gap_neg, gap_pos, active);
        let (got, periods) = request(scene);
        assert_eq!(
            periods.yaw_request_rad,
            Some(got),
            "the request is flagged valid"
        );
        let want = reference_request(&scene, h);
        let other = reference_request(&scene, 9_000.0 - h);
        eprintln!(
            "gap -{gap_neg}..{gap_pos}: request {got:.9} rad, reference {want:.9} over {h} m, \
             {other:.9} over the other neighbour's ground"
        );
        assert!(
            (f64::from(got) - want).abs() <= tol,
            "gap -{gap_neg}..{gap_pos}: {got} against {want} over {h} m"
        );
        assert!(
            (other - want).abs() > 10.0 * tol,
            "the two grounds give the same request: the case cannot tell them apart"
        );
    }
}
