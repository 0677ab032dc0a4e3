//! `core_math::wide::Wide` and its 64 / 32 division against u64 and f64.
use core_math::sample::SplitMix64;
use core_math::wide::{div_64_32, Wide};

/// x >> k, k uniform: every magnitude.
fn draw_u64(rng: &mut SplitMix64) -> u64 {
    let x = rng.next_u64();
    x >> (rng.next_u64() % 64)
}

fn value(w: Wide) -> f64 {
    let (m, e) = w.parts();
    m as f64 * libm::exp2(f64::from(e))
}

/// Each operation against the same on the exact values in f64 (or u128): within one
/// truncation of 2^-31 relative, two for the sum and the difference.
#[test]
fn wide_operations_match_f64() {
    let mut rng = SplitMix64(0x5EED_2026_1127_0002);
    let ulp = libm::exp2(-31.0);
    for _ in 0..300_000 {
        let (x, y) = (draw_u64(&mut rng).max(1), draw_u64(&mut rng).max(1));
        let (ex, ey) = (
            (rng.next_u64() % 81) as i32 - 40,
            (rng.next_u64() % 81) as i32 - 40,
        );
        let (a, b) = (Wide::from_u64(x, ex), Wide::from_u64(y, ey));
        let (va, vb) = (
            x as f64 * libm::exp2(f64::from(ex)),
            y as f64 * libm::exp2(f64::from(ey)),
        );
        let close = |got: Wide, want: f64, k: f64, what: &str| {
            let g = value(got);
            assert!(
                libm::fabs(g - want) <= k * ulp * want,
                "{what}: {g:e} vs {want:e} ({x} 2^{ex}, {y} 2^{ey})"
            );
        };
        close(a, va, 1.0, "from_u64");
        // Each input's truncation, then the operation's.
        close(a * b, va * vb, 3.0, "mul");
        close(a / b, va / vb, 3.0, "div");
        close(a.recip(), 1.0 / va, 2.0, "recip");
        close(a + b, va + vb, 4.0, "add");
        assert_eq!(a.gt(b), value(a) > value(b));
        let d = a.abs_diff(b);
        let want = libm::fabs(value(a) - value(b));
        assert!(
            libm::fabs(value(d) - want) <= 2.0 * ulp * value(a).max(value(b)),
            "abs_diff {} vs {want}",
            value(d)
        );
        // To f32: the exact value (32 bits, exact in f64) rounded once.
        assert_eq!(a.to_f32().to_bits(), (value(a) as f32).to_bits());
        // 2^32 times, truncated, saturating.
        let q = value(a) * libm::exp2(32.0);
        let want_q = if q >= libm::exp2(64.0) {
            u64::MAX
        } else {
            q as u64
        };
        assert_eq!(a.to_u64_scaled(32), want_q);
    }
    for x in [1.0f32, 0.5, 3.0, 1e-30, 1.5e30, f32::MAX, f32::MIN_POSITIVE] {
        let w = Wide::from_f32(x).unwrap();
        assert_eq!(value(w), f64::from(x));
        assert_eq!(w.to_f32(), x);
    }
    assert_eq!(Wide::from_f32(-1.0), None);
    assert_eq!(Wide::from_f32(f32::NAN), None);
    assert_eq!(Wide::from_f32(0.0), Some(Wide::ZERO));
    assert_eq!(Wide::ZERO.to_f32(), 0.0);
}

/// The 64 / 32 division against u64's, at random and at the edges of its domain.
#[test]
fn division_by_32_bits_is_exact() {
    let mut rng = SplitMix64(0x5EED_2026_1127_0003);
    let check = |hi: u32, lo: u32, d: u32| {
        let n = (u64::from(hi) << 32) | u64::from(lo);
        assert_eq!(
            u64::from(div_64_32(hi, lo, d)),
            n / u64::from(d),
            "{n} / {d}"
        );
    };
    for _ in 0..2_000_000 {
        let d = (rng.next_u64() as u32) | (1 << 31);
        let hi = (rng.next_u64() as u32) % d;
        check(hi, rng.next_u64() as u32, d);
        // Quotient digits at their corrections' edges.
        check(d - 1, u32::MAX, d);
        check(hi, 0, d);
    }
    for d in [1 << 31, u32::MAX, 0x8000_ffff, 0xffff_0000] {
        for hi in [0, d - 1, d >> 1] {
            for lo in [0, u32::MAX, 1 << 31] {
                check(hi, lo, d);
            }
        }
    }
}
