//! Nutation, IAU 2000B (McCarthy & Luzum 2003, Cel. Mech. Dyn. Astron. 85, 37): the 77
//! luni-solar terms of MHB_2000_SHORT and a fixed offset in lieu of the planetary terms,
//! as SOFA's `iauNut00b`, with the P03 adjustments of `iauNut06a` (Wallace & Capitaine
//! 2006, Eqs. 5) that make a nutation consistent with IAU 2006 precession.
//!
//! SOFA's note: within 1 mas of IAU 2000A over 1995-2050 (1.001 mas at most), the free
//! core nutation aside.

use super::{ARCSEC_TO_RAD, TURN_ARCSEC, TWO_PI};

/// Units of the table, 0.1 microarcsecond, to radians.
const U2R: f64 = ARCSEC_TO_RAD / 1.0e7;
/// The fixed offsets in lieu of planetary terms (Luzum 2001), -0.135 mas and +0.388 mas.
const DPPLAN: f64 = -0.135 * ARCSEC_TO_RAD / 1.0e3;
const DEPLAN: f64 = 0.388 * ARCSEC_TO_RAD / 1.0e3;

/// One luni-solar term: multipliers of l, l', F, D, Om; longitude sin, t sin, cos and
/// obliquity cos; obliquity t cos and sin (0.1 microarcsecond, and per Julian
/// century). Integers as SOFA states them, the last two within i16: 28 bytes a term
/// against 48 as f64, and each converts to f64 exactly, so the sums are those of an
/// f64 table bit for bit.
type Term = ([i8; 5], [i32; 4], [i16; 2]);

/// The 77 luni-solar terms of `iauNut00b`, in SOFA's order: the transcription. The
/// flight binary holds them as [`PACKED`] (and `TERM1`), 18 bytes a term instead of 28
/// (docs/target.md, flash); `unpack` gives them back.
#[rustfmt::skip]
pub const TERMS: [Term; 77] = [
    // 1-10
    ([ 0, 0, 0, 0, 1], [-172_064_161, -174_666, 33_386, 92_052_331], [9_086, 15_377]),
    ([ 0, 0, 2,-2, 2], [-13_170_906, -1_675, -13_696, 5_730_336], [-3_015, -4_587]),
    ([ 0, 0, 2, 0, 2], [-2_276_413, -234, 2_796, 978_459], [-485, 1_374]),
    ([ 0, 0, 0, 0, 2], [2_074_554, 207, -698, -897_492], [470, -291]),
    ([ 0, 1, 0, 0, 0], [1_475_877, -3_633, 11_817, 73_871], [-184, -1_924]),
    ([ 0, 1, 2,-2, 2], [-516_821, 1_226, -524, 224_386], [-677, -174]),
    ([ 1, 0, 0, 0, 0], [711_159, 73, -872, -6_750], [0, 358]),
    ([ 0, 0, 2, 0, 1], [-387_298, -367, 380, 200_728], [18, 318]),
    ([ 1, 0, 2, 0, 2], [-301_461, -36, 816, 129_025], [-63, 367]),
    ([ 0,-1, 2,-2, 2], [215_829, -494, 111, -95_929], [299, 132]),
    // 11-20
    ([ 0, 0, 2,-2, 1], [128_227, 137, 181, -68_982], [-9, 39]),
    ([-1, 0, 2, 0, 2], [123_457, 11, 19, -53_311], [32, -4]),
    ([-1, 0, 0, 2, 0], [156_994, 10, -168, -1_235], [0, 82]),
    ([ 1, 0, 0, 0, 1], [63_110, 63, 27, -33_228], [0, -9]),
    ([-1, 0, 0, 0, 1], [-57_976, -63, -189, 31_429], [0, -75]),
    ([-1, 0, 2, 2, 2], [-59_641, -11, 149, 25_543], [-11, 66]),
    ([ 1, 0, 2, 0, 1], [-51_613, -42, 129, 26_366], [0, 78]),
    ([-2, 0, 2, 0, 1], [45_893, 50, 31, -24_236], [-10, 20]),
    ([ 0, 0, 0, 2, 0], [63_384, 11, -150, -1_220], [0, 29]),
    ([ 0, 0, 2, 2, 2], [-38_571, -1, 158, 16_452], [-11, 68]),
    // 21-30
    ([ 0,-2, 2,-2, 2], [32_481, 0, 0, -13_870], [0, 0]),
    ([-2, 0, 0, 2, 0], [-47_722, 0, -18, 477], [0, -25]),
    ([ 2, 0, 2, 0, 2], [-31_046, -1, 131, 13_238], [-11, 59]),
    ([ 1, 0, 2,-2, 2], [28_593, 0, -1, -12_338], [10, -3]),
    ([-1, 0, 2, 0, 1], [20_441, 21, 10, -10_758], [0, -3]),
    ([ 2, 0, 0, 0, 0], [29_243, 0, -74, -609], [0, 13]),
    ([ 0, 0, 2, 0, 0], [25_887, 0, -66, -550], [0, 11]),
    ([ 0, 1, 0, 0, 1], [-14_053, -25, 79, 8_551], [-2, -45]),
    ([-1, 0, 0, 2, 1], [15_164, 10, 11, -8_001], [0, -1]),
    ([ 0, 2, 2,-2, 2], [-15_794, 72, -16, 6_850], [-42, -5]),
    // 31-40
    ([ 0, 0,-2, 2, 0], [21_783, 0, 13, -167], [0, 13]),
    ([ 1, 0, 0,-2, 1], [-12_873, -10, -37, 6_953], [0, -14]),
    ([ 0,-1, 0, 0, 1], [-12_654, 11, 63, 6_415], [0, 26]),
    ([-1, 0, 2, 2, 1], [-10_204, 0, 25, 5_222], [0, 15]),
    ([ 0, 2, 0, 0, 0], [16_707, -85, -10, 168], [-1, 10]),
    ([ 1, 0, 2, 2, 2], [-7_691, 0, 44, 3_268], [0, 19]),
    ([-2, 0, 2, 0, 0], [-11_024, 0, -14, 104], [0, 2]),
    ([ 0, 1, 2, 0, 2], [7_566, -21, -11, -3_250], [0, -5]),
    ([ 0, 0, 2, 2, 1], [-6_637, -11, 25, 3_353], [0, 14]),
    ([ 0,-1, 2, 0, 2], [-7_141, 21, 8, 3_070], [0, 4]),
    // 41-50
    ([ 0, 0, 0, 2, 1], [-6_302, -11, 2, 3_272], [0, 4]),
    ([ 1, 0, 2,-2, 1], [5_800, 10, 2, -3_045], [0, -1]),
    ([ 2, 0, 2,-2, 2], [6_443, 0, -7, -2_768], [0, -4]),
    ([-2, 0, 0, 2, 1], [-5_774, -11, -15, 3_041], [0, -5]),
    ([ 2, 0, 2, 0, 1], [-5_350, 0, 21, 2_695], [0, 12]),
    ([ 0,-1, 2,-2, 1], [-4_752, -11, -3, 2_719], [0, -3]),
    ([ 0, 0, 0,-2, 1], [-4_940, -11, -21, 2_720], [0, -9]),
    ([-1,-1, 0, 2, 0], [7_350, 0, -8, -51], [0, 4]),
    ([ 2, 0, 0,-2, 1], [4_065, 0, 6, -2_206], [0, 1]),
    ([ 1, 0, 0, 2, 0], [6_579, 0, -24, -199], [0, 2]),
    // 51-60
    ([ 0, 1, 2,-2, 1], [3_579, 0, 5, -1_900], [0, 1]),
    ([ 1,-1, 0, 0, 0], [4_725, 0, -6, -41], [0, 3]),
    ([-2, 0, 2, 0, 2], [-3_075, 0, -2, 1_313], [0, -1]),
    ([ 3, 0, 2, 0, 2], [-2_904, 0, 15, 1_233], [0, 7]),
    ([ 0,-1, 0, 2, 0], [4_348, 0, -10, -81], [0, 2]),
    ([ 1,-1, 2, 0, 2], [-2_878, 0, 8, 1_232], [0, 4]),
    ([ 0, 0, 0, 1, 0], [-4_230, 0, 5, -20], [0, -2]),
    ([-1,-1, 2, 2, 2], [-2_819, 0, 7, 1_207], [0, 3]),
    ([-1, 0, 2, 0, 0], [-4_056, 0, 5, 40], [0, -2]),
    ([ 0,-1, 2, 2, 2], [-2_647, 0, 11, 1_129], [0, 5]),
    // 61-70
    ([-2, 0, 0, 0, 1], [-2_294, 0, -10, 1_266], [0, -4]),
    ([ 1, 1, 2, 0, 2], [2_481, 0, -7, -1_062], [0, -3]),
    ([ 2, 0, 0, 0, 1], [2_179, 0, -2, -1_129], [0, -2]),
    ([-1, 1, 0, 1, 0], [3_276, 0, 1, -9], [0, 0]),
    ([ 1, 1, 0, 0, 0], [-3_389, 0, 5, 35], [0, -2]),
    ([ 1, 0, 2, 0, 0], [3_339, 0, -13, -107], [0, 1]),
    ([-1, 0, 2,-2, 1], [-1_987, 0, -6, 1_073], [0, -2]),
    ([ 1, 0, 0, 0, 2], [-1_981, 0, 0, 854], [0, 0]),
    ([-1, 0, 0, 1, 0], [4_026, 0, -353, -553], [0, -139]),
    ([ 0, 0, 2, 1, 2], [1_660, 0, -5, -710], [0, -2]),
    // 71-77
    ([-1, 0, 2, 4, 2], [-1_521, 0, 9, 647], [0, 4]),
    ([-1, 1, 0, 1, 1], [1_314, 0, 0, -700], [0, 0]),
    ([ 0,-2, 2,-2, 1], [-1_283, 0, 0, 672], [0, 0]),
    ([ 1, 0, 2, 2, 1], [-1_331, 0, 8, 663], [0, 4]),
    ([-2, 0, 2, 2, 2], [1_383, 0, -2, -594], [0, -2]),
    ([-1, 0, 0, 0, 2], [1_405, 0, 4, -610], [0, 2]),
    ([ 1, 1, 2,-2, 2], [1_290, 0, 0, -556], [0, 0]),
];

/// Terms 2-77 by columns: each multiplier plus 2 in three bits (l in bits 0-2, l' 3-5,
/// F 6-8, D 9-11, Om 12-14: SOFA's multipliers here lie in -2..=4); the two large
/// coefficients (longitude sin, obliquity cos) as i32; the other four as i16. Term 1
/// alone needs more than 16 bits for two of those four: it is `TERM1`.
pub struct Packed {
    multipliers: [u16; 76],
    large: [[i32; 2]; 76],
    small: [[i16; 4]; 76],
}

/// Term 1 of [`TERMS`], as transcribed.
const TERM1: Term = TERMS[0];

/// [`TERMS`] 2-77 packed at compile time; a value that does not fit stops the build.
pub static PACKED: Packed = pack(&TERMS);

const fn pack(terms: &[Term; 77]) -> Packed {
    let mut p = Packed {
        multipliers: [0; 76],
        large: [[0; 2]; 76],
        small: [[0; 4]; 76],
    };
    let mut i = 0;
    while i < 76 {
        let (n, c, d) = terms[i + 1];
        let mut m = 0u16;
        let mut j = 0;
        while j < 5 {
            assert!(n[j] >= -2 && n[j] <= 5, "a multiplier outside three bits");
            m |= ((n[j] + 2) as u16) << (3 * j);
            j += 1;
        }
        p.multipliers[i] = m;
        p.large[i] = [c[0], c[3]];
        assert!(
            c[1] as i16 as i32 == c[1] && c[2] as i16 as i32 == c[2],
            "beyond i16"
        );
        p.small[i] = [c[1] as i16, c[2] as i16, d[0], d[1]];
        i += 1;
    }
    p
}

/// A term of [`PACKED`] unpacked: the integers of [`TERMS`].
#[inline(always)]
fn unpack(m: u16, [c0, c3]: [i32; 2], [c1, c2, d0, d1]: [i16; 4]) -> Term {
    let n = [0, 1, 2, 3, 4].map(|j| ((m >> (3 * j)) & 7) as i8 - 2);
    (n, [c0, i32::from(c1), i32::from(c2), c3], [d0, d1])
}

/// The five Delaunay arguments l, l', F, D, Om (rad) at `t` Julian centuries TT since
/// J2000.0, linear in t (Simon et al. 1994), as `iauNut00b` computes them.
pub fn delaunay(t: f64) -> [f64; 5] {
    let arg = |c0: f64, c1: f64| fundamental_argument(t, c0, c1);
    [
        // Mean anomaly of the Moon.
        arg(485_868.249_036, 1_717_915_923.217_8),
        // Mean anomaly of the Sun.
        arg(1_287_104.793_05, 129_596_581.048_1),
        // Mean argument of the latitude of the Moon.
        arg(335_779.526_232, 1_739_527_262.847_8),
        // Mean elongation of the Moon from the Sun.
        arg(1_072_260.703_69, 1_602_961_601.209_0),
        // Mean longitude of the ascending node of the Moon.
        arg(450_160.398_036, -6_962_890.543_1),
    ]
}

/// c0 + c1 t arcseconds reduced to one turn, in radians: one Delaunay argument.
// Out of line: the five arguments held a soft-float copy each (docs/target.md, flash).
#[inline(never)]
fn fundamental_argument(t: f64, c0: f64, c1: f64) -> f64 {
    super::fmod(c0 + c1 * t, TURN_ARCSEC) * ARCSEC_TO_RAD
}

/// The argument sum n . fa of a term, reduced to (-2 pi, 2 pi).
pub(crate) fn argument(n: &[i8; 5], fa: &[f64; 5]) -> f64 {
    let mut a = 0.0;
    for (k, x) in n.iter().zip(fa.iter()) {
        a = plus_multiple(a, *k, *x);
    }
    super::fmod(a, TWO_PI)
}

/// a + k x. Out of line: [`argument`]'s five steps were a soft-float copy each.
#[inline(never)]
fn plus_multiple(a: f64, k: i8, x: f64) -> f64 {
    a + f64::from(k) * x
}

/// Nutation in longitude and obliquity (dpsi, deps) (rad), IAU 2000B, at `t` Julian
/// centuries TT since J2000.0 (SOFA `iauNut00b`): the series summed smallest term first,
/// plus the fixed planetary offsets.
pub fn nut00b(t: f64) -> (f64, f64) {
    let fa = delaunay(t);
    let (mut dp, mut de) = (0.0, 0.0);
    let packed = PACKED
        .multipliers
        .iter()
        .zip(&PACKED.large)
        .zip(&PACKED.small);
    for ((m, large), small) in packed.rev() {
        add_term(&unpack(*m, *large, *small), t, &fa, &mut dp, &mut de);
    }
    add_term(&TERM1, t, &fa, &mut dp, &mut de);
    (dp * U2R + DPPLAN, de * U2R + DEPLAN)
}

/// One term's part of (dpsi, deps) added, in 0.1 microarcsecond. Out of line, so that
/// the loop's last iteration (term 1, from [`TERM1`]) is not a second copy of it.
#[inline(never)]
fn add_term((n, c, d): &Term, t: f64, fa: &[f64; 5], dp: &mut f64, de: &mut f64) {
    let (sarg, carg) = crate::trig_f64::sin_cos(argument(n, fa));
    let [c0, c1, c2, c3] = c.map(f64::from);
    let [c4, c5] = d.map(f64::from);
    *dp += (c0 + c1 * t) * sarg + c2 * carg;
    *de += (c3 + c4 * t) * carg + c5 * sarg;
}

/// IAU 2000B nutation with the P03 adjustments of `iauNut06a` (J2's secular variation
/// and the 2006 precession rate): dpsi (1 + 0.4697e-6 + fj2), deps (1 + fj2),
/// fj2 = -2.7774e-6 t. The nutation this crate's C2T uses.
pub fn nut06b(t: f64) -> (f64, f64) {
    let (dp, de) = nut00b(t);
    let fj2 = -2.7774e-6 * t;
    (dp + dp * (0.4697e-6 + fj2), de + de * fj2)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The packed table gives back every term of the transcription.
    #[test]
    fn packed_terms_are_the_transcription() {
        assert_eq!(TERM1, TERMS[0]);
        let packed = PACKED
            .multipliers
            .iter()
            .zip(&PACKED.large)
            .zip(&PACKED.small);
        let mut k = 1;
        for ((m, large), small) in packed {
            assert_eq!(unpack(*m, *large, *small), TERMS[k], "term {}", k + 1);
            k += 1;
        }
        assert_eq!(k, TERMS.len());
    }
}
