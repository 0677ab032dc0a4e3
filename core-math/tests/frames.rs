//! The satellite bus's frames (`core_math::earth::frames`) against ERFA (pyerfa), the
//! goldens of `tools/goldens/erfa_frames.py` in `tests/data/`: C2T against
//! `eraC2t06a(TT, UT1, 0, 0)` and each of its pieces against its ERFA routine; the typed
//! refusals.
//!
//! `cargo test --release -p core-math --test frames -- --nocapture` prints the measured
//! maxima quoted in `docs/earth-model.md`, "Earth orientation (Part II)".

use core_math::earth::frames::cio::{s06, S06_TRUNCATION_BOUND_RAD};
use core_math::earth::frames::era::{era00, sp00};
use core_math::earth::frames::fw::{fw2m, pfw06};
use core_math::earth::frames::nutation::{nut00b, nut06b};
use core_math::earth::frames::time::{tt_from_gps_s, ut1_from_gps_s, GPS_S_MAX, JD_J2000};
use core_math::earth::frames::{c2t, c2t_from_cio, Mat3, TimeScales, C2T_TOLERANCE_RAD};
use core_math::sample::SplitMix64;
use core_math::{ModelError, Param};

const C2T_CSV: &str = include_str!("data/erfa_c2t.csv");

/// The rows of a golden file as (header, fields), comments skipped.
fn rows(csv: &str) -> (Vec<&str>, Vec<Vec<&str>>) {
    let mut lines = csv.lines().filter(|l| !l.starts_with('#') && !l.is_empty());
    let head = lines.next().expect("header").split(',').collect();
    (head, lines.map(|l| l.split(',').collect()).collect())
}

/// Column accessor by name.
struct Row<'a> {
    head: &'a [&'a str],
    fields: &'a [&'a str],
}

impl Row<'_> {
    fn f(&self, name: &str) -> f64 {
        let i = self.head.iter().position(|h| *h == name).expect(name);
        self.fields[i].parse().expect(name)
    }
}

fn matrix(row: &Row) -> Mat3 {
    let mut m = [[0.0; 3]; 3];
    for (i, mi) in m.iter_mut().enumerate() {
        for (j, mij) in mi.iter_mut().enumerate() {
            *mij = row.f(&format!("r{i}{j}"));
        }
    }
    m
}

/// The rotation angle (rad) of a^T b, for rotations a, b: atan2 of the antisymmetric
/// part's norm (2 sin) against the trace (1 + 2 cos), accurate at small angles.
fn angle_between(a: &Mat3, b: &Mat3) -> f64 {
    let mut m = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] = (0..3).map(|k| a[k][i] * b[k][j]).sum();
        }
    }
    let v = [m[2][1] - m[1][2], m[0][2] - m[2][0], m[1][0] - m[0][1]];
    let s2 = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let c2 = m[0][0] + m[1][1] + m[2][2] - 1.0;
    s2.atan2(c2)
}

fn scales(row: &Row) -> TimeScales {
    TimeScales {
        gps_utc_s: row.f("gps_utc_s"),
        dut1_s: row.f("dut1_s"),
    }
}

#[test]
fn c2t_within_its_tolerance_of_erfa_c2t06a() {
    let (head, data) = rows(C2T_CSV);
    assert!(data.len() >= 300);
    let (mut max, mut at) = (0.0f64, 0.0);
    for fields in &data {
        let row = Row {
            head: &head,
            fields,
        };
        let gps_s = row.f("gps_s");
        let ours = c2t(gps_s, &scales(&row)).unwrap();
        let err = angle_between(&ours, &matrix(&row));
        if err > max {
            (max, at) = (err, gps_s);
        }
    }
    println!(
        "C2T vs eraC2t06a over {} instants 2000-2050: max angle {max:.3e} rad (gps_s {at}); \
         tolerance {C2T_TOLERANCE_RAD:.1e}",
        data.len()
    );
    assert!(max <= C2T_TOLERANCE_RAD);
    const { assert!(C2T_TOLERANCE_RAD <= 1.0e-7) };
}

#[test]
fn c2t_assembly_is_erfas_given_erfas_cip_s_and_angles() {
    // With ERFA's own X, Y (IAU 2000A), s, ERA and s' the rotations reproduce
    // eraC2t06a to rounding: what remains in the test above is the nutation model.
    let (head, data) = rows(C2T_CSV);
    let mut max = 0.0f64;
    for fields in &data {
        let row = Row {
            head: &head,
            fields,
        };
        let m = c2t_from_cio(
            row.f("x06a"),
            row.f("y06a"),
            row.f("s06"),
            row.f("era00"),
            row.f("sp00"),
        );
        max = max.max(angle_between(&m, &matrix(&row)));
    }
    println!("C2T assembly from ERFA's X, Y, s, ERA, s' vs eraC2t06a: max {max:.2e} rad");
    assert!(max <= 1.0e-14, "{max:e}");
}

#[test]
fn time_scales_give_erfas_two_part_dates() {
    let (head, data) = rows(C2T_CSV);
    let mut max = 0.0f64;
    for fields in &data {
        let row = Row {
            head: &head,
            fields,
        };
        let gps_s = row.f("gps_s");
        let tt = tt_from_gps_s(gps_s).unwrap();
        let ut1 = ut1_from_gps_s(gps_s, &scales(&row)).unwrap();
        for (d, (c1, c2)) in [(tt, ("tt1", "tt2")), (ut1, ("ut11", "ut12"))] {
            let (d1, d2) = d.jd();
            // Both sides split whole days the same way: the difference is all in the
            // fraction, the golden's exact up to its own rounding.
            let diff = (d1 - row.f(c1)) + (d2 - row.f(c2));
            max = max.max(diff.abs());
        }
    }
    println!("TT, UT1 two-part dates vs the exact ones: max {max:.3e} d");
    // 1e-15 d = 0.1 ns.
    assert!(max <= 1.0e-15, "{max:e}");
}

#[test]
fn c2t_pieces_follow_their_erfa_routines() {
    let (head, data) = rows(C2T_CSV);
    let (mut nut, mut fw, mut era, mut sp, mut s, mut xy) =
        (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for fields in &data {
        let row = Row {
            head: &head,
            fields,
        };
        let gps_s = row.f("gps_s");
        let tt = tt_from_gps_s(gps_s).unwrap();
        let ut1 = ut1_from_gps_s(gps_s, &scales(&row)).unwrap();
        let t = tt.centuries();
        let (dp, de) = nut00b(t);
        nut = nut
            .max((dp - row.f("nut00b_dpsi")).abs())
            .max((de - row.f("nut00b_deps")).abs());
        let a = pfw06(t);
        for (ours, name) in [
            (a.gamb_rad, "pfw06_gamb"),
            (a.phib_rad, "pfw06_phib"),
            (a.psib_rad, "pfw06_psib"),
            (a.epsa_rad, "pfw06_epsa"),
        ] {
            fw = fw.max((ours - row.f(name)).abs());
        }
        let e = era00(&ut1) - row.f("era00");
        era = era.max(e.sin().abs());
        sp = sp.max((sp00(t) - row.f("sp00")).abs());
        let (x, y) = (row.f("x06a"), row.f("y06a"));
        s = s.max((s06(t, x, y) - row.f("s06")).abs());
        // Our CIP (IAU 2000B) against ERFA's (IAU 2000A).
        let (dp6, de6) = nut06b(t);
        let npb = fw2m(a.gamb_rad, a.phib_rad, a.psib_rad + dp6, a.epsa_rad + de6);
        xy = xy.max(((npb[2][0] - x).powi(2) + (npb[2][1] - y).powi(2)).sqrt());
    }
    println!(
        "pieces vs ERFA: nut00b {nut:.2e}, pfw06 {fw:.2e}, era00 {era:.2e}, sp00 {sp:.2e}, \
         s06 (truncated) {s:.2e}, CIP 2000B vs 2000A {xy:.2e} rad"
    );
    // The transcribed series and polynomials agree to rounding: one unit of the
    // nutation table's last digit is 4.8e-13 rad.
    assert!(nut <= 1.0e-15, "nut00b {nut:e}");
    assert!(fw <= 1.0e-15, "pfw06 {fw:e}");
    // ERA's ~6 rad argument rounds to ~1e-15 rad; the UT1 day split adds ~1e-16 d.
    assert!(era <= 1.0e-11, "era00 {era:e}");
    assert!(sp <= 1.0e-20, "sp00 {sp:e}");
    assert!(s <= S06_TRUNCATION_BOUND_RAD, "s06 {s:e}");
    assert!(xy <= 1.0e-8, "CIP {xy:e}");
}

fn orthonormality_error(m: &Mat3) -> f64 {
    let mut e = 0.0f64;
    for i in 0..3 {
        for j in 0..3 {
            let d: f64 = (0..3).map(|k| m[i][k] * m[j][k]).sum();
            e = e.max((d - if i == j { 1.0 } else { 0.0 }).abs());
        }
    }
    e
}

fn det(m: &Mat3) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

#[test]
fn c2t_is_a_proper_rotation() {
    let mut rng = SplitMix64(23);
    let mut max = 0.0f64;
    for i in 0..2000 {
        let gps_s = if i == 0 {
            0.0
        } else if i == 1 {
            GPS_S_MAX
        } else {
            rng.uniform(0.0, GPS_S_MAX)
        };
        let sc = TimeScales {
            gps_utc_s: (rng.uniform(0.0, 40.0)).floor(),
            dut1_s: rng.uniform(-0.89, 0.89),
        };
        let m = c2t(gps_s, &sc).unwrap();
        max = max.max(orthonormality_error(&m)).max((det(&m) - 1.0).abs());
    }
    println!("C2T orthonormality: max |R R^T - I|, |det - 1| {max:.2e}");
    assert!(max <= 1.0e-15, "{max:e}");
}

#[test]
fn c2t_turns_with_the_earth() {
    // One sidereal-ish second later the matrix has turned about z by the Earth's rate.
    let sc = TimeScales::default();
    let gps_s = 1.4e9;
    let a = c2t(gps_s, &sc).unwrap();
    let b = c2t(gps_s + 1.0, &sc).unwrap();
    let rate = angle_between(&a, &b);
    assert!((rate - 7.292_115_146_7e-5).abs() < 1e-12, "{rate:e}");
}

#[test]
fn time_refusals_are_typed() {
    let ok = TimeScales::default();
    assert_eq!(ok.validate(), Ok(()));
    for (gps_s, e) in [
        (f64::NAN, ModelError::NonFinite(Param::GpsTime)),
        (f64::INFINITY, ModelError::NonFinite(Param::GpsTime)),
        (-1.0, ModelError::OutOfDomain(Param::GpsTime)),
        (
            GPS_S_MAX * 1.000_001,
            ModelError::OutOfDomain(Param::GpsTime),
        ),
    ] {
        assert_eq!(c2t(gps_s, &ok), Err(e), "{gps_s}");
        assert_eq!(tt_from_gps_s(gps_s), Err(e), "{gps_s}");
    }
    for (leap, dut1, e) in [
        (f64::NAN, 0.0, ModelError::NonFinite(Param::LeapSeconds)),
        (18.0, f64::NEG_INFINITY, ModelError::NonFinite(Param::Dut1)),
        (17.5, 0.0, ModelError::InvalidInput(Param::LeapSeconds)),
        (-1.0, 0.0, ModelError::OutOfDomain(Param::LeapSeconds)),
        (61.0, 0.0, ModelError::OutOfDomain(Param::LeapSeconds)),
        (18.0, 0.9, ModelError::InvalidInput(Param::Dut1)),
        (18.0, -0.95, ModelError::InvalidInput(Param::Dut1)),
    ] {
        let sc = TimeScales {
            gps_utc_s: leap,
            dut1_s: dut1,
        };
        assert_eq!(sc.validate(), Err(e));
        assert_eq!(c2t(1.4e9, &sc), Err(e));
    }
    assert!(c2t(
        0.0,
        &TimeScales {
            gps_utc_s: 0.0,
            dut1_s: 0.0
        }
    )
    .is_ok());
    assert!(c2t(
        1.4e9,
        &TimeScales {
            gps_utc_s: 60.0,
            dut1_s: -0.899
        }
    )
    .is_ok());
}

#[test]
fn tt_is_split_exactly_at_the_gps_epoch_and_j2000() {
    let tt = tt_from_gps_s(0.0).unwrap();
    assert_eq!(tt.whole_d, -7300.0);
    assert_eq!(tt.frac_d, (51.184 - 43_200.0) / 86_400.0);
    assert_eq!(tt.jd().0, JD_J2000 - 7300.0);
    // J2000.0 TT = 2000-01-01T12:00:00 TT = 630 763 148.816 s GPS, a float within
    // half its ulp (1.2e-7 s) of that.
    let tt = tt_from_gps_s(630_763_148.816).unwrap();
    assert_eq!(tt.whole_d, 0.0);
    assert!((tt.frac_d * 86_400.0).abs() <= 6.0e-8, "{}", tt.frac_d);
}
