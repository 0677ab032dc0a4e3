//! The general model's maps for the real-Earth fixed-point backend: `EARTH_FIXED`
//! against `EarthReference` over the same grids as `GENERAL_F32` (`general::GMAPS`),
//! with the targets by distance to the limb: 2e-5 from 0.01 deg inside the limb
//! at every case, and 2e-6 from 1 deg outward where the problem's condition number is
//! at most `EARTH_F32_KAPPA_LIMIT`, the qualifier `docs/fixed-point.md` argues it under
//! (beyond it the problem amplifies the 2^-34 rad/s roundings of the rates). Near the
//! limb kappa exceeds 30 everywhere (it grows like 1/q), so there the target is held
//! without the qualifier.
//!
//! The backend takes the attitude rounded to I24F40 (`geometry_from_f64`); the reference
//! is evaluated at those rounded inputs, widened back, as `tests/earth_fixed.rs` does.
//! Every refusal is a typed error and is counted; none is silently skipped.

use anyhow::Result;
use core_math::accuracy::{earth_kappa, EARTH_F32_KAPPA_LIMIT};
use core_math::earth::fixed::{geometry_from_f64, motion_to_f64};
use core_math::earth::limb_margin_rad;
use core_math::sample::EarthCase;
use core_math::{Backend, EarthReference, ModelError, EARTH_FIXED};

use std::path::Path;

use crate::markdown::{e2, sig, table};

use super::doc::lg;
use super::general::MIN_MARGIN_DEG;
use super::grid::{self, Cell as _, Panel, Worst};

/// The targets (relative |dv| / |v|) from 1 deg and from 0.01 deg inside the limb.
pub const FAR_TARGET: f64 = 2e-6;
pub const NEAR_TARGET: f64 = 2e-5;

/// What one accepted case measures.
#[derive(Clone, Copy, Debug, Default)]
pub struct FOutcome {
    /// |dv| / |v| of EARTH_FIXED against the reference at the same (I24F40) inputs.
    pub err: f64,
    /// |dv1| / |v1|.
    pub err_v1: f64,
    pub kappa: f64,
    pub margin_rad: f64,
    /// |v| of the reference (m/s).
    pub v: f64,
}

impl FOutcome {
    /// The target at this case's limb margin (the maps stop at 0.01 deg).
    pub fn target(&self) -> f64 {
        if self.margin_rad.to_degrees() >= 1.0 {
            FAR_TARGET
        } else {
            NEAR_TARGET
        }
    }
}

/// What a case gives: measured, out of the maps (beyond or within 0.01 deg of the limb,
/// or the reference refuses), refused by the backend with a typed error, or an Ok that
/// is not finite (a defect: it must never happen).
pub enum FResult {
    Ok(FOutcome),
    Outside,
    Refused(ModelError),
    NonFinite,
}

pub fn evaluate(c: &EarthCase) -> FResult {
    let margin = match limb_margin_rad(&c.geometry, &c.camera, c.n_px) {
        Ok(m) if m.to_degrees() >= MIN_MARGIN_DEG => m,
        _ => return FResult::Outside,
    };
    let g = match geometry_from_f64(&c.geometry) {
        Ok(g) => g,
        Err(e) => return FResult::Refused(e),
    };
    let g64 = g.to_f64();
    let Ok(r) = EarthReference.evaluate(&c.camera, &g64, c.n_px) else {
        return FResult::Outside;
    };
    let m = match EARTH_FIXED.evaluate(&c.camera, &g, c.n_px) {
        Ok(m) => motion_to_f64(&m),
        Err(e) => return FResult::Refused(e),
    };
    if !(m.v1_mps.is_finite() && m.v2_mps.is_finite()) {
        return FResult::NonFinite;
    }
    let Ok(kappa) = earth_kappa(&c.camera, &g64, c.n_px) else {
        return FResult::Outside;
    };
    let (d1, d2) = (m.v1_mps - r.v1_mps, m.v2_mps - r.v2_mps);
    let v = libm::hypot(r.v1_mps, r.v2_mps);
    FResult::Ok(FOutcome {
        err: libm::hypot(d1, d2) / v,
        err_v1: d1.abs() / r.v1_mps.abs(),
        kappa,
        margin_rad: margin,
        v,
    })
}

/// A case of a fixed map: where, and what it measured.
pub type FSample = (EarthCase, FOutcome);

/// Maxima over a cell's (or a set of cells') cases, with the case behind each.
#[derive(Clone, Debug, Default)]
pub struct FCell {
    pub n: u64,
    /// Typed refusals of cases the reference accepts, and the first error seen.
    pub refused: u64,
    pub refused_by: Option<ModelError>,
    /// Ok results that are not finite (must stay 0).
    pub non_finite: u64,
    pub err: Worst<FSample>,
    pub err_v1: Worst<FSample>,
    /// The largest error at least 1 deg inside the limb, and from 0.01 to 1 deg.
    pub far: Worst<FSample>,
    pub near: Worst<FSample>,
    /// The first where kappa <= EARTH_F32_KAPPA_LIMIT, where its target is stated.
    pub far_tame: Worst<FSample>,
    /// err / target: the largest over all cases, and over the checked ones (every case
    /// from 0.01 to 1 deg, those with kappa <= 30 from 1 deg outward).
    pub of_target: Worst<FSample>,
    pub of_target_checked: Worst<FSample>,
    /// Cases over their band's target, and the smallest kappa among them.
    pub over: u64,
    pub over_kappa_min: f64,
    pub min_margin_rad: f64,
}

impl grid::Cell for FCell {
    type Point = EarthCase;

    fn empty() -> Self {
        FCell {
            over_kappa_min: f64::INFINITY,
            min_margin_rad: f64::INFINITY,
            ..FCell::default()
        }
    }

    fn sample(&mut self, c: &EarthCase) {
        match evaluate(c) {
            FResult::Ok(o) => self.add(c, &o),
            FResult::Outside => {}
            FResult::Refused(e) => {
                self.refused += 1;
                self.refused_by = self.refused_by.or(Some(e));
            }
            FResult::NonFinite => self.non_finite += 1,
        }
    }

    fn n(&self) -> u64 {
        self.n
    }

    fn merge(&mut self, o: &FCell) {
        self.n += o.n;
        self.refused += o.refused;
        self.refused_by = self.refused_by.or(o.refused_by);
        self.non_finite += o.non_finite;
        self.over += o.over;
        self.over_kappa_min = self.over_kappa_min.min(o.over_kappa_min);
        self.min_margin_rad = self.min_margin_rad.min(o.min_margin_rad);
        self.err.merge(&o.err);
        self.err_v1.merge(&o.err_v1);
        self.of_target.merge(&o.of_target);
        self.far.merge_raise(&o.far);
        self.near.merge_raise(&o.near);
        self.far_tame.merge_raise(&o.far_tame);
        self.of_target_checked.merge_raise(&o.of_target_checked);
    }

    /// A checked case over its band's target, or a non-finite Ok. Refusals are
    /// typed errors, counted and reported, not failures: the backend's envelope
    /// (`docs/fixed-point.md`) is narrower than the reference's.
    fn broken(&self) -> Vec<String> {
        let mut bad = Vec::new();
        if self.of_target_checked.max > 1.0 {
            let at = self.of_target_checked.at.map(|(c, o)| describe(&c, &o));
            bad.push(format!(
                "EARTH_FIXED err/target = {:.3} > 1 at {}",
                self.of_target_checked.max,
                at.unwrap_or_default()
            ));
        }
        if self.non_finite > 0 {
            bad.push(format!(
                "{} non-finite Ok result(s) of EARTH_FIXED",
                self.non_finite
            ));
        }
        bad
    }
}

impl FCell {
    fn add(&mut self, c: &EarthCase, o: &FOutcome) {
        self.n += 1;
        self.min_margin_rad = self.min_margin_rad.min(o.margin_rad);
        let w = (*c, *o);
        let tame = o.kappa <= EARTH_F32_KAPPA_LIMIT;
        let of_target = o.err / o.target();
        if of_target > 1.0 {
            self.over += 1;
            self.over_kappa_min = self.over_kappa_min.min(o.kappa);
        }
        let far = o.margin_rad.to_degrees() >= 1.0;
        if far {
            self.far.raise(o.err, w);
            if tame {
                self.far_tame.raise(o.err, w);
            }
        } else {
            self.near.raise(o.err, w);
        }
        if tame || !far {
            self.of_target_checked.raise(of_target, w);
        }
        self.of_target.offer(of_target, w);
        self.err.offer(o.err, w);
        self.err_v1.offer(o.err_v1, w);
    }
}

/// A swept map of the fixed backend.
pub type FMap = grid::Map<FCell>;

/// Where a case is.
pub fn describe(c: &EarthCase, o: &FOutcome) -> String {
    let mut s = super::general::case_place(c, o.margin_rad, o.v);
    s.push_str(&format!(", kappa {}", sig(o.kappa)));
    s
}

/// Writes the map's PNG of the fixed error into `dir`.
pub fn write_pngs(m: &FMap, dir: &Path) -> Result<()> {
    let panels: [Panel<FCell>; 1] = [Panel {
        suffix: "err-fixed",
        title: "EARTH_FIXED error |dv|/|v|",
        z_label: "rel. error",
        z_range: (-9.0, -3.0),
        linear: false,
        value: |c| lg(c.err.max),
        bound: Some(FAR_TARGET),
    }];
    m.write_pngs(&panels, dir)
}

const TABLE_HEADER: [&str; 10] = [
    "map",
    "cases",
    "max err \\|dv\\|/\\|v\\|",
    "err v1",
    "err >= 1 deg in (target 2e-6)",
    "same, kappa <= 30",
    "err 0.01 - 1 deg (target 2e-5)",
    "min limb margin (deg)",
    "cases over target (smallest kappa)",
    "refused (first error)",
];

fn or_dash(w: &Worst<FSample>) -> String {
    if w.at.is_some() {
        e2(w.max)
    } else {
        "-".into()
    }
}

fn row(name: &str, a: &FCell) -> Vec<String> {
    vec![
        name.to_string(),
        a.n.to_string(),
        e2(a.err.max),
        e2(a.err_v1.max),
        or_dash(&a.far),
        or_dash(&a.far_tame),
        or_dash(&a.near),
        sig(a.min_margin_rad.to_degrees()),
        if a.over > 0 {
            format!("{} ({})", a.over, sig(a.over_kappa_min))
        } else {
            "0".into()
        },
        match a.refused_by {
            Some(e) => format!("{} ({e:?})", a.refused),
            None => a.refused.to_string(),
        },
    ]
}

/// Every value the document's fixed-backend section quotes, by template key (`X.*`).
pub fn figures(maps: &[FMap], secs: f64) -> std::collections::BTreeMap<String, String> {
    let mut v = std::collections::BTreeMap::new();
    let mut put = |k: &str, s: String| {
        v.insert(k.to_string(), s);
    };
    put("X.secs", format!("{secs:.1}"));
    let mut rows = Vec::new();
    let mut all = FCell::empty();
    for m in maps {
        let a = m.aggregate(|_, _| true);
        let l = m.spec.letter.replace('\'', "y");
        let mut put = |what: &str, s: String| put(&format!("X{l}.{what}"), s);
        put("err", e2(a.err.max));
        put("refused", a.refused.to_string());
        if let Some((c, o)) = &a.err.at {
            put("max_err.at", describe(c, o));
        }
        rows.push(row(&format!("{}: {}", m.spec.letter, m.spec.title), &a));
        all.merge(&a);
    }
    rows.push(row("all general maps", &all));
    put("X.samples", all.n.to_string());
    put("X.refused", all.refused.to_string());
    put("X.err", e2(all.err.max));
    put("X.err_v1", e2(all.err_v1.max));
    put("X.far", e2(all.far.max));
    put("X.far_tame", e2(all.far_tame.max));
    put("X.near", e2(all.near.max));
    put("X.over", all.over.to_string());
    put("X.over_kappa", sig(all.over_kappa_min));
    put(
        "X.of_target_checked",
        format!("{:.3}", all.of_target_checked.max),
    );
    for (what, w) in [
        ("max_err", &all.err),
        ("far", &all.far),
        ("far_tame", &all.far_tame),
        ("near", &all.near),
        ("of_target", &all.of_target),
    ] {
        if let Some((c, o)) = &w.at {
            put(&format!("X.{what}.at"), describe(c, o));
            put(&format!("X.{what}.err"), e2(o.err));
            put(&format!("X.{what}.kappa"), sig(o.kappa));
        }
    }
    put("X.table", table(&TABLE_HEADER, &rows));
    put(
        "X.bound_line",
        format!(
            "EARTH_FIXED (>= {MIN_MARGIN_DEG} deg inside the limb): max err/target {:.3} \
             (2e-5 from 0.01 deg; 2e-6 from 1 deg where kappa <= {EARTH_F32_KAPPA_LIMIT}); \
             max err {}; {} case(s) over the bare target, smallest kappa {}; {} refused",
            all.of_target_checked.max,
            e2(all.err.max),
            all.over,
            sig(all.over_kappa_min),
            all.refused
        ),
    );
    // Map E by limb-margin band.
    if let Some(e) = maps.iter().find(|m| m.spec.letter == "E") {
        put(
            "XE.band_table",
            super::general::band_table(TABLE_HEADER, |name, lo, hi| {
                row(name, &e.aggregate(|_, y| y >= lo && y < hi))
            }),
        );
    }
    v
}
