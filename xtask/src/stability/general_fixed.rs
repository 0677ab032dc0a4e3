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
use core_math::accuracy::EARTH_F32_KAPPA_LIMIT;
use core_math::earth::fixed::geometry_from_f64;
use core_math::earth::EarthGeometry;
use core_math::ModelError;

use std::path::Path;

use crate::accuracy::{Motion, EARTH_FIXED_MOTION};
use crate::markdown::{e2, sig};

use super::doc::lg;
use super::general::{describe, or_dash, GCell, GMap, GOutcome, Tested, MIN_MARGIN_DEG};
use super::grid::{Column, Panel};

/// The targets (relative |dv| / |v|) from 1 deg and from 0.01 deg inside the limb.
pub const FAR_TARGET: f64 = 2e-6;
pub const NEAR_TARGET: f64 = 2e-5;

/// `EARTH_FIXED`: the attitude rounded to I24F40, the reference at those inputs widened
/// back.
#[derive(Clone, Copy, Debug, Default)]
pub struct Fixed;

impl Tested for Fixed {
    const KEY: &'static str = "X";
    const MAP_KEY: &'static str = "X";
    const COLUMNS: &'static [Column<GCell<Self>>] = &COLUMNS;

    fn inputs(g: &EarthGeometry<f64>) -> Result<EarthGeometry<f64>, ModelError> {
        Ok(geometry_from_f64(g)?.to_f64())
    }

    /// The inputs rounded again, which gives them back exactly.
    const MOTION: Motion = EARTH_FIXED_MOTION;

    fn note(o: &GOutcome) -> String {
        format!(", kappa {}", sig(o.kappa))
    }

    /// A checked case over its band's target, or a non-finite Ok. Refusals are
    /// typed errors, counted and reported, not failures: the backend's envelope
    /// (`docs/fixed-point.md`) is narrower than the reference's.
    fn broken(c: &GCell<Fixed>) -> Vec<String> {
        let mut bad = Vec::new();
        if c.of_target_checked.max > 1.0 {
            let at = c
                .of_target_checked
                .at
                .map(|(c, o)| describe::<Fixed>(&c, &o));
            bad.push(format!(
                "EARTH_FIXED err/target = {:.3} > 1 at {}",
                c.of_target_checked.max,
                at.unwrap_or_default()
            ));
        }
        if c.non_finite > 0 {
            bad.push(format!(
                "{} non-finite Ok result(s) of EARTH_FIXED",
                c.non_finite
            ));
        }
        bad
    }

    fn bound_line(all: &FCell) -> String {
        format!(
            "EARTH_FIXED (>= {MIN_MARGIN_DEG} deg inside the limb): max err/target {:.3} \
             (2e-5 from 0.01 deg; 2e-6 from 1 deg where kappa <= {EARTH_F32_KAPPA_LIMIT}); \
             max err {}; {} case(s) over the bare target, smallest kappa {}; {} refused",
            all.of_target_checked.max,
            e2(all.err.max),
            all.over,
            sig(all.over_kappa_min),
            all.refused
        )
    }
}

/// A swept map of the fixed backend.
pub type FMap = GMap<Fixed>;
type FCell = GCell<Fixed>;

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

const COLUMNS: [Column<FCell>; 9] = [
    ("cases", |a| a.n.to_string()),
    ("max err \\|dv\\|/\\|v\\|", |a| e2(a.err.max)),
    ("err v1", |a| e2(a.err_v1.max)),
    ("err >= 1 deg in (target 2e-6)", |a| or_dash(&a.far)),
    ("same, kappa <= 30", |a| or_dash(&a.tame)),
    ("err 0.01 - 1 deg (target 2e-5)", |a| or_dash(&a.near)),
    ("min limb margin (deg)", |a| {
        sig(a.min_margin_rad.to_degrees())
    }),
    ("cases over target (smallest kappa)", |a| match a.over {
        0 => "0".into(),
        n => format!("{n} ({})", sig(a.over_kappa_min)),
    }),
    ("refused (first error)", |a| match a.refused_by {
        Some(e) => format!("{} ({e:?})", a.refused),
        None => a.refused.to_string(),
    }),
];
