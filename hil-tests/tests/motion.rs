//! Image-motion velocity and line period on the target (CLOSED_F32) against the f64
//! reference computed on the host at build time.
#![no_std]
#![no_main]

use hil_tests as _;

#[defmt_test::tests]
mod tests {
    use hil_tests::checks::motion_vs_reference;

    #[test]
    fn default_scene_sample_points() {
        motion_vs_reference("default").assert_passed("default scene vs f64 reference");
    }

    #[test]
    fn stiff_cases() {
        motion_vs_reference("stiff").assert_passed("stiff cases vs f64 reference");
    }

    #[test]
    fn refusals() {
        motion_vs_reference("refused").assert_passed("refusals vs f64 reference");
    }
}
