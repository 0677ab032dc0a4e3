//! Where the results go. Today: defmt log lines (decoded on the host). Later: the
//! line clock of each detector segment.

use crate::pipeline::{SegmentReport, SAMPLE_NAMES};
use crate::scene::Scene;

/// One line describing the scene being evaluated.
pub fn log_scene(scene: &Scene) {
    let g = scene.geometry;
    defmt::info!(
        "scene: H {=f32} km, R {=f32} km, f {=f64} m, pixel {=f64} um, i0 {=f32} deg, roll {=f32} deg, gamma0 {=f32} deg",
        g.altitude_m / 1.0e3,
        g.earth_radius_m / 1.0e3,
        scene.camera.focal_m,
        scene.camera.pixel_m * 1.0e6,
        g.inclination_rad.to_degrees(),
        g.roll_rad.to_degrees(),
        g.arg_latitude_rad.to_degrees(),
    );
    defmt::info!(
        "detector: {=u32} segments of {=u32} px from n = {=i32}; line clock {=f32} MHz",
        scene.layout.segments,
        scene.layout.segment_px,
        scene.layout.first_px,
        scene.line_clock_hz / 1.0e6,
    );
}

/// One line per sample point of a segment.
pub fn log_segment(report: &SegmentReport) {
    for (p, name) in report.points.iter().zip(SAMPLE_NAMES) {
        defmt::info!(
            "segment {=u8} {=str} n={=i32}: v1={=f32} v2={=f32} |v|={=f32} m/s, line period {=f32} s = {=u32} ticks",
            report.index,
            name,
            p.n_px,
            p.v1_mps,
            p.v2_mps,
            p.speed_mps,
            p.period_s,
            p.ticks,
        );
    }
}
