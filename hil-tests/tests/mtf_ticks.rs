//! MTF_mismatch and line-period ticks on the target (f32) against the f64 functions
//! evaluated on the host at build time.
#![no_std]
#![no_main]

use hil_tests as _;

#[defmt_test::tests]
mod tests {
    use hil_tests::checks::{mtf_vs_f64, ticks_vs_f64};

    #[test]
    fn mtf_mismatch_vs_f64() {
        mtf_vs_f64().assert_passed("mtf_mismatch f32 vs f64 (absolute error)");
    }

    #[test]
    fn line_period_ticks_vs_f64() {
        ticks_vs_f64().assert_passed(
            "line_period_ticks f32 vs f64 (error in ticks, <= 0.5 is exact rounding)",
        );
    }
}
