//! The general (real-Earth) model's maps: `GENERAL_F32` against `EarthReference`, with
//! the problem's componentwise condition number `earth_kappa` over its 19 inputs, and
//! the measured bound err <= `EARTH_F32_KAPPA_C` kappa u32.
//!
//! Three maps at the default orbit (circular, 645 km above the WGS 84 equatorial radius,
//! i0 97.98 deg unless the map spans the altitude): pitch x roll (yaw 0, and yaw 30 deg),
//! altitude x limb margin, and pitch rate x roll rate (the rates that cancel the image
//! motion). Error |dv|/|v|: hypot of the component differences over the reference's
//! hypot(v1, v2), inputs as given in f64 (the f32 path rounds the attitude itself).

use anyhow::Result;
use core_math::accuracy::{
    earth_kappa, EARTH_F32_KAPPA_C, EARTH_F32_KAPPA_LIMIT, EARTH_F32_REL_TOLERANCE,
};
use core_math::earth::{circular_state, limb_margin_rad, Attitude, EarthCamera, EarthGeometry};
use core_math::sample::{roll_at_limb_margin, EarthCase};
use core_math::vector::norm;
use core_math::{Backend, EarthReference, Ellipsoid, ModelError, EARTH_RATE_RAD_S};

use std::collections::BTreeMap;
use std::path::Path;

use crate::markdown::{e2, f2, sig, sig_range};

use super::doc::lg;
use super::general_fixed::{FAR_TARGET, NEAR_TARGET};
use super::grid::{self, Cell as _, Column, Panel, Spec, Worst};
use super::maps::I0_SSO_DEG;
use crate::accuracy::{Motion, GENERAL_F32_MOTION, U_F32};

/// The paper's camera on the detector line through the optical axis.
pub const CAMERA: EarthCamera = EarthCamera {
    focal_m: 0.555,
    pixel_m: 13e-6,
    p1_m: 0.0,
};
/// The maps keep lines of sight at least this far inside the limb (deg): the bound
/// err <= C kappa u32 is stated there (`core_math::accuracy::EARTH_F32_KAPPA_C`).
pub const MIN_MARGIN_DEG: f64 = 0.01;
/// Default altitude above the equatorial radius (km) and argument of latitude (deg).
const H0_KM: f64 = 645.0;
const G0_DEG: f64 = 45.0;
/// Pixels across the swath (n_px): the two ends and the centre of a 60 000-pixel line.
const PIXELS: [f64; 3] = [-30_000.0, 0.0, 30_000.0];

/// A circular orbit at `h_km` above the WGS 84 equatorial radius, inclination `i0_deg`,
/// argument of latitude `g0_deg`, with the attitude given (rad, rad/s).
fn case(h_km: f64, i0_deg: f64, g0_deg: f64, attitude: Attitude<f64>, n_px: f64) -> EarthCase {
    let e = Ellipsoid::WGS84;
    EarthCase {
        camera: CAMERA,
        geometry: EarthGeometry {
            state: circular_state(e.a_m + h_km * 1e3, i0_deg.to_radians(), g0_deg.to_radians()),
            attitude,
            ground_h_m: 0.0,
            ellipsoid: e,
            earth_rate_rad_s: EARTH_RATE_RAD_S,
        },
        n_px,
    }
}

fn angles(roll_deg: f64, pitch_deg: f64, yaw_deg: f64) -> Attitude<f64> {
    Attitude {
        roll_rad: roll_deg.to_radians(),
        pitch_rad: pitch_deg.to_radians(),
        yaw_rad: yaw_deg.to_radians(),
        ..Attitude::default()
    }
}

/// The grey cells of every general map.
const MISSING: &str = "< 0.01 deg inside the limb";

fn pitch_roll(yaw_deg: f64, pitch: f64, roll: f64, s: usize) -> EarthCase {
    let n = PIXELS[s % PIXELS.len()];
    case(H0_KM, I0_SSO_DEG, G0_DEG, angles(roll, pitch, yaw_deg), n)
}

/// Altitude x limb margin: the roll that puts the line of sight `10^y` deg inside the
/// limb, for a pixel at either end of the line (the side of the roll), with the pitch,
/// yaw and argument of latitude cycling over the sub-samples.
fn altitude_limb(h_km: f64, log_margin_deg: f64, s: usize) -> Option<EarthCase> {
    const PITCH: [f64; 3] = [0.0, 20.0, -30.0];
    const YAW_G0: [(f64, f64); 2] = [(0.0, G0_DEG), (30.0, 135.0)];
    let side = [1.0, -1.0][s % 2];
    let (yaw, g0) = YAW_G0[(s / 2) % 2];
    let pitch = PITCH[s % 3];
    let mut c = case(
        h_km,
        I0_SSO_DEG,
        g0,
        angles(0.0, pitch, yaw),
        side * PIXELS[2],
    );
    let margin = 10f64.powf(log_margin_deg).to_radians();
    c.geometry.attitude.roll_rad = roll_at_limb_margin(&c, margin, side)?;
    Some(c)
}

/// Pitch rate x roll rate (deg/s), the angles 0 (and roll 20, pitch -10 deg).
fn rates(pitch_rate: f64, roll_rate: f64, s: usize) -> Option<EarthCase> {
    let (roll, pitch) = [(0.0, 0.0), (20.0, -10.0)][(s / 3) % 2];
    let mut a = angles(roll, pitch, 0.0);
    a.roll_rate_rad_s = roll_rate.to_radians();
    a.pitch_rate_rad_s = pitch_rate.to_radians();
    Some(case(H0_KM, I0_SSO_DEG, G0_DEG, a, PIXELS[s % 3]))
}

/// Map D: pitch x roll at yaw 0.
const PITCH_ROLL: Spec<EarthCase> = Spec {
    key: "general-pitch-roll",
    letter: "D",
    title: "pitch x roll, yaw 0",
    x_label: "pitch (deg)",
    y_label: "roll (deg)",
    x_range: (-45.0, 45.0),
    y_range: (-45.0, 45.0),
    y_decades: false,
    nx: 120,
    ny: 120,
    sub: 3,
    point: |x, y, s| Some(pitch_roll(0.0, x, y, s)),
    others: "645 km above the WGS 84 equatorial radius, circular, i0 97.98 deg, \
             g0 45 deg, yaw 0, no rates; n_px = -30 000, 0, 30 000 over the sub-samples",
    missing: MISSING,
};

/// Map F: pitch rate x roll rate.
const RATES: Spec<EarthCase> = Spec {
    key: "general-rates",
    letter: "F",
    title: "pitch rate x roll rate",
    x_label: "pitch rate (deg/s)",
    y_label: "roll rate (deg/s)",
    x_range: (-2.0, 2.0),
    y_range: (-2.0, 2.0),
    y_decades: false,
    nx: 120,
    ny: 120,
    sub: 6,
    point: rates,
    others: "645 km, circular, i0 97.98 deg, g0 45 deg; n_px = -30 000, 0, 30 000 at \
             roll = pitch = yaw = 0, then at roll 20, pitch -10 deg; yaw rate 0",
    missing: MISSING,
};

pub const GMAPS: [Spec<EarthCase>; 5] = [
    PITCH_ROLL,
    Spec {
        key: "general-pitch-roll-yaw30",
        letter: "D'",
        title: "pitch x roll, yaw 30 deg",
        nx: 90,
        ny: 90,
        point: |x, y, s| Some(pitch_roll(30.0, x, y, s)),
        others: "as map D with yaw 30 deg",
        ..PITCH_ROLL
    },
    Spec {
        key: "general-altitude-limb",
        letter: "E",
        title: "altitude x limb margin",
        x_label: "altitude (km)",
        y_label: "limb margin (deg)",
        x_range: (200.0, 2000.0),
        y_range: (-2.0, 1.0),
        y_decades: true,
        nx: 96,
        ny: 96,
        sub: 6,
        point: altitude_limb,
        others: "circular, i0 97.98 deg; n_px = +/-30 000 (35.1 deg field angle) on the side \
                 of the roll, which is solved for the margin; pitch 0, 20, -30 deg; (yaw, g0) \
                 (0, 45) and (30, 135) deg, cycling over the sub-samples; no rates",
        missing: MISSING,
    },
    RATES,
    Spec {
        key: "general-rates-zoom",
        letter: "F'",
        title: "pitch rate x roll rate, the cancellation",
        x_range: (0.2, 1.0),
        y_range: (-0.2, 0.2),
        nx: 100,
        ny: 50,
        others: "as map F",
        ..RATES
    },
];

/// A real-Earth backend under test against `EarthReference`: the inputs it takes, and
/// its motion widened to f64. Both backends share one path ([`evaluate`], [`GCell`]);
/// each keeps its own checks and wording.
pub trait Tested: Clone + Copy + std::fmt::Debug + Default + Send + 'static {
    /// The template keys of its figures: `{KEY}.*` for all the maps together,
    /// `{MAP_KEY}<letter>.*` for each map.
    const KEY: &'static str;
    const MAP_KEY: &'static str;
    /// The columns of its table, after the map's name.
    const COLUMNS: &'static [Column<GCell<Self>>];
    /// The inputs the reference takes for the case's `g`: the backend's own inputs,
    /// widened back to f64 where it rounds them itself on the way in.
    fn inputs(g: &EarthGeometry<f64>) -> Result<EarthGeometry<f64>, ModelError>;
    /// The backend's motion at those inputs, widened to f64.
    const MOTION: Motion;
    /// What [`describe`] adds after the place.
    fn note(o: &GOutcome) -> String;
    /// Each stated bound a cell (or an aggregate) breaks, one line each.
    fn broken(c: &GCell<Self>) -> Vec<String>;
    /// The line `cargo xtask stability` prints under its table, for all the maps.
    fn bound_line(all: &GCell<Self>) -> String;
}

/// `GENERAL_F32`, the attitude rounded to f32 by the backend itself; the reference at
/// the inputs as given.
#[derive(Clone, Copy, Debug, Default)]
pub struct F32;

impl Tested for F32 {
    const KEY: &'static str = "G";
    const MAP_KEY: &'static str = "";
    const COLUMNS: &'static [Column<GCell<Self>>] = &COLUMNS;
    const MOTION: Motion = GENERAL_F32_MOTION;

    fn inputs(g: &EarthGeometry<f64>) -> Result<EarthGeometry<f64>, ModelError> {
        Ok(*g)
    }

    fn note(o: &GOutcome) -> String {
        format!(", v1 {} m/s", e2(o.v1))
    }

    /// A case at least [`MIN_MARGIN_DEG`] inside the limb that breaks
    /// err <= EARTH_F32_KAPPA_C kappa u32, or one the f32 backend refused although the
    /// reference accepts it.
    fn broken(c: &GCell<F32>) -> Vec<String> {
        let mut bad = Vec::new();
        if c.ratio.max > EARTH_F32_KAPPA_C {
            let at = c.ratio.at.map(|(c, o)| describe::<F32>(&c, &o));
            bad.push(format!(
                "general f32 err/(kappa u) = {:.3} > {EARTH_F32_KAPPA_C} at {}",
                c.ratio.max,
                at.unwrap_or_default()
            ));
        }
        if c.refused > 0 {
            bad.push(format!(
                "{} case(s) the reference accepts refused by GENERAL_F32",
                c.refused
            ));
        }
        bad
    }

    fn bound_line(all: &GCell<F32>) -> String {
        format!(
            "general model (>= {MIN_MARGIN_DEG} deg inside the limb): max err/(kappa u32) {:.2}, \
             bound {EARTH_F32_KAPPA_C}; max kappa {}; max f32 err {} (line period {})",
            all.ratio.max,
            sig(all.kappa.max),
            e2(all.err.max),
            e2(all.err_v1.max)
        )
    }
}

/// What one case measures.
#[derive(Clone, Copy, Debug, Default)]
pub struct GOutcome {
    /// |dv| / |v| of the backend (at its own inputs) against the reference.
    pub err: f64,
    /// |dv1| / |v1|: the line period's relative error (period = pixel / |v1|).
    pub err_v1: f64,
    pub kappa: f64,
    pub margin_rad: f64,
    /// |v| and v1 of the reference (m/s).
    pub v: f64,
    pub v1: f64,
}

impl GOutcome {
    pub fn ratio(&self) -> f64 {
        self.err / (self.kappa * U_F32)
    }

    /// The fixed backend's target at this case's limb margin (the maps stop at 0.01 deg).
    pub fn target(&self) -> f64 {
        if self.margin_rad.to_degrees() >= 1.0 {
            FAR_TARGET
        } else {
            NEAR_TARGET
        }
    }
}

/// Why a case has no outcome.
pub enum GSkip {
    /// Beyond the limb or within [`MIN_MARGIN_DEG`] of it, or the reference refuses it.
    Outside,
    /// The reference accepts and the backend refuses, with its typed error.
    Refused(ModelError),
    /// An Ok that is not finite (a defect: it must never happen).
    NonFinite,
}

pub fn evaluate<B: Tested>(c: &EarthCase) -> Result<GOutcome, GSkip> {
    let margin = match limb_margin_rad(&c.geometry, &c.camera, c.n_px) {
        // Also NaN.
        Ok(m) if m.to_degrees() >= MIN_MARGIN_DEG => m,
        _ => return Err(GSkip::Outside),
    };
    let g64 = B::inputs(&c.geometry).map_err(GSkip::Refused)?;
    let r = EarthReference
        .evaluate(&c.camera, &g64, c.n_px)
        .map_err(|_| GSkip::Outside)?;
    let m = (B::MOTION)(&c.camera, &g64, c.n_px).map_err(GSkip::Refused)?;
    if !(m.v1_mps.is_finite() && m.v2_mps.is_finite()) {
        return Err(GSkip::NonFinite);
    }
    let kappa = earth_kappa(&c.camera, &g64, c.n_px).map_err(|_| GSkip::Outside)?;
    let (d1, d2) = (m.v1_mps - r.v1_mps, m.v2_mps - r.v2_mps);
    let v = libm::hypot(r.v1_mps, r.v2_mps);
    Ok(GOutcome {
        err: libm::hypot(d1, d2) / v,
        err_v1: d1.abs() / r.v1_mps.abs(),
        kappa,
        margin_rad: margin,
        v,
        v1: r.v1_mps,
    })
}

/// A case of a general map: where, and what it measured.
pub type GSample = (EarthCase, GOutcome);

/// Maxima over a cell's (or a set of cells') cases, with the case behind each: what
/// either backend's section of the document quotes.
#[derive(Clone, Debug, Default)]
pub struct GCell<B = F32> {
    pub n: u64,
    /// Typed refusals of cases the reference accepts, and the first error seen.
    pub refused: u64,
    pub refused_by: Option<ModelError>,
    /// Ok results that are not finite (must stay 0).
    pub non_finite: u64,
    pub err: Worst<GSample>,
    pub err_v1: Worst<GSample>,
    pub kappa: Worst<GSample>,
    pub kappa_min: f64,
    /// err/(kappa u32).
    pub ratio: Worst<GSample>,
    pub min_margin_rad: f64,
    /// Cases with err above EARTH_F32_REL_TOLERANCE (2e-6), and the smallest kappa among them.
    pub over_tol: u64,
    pub over_tol_kappa_min: f64,
    /// The largest error among the cases with kappa <= EARTH_F32_KAPPA_LIMIT and at least
    /// 1 deg inside the limb (where the 2e-6 bound is stated).
    pub tame: Worst<GSample>,
    /// The largest |dv1|/|v1| where the drift is under 60 deg (|v1| >= |v|/2).
    pub steady: Worst<GSample>,
    /// The largest error at least 1 deg inside the limb, and from 0.01 to 1 deg.
    pub far: Worst<GSample>,
    pub near: Worst<GSample>,
    /// The largest err / [`GOutcome::target`] over the checked cases (every case from
    /// 0.01 to 1 deg, those with kappa <= 30 from 1 deg outward).
    pub of_target_checked: Worst<GSample>,
    /// Cases over their band's target, and the smallest kappa among them.
    pub over: u64,
    pub over_kappa_min: f64,
    backend: std::marker::PhantomData<B>,
}

impl<B: Tested> grid::Cell for GCell<B> {
    type Point = EarthCase;

    fn empty() -> Self {
        GCell {
            kappa_min: f64::INFINITY,
            min_margin_rad: f64::INFINITY,
            over_tol_kappa_min: f64::INFINITY,
            over_kappa_min: f64::INFINITY,
            ..GCell::default()
        }
    }

    fn sample(&mut self, c: &EarthCase) {
        match evaluate::<B>(c) {
            Ok(o) => self.add(c, &o),
            Err(GSkip::Outside) => {}
            Err(GSkip::Refused(e)) => {
                self.refused += 1;
                self.refused_by = self.refused_by.or(Some(e));
            }
            Err(GSkip::NonFinite) => self.non_finite += 1,
        }
    }

    fn n(&self) -> u64 {
        self.n
    }

    fn merge(&mut self, o: &Self) {
        self.n += o.n;
        self.refused += o.refused;
        self.refused_by = self.refused_by.or(o.refused_by);
        self.non_finite += o.non_finite;
        self.kappa_min = self.kappa_min.min(o.kappa_min);
        self.min_margin_rad = self.min_margin_rad.min(o.min_margin_rad);
        self.over_tol += o.over_tol;
        self.over_tol_kappa_min = self.over_tol_kappa_min.min(o.over_tol_kappa_min);
        self.over += o.over;
        self.over_kappa_min = self.over_kappa_min.min(o.over_kappa_min);
        for (s, o) in [
            (&mut self.tame, &o.tame),
            (&mut self.steady, &o.steady),
            (&mut self.far, &o.far),
            (&mut self.near, &o.near),
            (&mut self.of_target_checked, &o.of_target_checked),
        ] {
            s.merge_raise(o);
        }
        for (s, o) in [
            (&mut self.ratio, &o.ratio),
            (&mut self.kappa, &o.kappa),
            (&mut self.err, &o.err),
            (&mut self.err_v1, &o.err_v1),
        ] {
            s.merge(o);
        }
    }

    fn broken(&self) -> Vec<String> {
        B::broken(self)
    }
}

impl<B: Tested> GCell<B> {
    fn add(&mut self, c: &EarthCase, o: &GOutcome) {
        self.n += 1;
        self.kappa_min = self.kappa_min.min(o.kappa);
        self.min_margin_rad = self.min_margin_rad.min(o.margin_rad);
        if o.err > EARTH_F32_REL_TOLERANCE {
            self.over_tol += 1;
            self.over_tol_kappa_min = self.over_tol_kappa_min.min(o.kappa);
        }
        let of_target = o.err / o.target();
        if of_target > 1.0 {
            self.over += 1;
            self.over_kappa_min = self.over_kappa_min.min(o.kappa);
        }
        let w = (*c, *o);
        let (tame, far) = (
            o.kappa <= EARTH_F32_KAPPA_LIMIT,
            o.margin_rad.to_degrees() >= 1.0,
        );
        if far {
            self.far.raise(o.err, w);
            if tame {
                self.tame.raise(o.err, w);
            }
        } else {
            self.near.raise(o.err, w);
        }
        if tame || !far {
            self.of_target_checked.raise(of_target, w);
        }
        if o.v1.abs() >= 0.5 * o.v {
            self.steady.raise(o.err_v1, w);
        }
        self.ratio.offer(o.ratio(), w);
        self.kappa.offer(o.kappa, w);
        self.err.offer(o.err, w);
        self.err_v1.offer(o.err_v1, w);
    }
}

/// A swept map of the general model for backend `B`.
pub type GMap<B = F32> = grid::Map<GCell<B>>;

/// Where a case is, its limb margin and image speed, then the backend's note.
pub fn describe<B: Tested>(c: &EarthCase, o: &GOutcome) -> String {
    let a = &c.geometry.attitude;
    let r = c.geometry.state.position_m;
    let h_km = (norm(r) - c.geometry.ellipsoid.a_m) / 1e3;
    let mut s = format!(
        "H {h_km:.0} km, roll {:.2} deg, pitch {:.2} deg, yaw {:.0} deg",
        a.roll_rad.to_degrees(),
        a.pitch_rad.to_degrees(),
        a.yaw_rad.to_degrees(),
    );
    if a.roll_rate_rad_s != 0.0 || a.pitch_rate_rad_s != 0.0 {
        s.push_str(&format!(
            ", roll rate {:.3} deg/s, pitch rate {:.3} deg/s",
            a.roll_rate_rad_s.to_degrees(),
            a.pitch_rate_rad_s.to_degrees()
        ));
    }
    s.push_str(&format!(
        ", n_px {:.0}; limb margin {} deg, |v| {} m/s{}",
        c.n_px,
        sig(o.margin_rad.to_degrees()),
        e2(o.v),
        B::note(o)
    ));
    s
}

/// Writes the map's three PNGs (kappa, f32 error, err/(kappa u)) into `dir`.
pub fn write_pngs(m: &GMap, dir: &Path) -> Result<()> {
    let kmax = m
        .cells
        .iter()
        .filter(|c| c.n > 0)
        .fold(1.0f64, |a, c| a.max(c.kappa.max));
    let panels: [Panel<GCell<F32>>; 3] = [
        Panel {
            suffix: "kappa",
            title: "condition number kappa",
            z_label: "kappa",
            z_range: (0.0, lg(kmax).ceil().max(2.0)),
            linear: false,
            value: |c| lg(c.kappa.max),
            bound: Some(EARTH_F32_KAPPA_LIMIT),
        },
        Panel {
            suffix: "err-f32",
            title: "f32 error |dv|/|v|",
            z_label: "rel. error",
            z_range: (-9.0, -3.0),
            linear: false,
            value: |c| lg(c.err.max),
            bound: Some(EARTH_F32_REL_TOLERANCE),
        },
        Panel {
            suffix: "ratio-f32",
            title: "f32: err / (kappa u)",
            z_label: "err / (kappa u)",
            z_range: (-3.0, 1.0),
            linear: false,
            value: |c| lg(c.ratio.max),
            bound: Some(EARTH_F32_KAPPA_C),
        },
    ];
    m.write_pngs(&panels, dir)
}

/// A 96-stage segment's line-period mismatch budget, 0.351 / 96 (`docs/derivation.md`).
pub const SEGMENT_BUDGET: f64 = 0.351 / 96.0;

/// `GENERAL_F32`'s table.
const COLUMNS: [Column<GCell>; 10] = [
    ("cases", |a| a.n.to_string()),
    ("kappa min - max", |a| sig_range(a.kappa_min, a.kappa.max)),
    ("f32 err \\|dv\\|/\\|v\\|", |a| e2(a.err.max)),
    ("f32 err v1 (line period)", |a| e2(a.err_v1.max)),
    ("err, kappa <= 30 and >= 1 deg in", |a| or_dash(&a.tame)),
    ("cases err > 2e-6", |a| a.over_tol.to_string()),
    ("smallest kappa with err > 2e-6", |a| match a.over_tol {
        0 => "-".into(),
        _ => sig(a.over_tol_kappa_min),
    }),
    ("max err/(kappa u)", |a| f2(a.ratio.max)),
    ("min limb margin (deg)", |a| {
        sig(a.min_margin_rad.to_degrees())
    }),
    ("refused", |a| a.refused.to_string()),
];

/// The largest value of `w`, or "-" where no case raised it.
pub fn or_dash(w: &Worst<GSample>) -> String {
    w.at.map_or("-".into(), |_| e2(w.max))
}

/// Every value the document quotes about backend `B`'s maps, by template key:
/// `{B::KEY}.*` for all the maps together (with `.secs`, `.table`, `.bound_line`), and
/// `{B::MAP_KEY}<letter>.*` for each map (D' as Dy) and map E's table by limb margin.
pub fn figures<B: Tested>(maps: &[GMap<B>], secs: f64) -> BTreeMap<String, String> {
    let mut v = BTreeMap::new();
    let mut put = |k: &str, s: String| {
        v.insert(k.to_string(), s);
    };
    let (key, mk) = (B::KEY, B::MAP_KEY);
    put(&format!("{key}.secs"), format!("{secs:.1}"));
    let mut rows = Vec::new();
    for m in maps {
        let a = m.aggregate(|_, _| true);
        let l = format!("{mk}{}", m.spec.letter.replace('\'', "y"));
        put(&format!("{l}.grid"), m.grid_text(a.n));
        put(&format!("{l}.others"), m.spec.others.into());
        cell_figures(&mut put, &l, &a);
        rows.push((format!("{}: {}", m.spec.letter, m.spec.title), a));
    }
    let all = grid::merged(maps);
    cell_figures(&mut put, key, &all);
    put(&format!("{key}.bound_line"), B::bound_line(&all));
    rows.push(("all general maps".into(), all));
    put(
        &format!("{key}.table"),
        grid::table("map", B::COLUMNS, &rows),
    );
    // Map E by limb-margin band (log10 of the margin in deg, the map's y).
    if let Some(e) = maps.iter().find(|m| m.spec.letter == "E") {
        let bands = [
            (-2.0, -1.0, "0.01 - 0.1 deg"),
            (-1.0, 0.0, "0.1 - 1 deg"),
            (0.0, 1.0, "1 - 10 deg"),
        ];
        let band = |&(lo, hi, name): &(f64, f64, &str)| {
            (name.to_string(), e.aggregate(|_, y| y >= lo && y < hi))
        };
        let rows: Vec<_> = bands.iter().map(band).collect();
        let table = grid::table("limb margin", B::COLUMNS, &rows);
        put(&format!("{mk}E.band_table"), table);
    }
    v
}

/// What only `GENERAL_F32`'s section quotes: the bound and the budget, and the parts of
/// maps D, E and F it discusses.
pub fn f32_figures(maps: &[GMap]) -> BTreeMap<String, String> {
    let mut v = BTreeMap::new();
    let mut put = |k: &str, s: String| {
        v.insert(k.to_string(), s);
    };
    put("G.c", format!("{EARTH_F32_KAPPA_C}"));
    put("G.min_margin", format!("{MIN_MARGIN_DEG}"));
    put("G.err_tame", format!("{:.3e}", grid::merged(maps).tame.max));
    // The line period against a 96-stage segment's budget.
    put("G.budget", format!("{SEGMENT_BUDGET:.2e}"));
    let kappa_at = |err: f64| err / (EARTH_F32_KAPPA_C * U_F32);
    put("G.budget_kappa", sig(kappa_at(SEGMENT_BUDGET)));
    put(
        "G.tol_kappa",
        format!("{:.0}", kappa_at(EARTH_F32_REL_TOLERANCE)),
    );
    // Map E by distance to the limb: at least 1 deg, under 1 deg, 0.01 - 0.1 deg.
    if let Some(e) = maps.iter().find(|m| m.spec.letter == "E") {
        cell_figures(&mut put, "E.ge1deg", &e.aggregate(|_, y| y >= 0.0));
        cell_figures(&mut put, "E.lt1deg", &e.aggregate(|_, y| y < 0.0));
        cell_figures(&mut put, "E.lt0.1deg", &e.aggregate(|_, y| y < -1.0));
        // kappa x margin over each cell's largest-kappa case: kappa ~ 1/q ~ 1/sqrt(margin).
        let km = e.cells.iter().filter_map(|c| c.kappa.at);
        let (lo, hi) = km
            .map(|(_, o)| o.kappa * o.margin_rad.sqrt())
            .fold((f64::INFINITY, 0.0f64), |(l, h), x| (l.min(x), h.max(x)));
        put("E.ksqrtm", sig_range(lo, hi));
    }
    // Maps D: the cells at least 1 deg inside the limb.
    for l in ["D", "D'"] {
        if let Some(d) = maps.iter().find(|m| m.spec.letter == l) {
            let mut a = GCell::empty();
            for c in &d.cells {
                if c.n > 0 && c.min_margin_rad.to_degrees() >= 1.0 {
                    a.merge(c);
                }
            }
            cell_figures(&mut put, &format!("{}.ge1deg", l.replace('\'', "y")), &a);
        }
    }
    // Map F: the fraction of the rate square where kappa > 30 and where err > 2e-6.
    if let Some(f) = maps.iter().find(|m| m.spec.letter == "F") {
        let n = f.cells.iter().filter(|c| c.n > 0).count() as f64;
        let frac = |p: &dyn Fn(&GCell) -> bool| {
            let k = f.cells.iter().filter(|c| c.n > 0 && p(c)).count();
            format!("{:.1}", 100.0 * k as f64 / n)
        };
        put(
            "F.pct_stiff",
            frac(&|c| c.kappa.max > EARTH_F32_KAPPA_LIMIT),
        );
        put("F.pct_over", frac(&|c| c.over_tol > 0));
        // The reference |v| at zero rates, nadir pixel, for scale.
        let k0 = case(H0_KM, I0_SSO_DEG, G0_DEG, Attitude::default(), 0.0);
        if let Ok(o) = evaluate::<F32>(&k0) {
            put("F.v0", e2(o.v));
            put("F.v1_0", e2(o.v1));
            put(
                "F.period0_ms",
                format!("{:.3}", 1e3 * CAMERA.pixel_m / o.v1.abs()),
            );
            put("F.kappa0", sig(o.kappa));
            // The pitch rate whose rotational term f w matches |v| at nadir.
            put("F.cancel_rate", f2((o.v / CAMERA.focal_m).to_degrees()));
        }
    }
    v
}

/// The values the document may quote about an aggregate of cases, as (`{p}.<what>`,
/// text), and about the case behind each of its maxima ([`case_figures`]). Every
/// aggregate gets the same set, so that the template can quote any of them the same
/// way; the keys it does not use are ignored.
fn cell_figures<B: Tested>(put: &mut impl FnMut(&str, String), p: &str, a: &GCell<B>) {
    let mut put = |what: &str, s: String| put(&format!("{p}.{what}"), s);
    put("samples", a.n.to_string());
    put("ratio", f2(a.ratio.max));
    put("kappa_min", sig(a.kappa_min));
    put("kappa_max", sig(a.kappa.max));
    put("kappa_range", sig_range(a.kappa_min, a.kappa.max));
    put("err", e2(a.err.max));
    put("err_v1", e2(a.err_v1.max));
    put("tame", e2(a.tame.max));
    put("near", e2(a.near.max));
    put("steady", e2(a.steady.max));
    // Percentages of a 96-stage segment's line-period budget.
    put("budget_pct", f2(100.0 * a.err_v1.max / SEGMENT_BUDGET));
    put("steady_pct", f2(100.0 * a.steady.max / SEGMENT_BUDGET));
    put("over_tol", a.over_tol.to_string());
    put("over_tol_kappa", sig(a.over_tol_kappa_min));
    put("over", a.over.to_string());
    put("over_kappa", sig(a.over_kappa_min));
    put("of_target", format!("{:.3}", a.of_target_checked.max));
    for (what, w) in [
        ("worst", &a.ratio),
        ("max_kappa", &a.kappa),
        ("max_err", &a.err),
        ("max_err_v1", &a.err_v1),
        ("tame", &a.tame),
        ("steady", &a.steady),
        ("near", &a.near),
    ] {
        case_figures::<B>(&mut put, what, w);
    }
}

/// The values the document may quote about one case (a map's worst, largest-kappa, ...),
/// as (`{prefix}.<what>`, text).
fn case_figures<B: Tested>(put: &mut impl FnMut(&str, String), prefix: &str, w: &Worst<GSample>) {
    let Some((c, o)) = &w.at else { return };
    put(&format!("{prefix}.at"), describe::<B>(c, o));
    put(&format!("{prefix}.kappa"), sig(o.kappa));
    put(&format!("{prefix}.err"), e2(o.err));
    put(&format!("{prefix}.v1"), e2(o.v1));
    let period_ms = 1e3 * CAMERA.pixel_m / o.v1.abs();
    put(&format!("{prefix}.period_ms"), sig(period_ms));
}
