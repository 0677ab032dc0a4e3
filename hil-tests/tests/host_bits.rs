//! The target's f32 results are bit-identical to the same functions run on the host at
//! build time: what lets the host-side accuracy sweep stand for the target.
#![no_std]
#![no_main]

use hil_tests as _;

#[defmt_test::tests]
mod tests {
    use hil_tests::checks::{motion_bits_vs_host, mtf_bits_vs_host, ticks_bits_vs_host};

    #[test]
    fn closed_f32_bit_identical_to_host() {
        motion_bits_vs_host().assert_passed("CLOSED_F32 target vs host, bit for bit");
    }

    #[test]
    fn mtf_bit_identical_to_host() {
        mtf_bits_vs_host().assert_passed("mtf_mismatch::<f32> target vs host, bit for bit");
    }

    #[test]
    fn ticks_bit_identical_to_host() {
        ticks_bits_vs_host().assert_passed("line_period_ticks::<f32> target vs host, bit for bit");
    }
}
