//! The satellite bus's frames (`core_math::earth::frames`) against ERFA (pyerfa), the
//! goldens of `tools/goldens/erfa_frames.py` in `tests/data/`: C2T against
//! `eraC2t06a(TT, UT1, 0, 0)` and each of its pieces against its ERFA routine; geodetic
//! conversions against `eraGd2gce` / `eraGc2gde` and by round trip; the typed refusals.
//!
//! `cargo test --release -p core-math --test frames -- --nocapture` prints the measured
//! maxima quoted in `docs/earth-model.md`, "Earth orientation (Part II)".

use core_math::earth::frames::cio::{s06, S06_TRUNCATION_BOUND_RAD};
use core_math::earth::frames::era::{era00, sp00};
use core_math::earth::frames::fw::{fw2m, pfw06};
use core_math::earth::frames::geodetic::GEODETIC_MAX_FLATTENING;
use core_math::earth::frames::nutation::{nut00b, nut06b};
use core_math::earth::frames::time::{tt_from_gps_s, ut1_from_gps_s, GPS_S_MAX, JD_J2000};
use core_math::earth::frames::{
    c2t, c2t_from_cio, geodetic_from_itrf, itrf_from_geodetic, CelestialPole, Mat3, TimeScales,
    C2T_TOLERANCE_RAD, POLE_MAX_AGE_S,
};
use core_math::sample::SplitMix64;
use core_math::{Ellipsoid, ModelError, Param};
use std::f64::consts::{FRAC_PI_2, PI};

const C2T_CSV: &str = include_str!("data/erfa_c2t.csv");
const GEODETIC_CSV: &str = include_str!("data/erfa_geodetic.csv");

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
    fn s(&self, name: &str) -> &str {
        let i = self.head.iter().position(|h| *h == name).expect(name);
        self.fields[i]
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

/// C2T from a [`CelestialPole`] computed up to [`POLE_MAX_AGE_S`] earlier or later, with
/// the Earth rotation angle of the instant: within the tolerance of `eraC2t06a`, and
/// within 1.5e-9 rad of a fresh [`c2t`] (the pole's own motion over a minute).
#[test]
fn c2t_from_a_pole_a_minute_old_stays_within_tolerance() {
    let (head, data) = rows(C2T_CSV);
    let (mut max_erfa, mut max_fresh) = (0.0f64, 0.0f64);
    for fields in &data {
        let row = Row {
            head: &head,
            fields,
        };
        let (gps_s, sc) = (row.f("gps_s"), scales(&row));
        for age_s in [-POLE_MAX_AGE_S, POLE_MAX_AGE_S] {
            let Ok(pole) = CelestialPole::at(gps_s - age_s, &sc) else {
                continue;
            };
            let m = pole.c2t(gps_s, &sc).unwrap();
            max_erfa = max_erfa.max(angle_between(&m, &matrix(&row)));
            max_fresh = max_fresh.max(angle_between(&m, &c2t(gps_s, &sc).unwrap()));
        }
    }
    println!(
        "C2T from a pole {POLE_MAX_AGE_S} s old: {max_fresh:.3e} rad from a fresh C2T, \
         {max_erfa:.3e} rad from eraC2t06a"
    );
    assert!(max_fresh <= 1.5e-9 && max_erfa <= C2T_TOLERANCE_RAD);
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

fn ellipsoid(row: &Row) -> Ellipsoid {
    Ellipsoid {
        a_m: row.f("a_m"),
        flattening: row.f("flattening"),
    }
}

/// |a - b| reduced to (-pi, pi].
fn dlon(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(2.0 * PI);
    d.min(2.0 * PI - d)
}

#[test]
fn geodetic_matches_erfa_gd2gce_and_gc2gde() {
    let (head, data) = rows(GEODETIC_CSV);
    assert!(data.len() >= 300);
    let (mut fwd, mut lat_e, mut lon_e, mut h_e, mut vs_gc) =
        (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let mut names = std::collections::BTreeSet::new();
    for fields in &data {
        let row = Row {
            head: &head,
            fields,
        };
        names.insert(row.s("ellipsoid").to_string());
        let ell = ellipsoid(&row);
        let (lat, lon, h) = (row.f("lat_rad"), row.f("lon_rad"), row.f("h_m"));
        let xyz = [row.f("x_m"), row.f("y_m"), row.f("z_m")];
        let ours = itrf_from_geodetic(lat, lon, h, &ell).unwrap();
        let d =
            ((ours[0] - xyz[0]).powi(2) + (ours[1] - xyz[1]).powi(2) + (ours[2] - xyz[2]).powi(2))
                .sqrt();
        fwd = fwd.max(d);
        let (la, lo, hh) = geodetic_from_itrf(xyz, &ell).unwrap();
        lat_e = lat_e.max((la - lat).abs());
        h_e = h_e.max((hh - h).abs());
        // Longitude is only defined off the axis: there its error moves the point by
        // rho dlon (m), below 1e-4 m (the golden x, y at a pole are 1e-10 m).
        let rho = xyz[0].hypot(xyz[1]);
        lon_e = lon_e.max(rho * dlon(lo, lon));
        let (gla, glo, gh) = (
            row.f("gc2gde_lat_rad"),
            row.f("gc2gde_lon_rad"),
            row.f("gc2gde_h_m"),
        );
        vs_gc = vs_gc
            .max((la - gla).abs())
            .max(rho * dlon(lo, glo) / ell.a_m)
            .max((hh - gh).abs() / ell.a_m);
    }
    println!(
        "geodetic vs ERFA over {} rows ({names:?}): itrf_from_geodetic vs eraGd2gce {fwd:.2e} m; \
         geodetic_from_itrf of eraGd2gce's points: lat {lat_e:.2e} rad, lon {lon_e:.2e} m along \
         the parallel, h {h_e:.2e} m; vs eraGc2gde {vs_gc:.2e} (rad, or m / a)",
        data.len()
    );
    assert_eq!(names.len(), 3);
    assert!(fwd <= 1.0e-4, "{fwd:e}");
    assert!(lat_e <= 1.0e-9, "{lat_e:e}");
    assert!(lon_e <= 1.0e-4, "{lon_e:e}");
    assert!(h_e <= 1.0e-4, "{h_e:e}");
    assert!(vs_gc <= 1.0e-9, "{vs_gc:e}");
}

#[test]
fn geodetic_round_trips() {
    let mut rng = SplitMix64(2023);
    let ells = [
        Ellipsoid::WGS84,
        Ellipsoid {
            a_m: 6_378_245.0,
            flattening: 1.0 / 298.3,
        },
        Ellipsoid {
            a_m: 3_396_190.0,
            flattening: GEODETIC_MAX_FLATTENING,
        },
    ];
    let (mut dpos, mut dlat, mut dh) = (0.0f64, 0.0f64, 0.0f64);
    for i in 0..30_000 {
        let ell = ells[i % ells.len()];
        let lat = match i % 50 {
            0 => FRAC_PI_2,
            1 => -FRAC_PI_2,
            2 => 0.0,
            _ => rng.uniform(-1.0, 1.0).asin(),
        };
        let lon = rng.uniform(-PI, PI);
        let h = if i % 2 == 0 {
            rng.uniform(-500.0, 2.0e6)
        } else {
            rng.uniform(-0.25 * ell.a_m, 4.0e7)
        };
        let r = itrf_from_geodetic(lat, lon, h, &ell).unwrap();
        let (la, lo, hh) = geodetic_from_itrf(r, &ell).unwrap();
        let back = itrf_from_geodetic(la, lo, hh, &ell).unwrap();
        let d =
            ((back[0] - r[0]).powi(2) + (back[1] - r[1]).powi(2) + (back[2] - r[2]).powi(2)).sqrt();
        dpos = dpos.max(
            d / (r[0] * r[0] + r[1] * r[1] + r[2] * r[2])
                .sqrt()
                .max(ell.a_m)
                * ell.a_m,
        );
        dlat = dlat.max((la - lat).abs());
        dh = dh.max((hh - h).abs());
    }
    println!(
        "geodetic round trips (30 000, h -a/4 .. 40 000 km): position {dpos:.2e} m (scaled to |r| = a \
         beyond a), lat {dlat:.2e} rad, h {dh:.2e} m"
    );
    assert!(dpos <= 1.0e-4, "{dpos:e}");
    assert!(dlat <= 1.0e-9, "{dlat:e}");
    assert!(dh <= 1.0e-4, "{dh:e}");
}

#[test]
fn geodetic_poles_and_axis() {
    let e = Ellipsoid::WGS84;
    let b = e.b_m();
    for (z, lat) in [(b + 100.0, FRAC_PI_2), (-(b + 100.0), -FRAC_PI_2)] {
        let (la, lo, h) = geodetic_from_itrf([0.0, 0.0, z], &e).unwrap();
        assert_eq!((la, lo), (lat, 0.0));
        assert!((h - 100.0).abs() < 1e-8, "{h}");
    }
    let (la, lo, h) = geodetic_from_itrf([e.a_m + 5.0, 0.0, 0.0], &e).unwrap();
    assert_eq!((la, lo), (0.0, 0.0));
    assert!((h - 5.0).abs() < 1e-8, "{h}");
    let (_, lo, _) = geodetic_from_itrf([-e.a_m, 0.0, 0.0], &e).unwrap();
    assert_eq!(lo, PI);
}

#[test]
fn geodetic_refusals_are_typed() {
    let e = Ellipsoid::WGS84;
    for (r, err) in [
        ([0.0, 0.0, 0.0], ModelError::OutOfDomain(Param::Position)),
        (
            [1.0e6, 0.0, 1.0e6],
            ModelError::OutOfDomain(Param::Position),
        ),
        ([f64::NAN, 0.0, 7e6], ModelError::NonFinite(Param::Position)),
        (
            [0.0, f64::INFINITY, 7e6],
            ModelError::NonFinite(Param::Position),
        ),
        ([2.0e9, 0.0, 0.0], ModelError::OutOfDomain(Param::Position)),
    ] {
        assert_eq!(geodetic_from_itrf(r, &e), Err(err), "{r:?}");
    }
    let r = [7.0e6, 0.0, 0.0];
    for (ell, err) in [
        (
            Ellipsoid {
                a_m: f64::NAN,
                flattening: 0.0,
            },
            ModelError::NonFinite(Param::SemiMajorAxis),
        ),
        (
            Ellipsoid {
                a_m: 6.4e6,
                flattening: f64::NAN,
            },
            ModelError::NonFinite(Param::Flattening),
        ),
        (
            Ellipsoid {
                a_m: 0.0,
                flattening: 0.0,
            },
            ModelError::InvalidInput(Param::SemiMajorAxis),
        ),
        (
            Ellipsoid {
                a_m: 6.4e6,
                flattening: -0.1,
            },
            ModelError::InvalidInput(Param::Flattening),
        ),
        (
            Ellipsoid {
                a_m: 6.4e6,
                flattening: 1.0,
            },
            ModelError::InvalidInput(Param::Flattening),
        ),
        (
            Ellipsoid {
                a_m: 6.4e6,
                flattening: 0.2,
            },
            ModelError::OutOfDomain(Param::Flattening),
        ),
        (
            Ellipsoid {
                a_m: 1.0,
                flattening: 0.0,
            },
            ModelError::OutOfDomain(Param::SemiMajorAxis),
        ),
    ] {
        assert_eq!(geodetic_from_itrf(r, &ell), Err(err), "{ell:?}");
        assert_eq!(itrf_from_geodetic(0.0, 0.0, 0.0, &ell), Err(err), "{ell:?}");
    }
    for (lat, lon, h, err) in [
        (f64::NAN, 0.0, 0.0, ModelError::NonFinite(Param::Latitude)),
        (
            0.0,
            f64::INFINITY,
            0.0,
            ModelError::NonFinite(Param::Longitude),
        ),
        (0.0, 0.0, f64::NAN, ModelError::NonFinite(Param::Height)),
        (1.6, 0.0, 0.0, ModelError::InvalidInput(Param::Latitude)),
        (-1.6, 0.0, 0.0, ModelError::InvalidInput(Param::Latitude)),
        (0.0, 7.0, 0.0, ModelError::OutOfDomain(Param::Longitude)),
        (
            0.0,
            0.0,
            -0.26 * e.a_m,
            ModelError::OutOfDomain(Param::Height),
        ),
        (0.0, 0.0, 2.0e9, ModelError::OutOfDomain(Param::Height)),
    ] {
        assert_eq!(
            itrf_from_geodetic(lat, lon, h, &e),
            Err(err),
            "{lat} {lon} {h}"
        );
    }
}
