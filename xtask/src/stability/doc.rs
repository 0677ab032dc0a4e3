//! The figures: PNG maps, the tables, and the values the document's template quotes.

use anyhow::{Context, Result};
use std::collections::BTreeMap;
use std::path::Path;

use crate::markdown::{e2, f2, sig, sig_range};

use super::grid::{self, Column};
use super::maps::{Cell, Map};
use super::point::{Outcome, Point, INPUTS};
use super::{C_F32, C_FIXED};

/// log10 with a floor, so that an exact 0 lands at the bottom of the colour scale.
pub fn lg(x: f64) -> f64 {
    x.max(1e-30).log10()
}

/// A short description of where a point is.
pub fn describe(pt: &Point, o: &Outcome) -> String {
    let g = &pt.g;
    format!(
        "H {:.0} km, roll {:.2} deg, field {:.2} deg, i0 {:.1} deg, g0 {:.1} deg; limb margin {} deg",
        g.altitude_m / 1e3,
        g.roll_rad.to_degrees(),
        pt.field_rad.to_degrees(),
        g.inclination_rad.to_degrees(),
        g.arg_latitude_rad.to_degrees(),
        sig(o.margin_rad.to_degrees()),
    )
}

type Panel = grid::Panel<Cell>;

const ERR_RANGE: (f64, f64) = (-10.0, -3.0);
const RATIO_RANGE: (f64, f64) = (-3.0, 1.0);

const PANELS: [Panel; 6] = [
    Panel {
        suffix: "kappa",
        title: "condition number kappa",
        z_label: "kappa",
        z_range: (0.0, 4.0),
        linear: false,
        value: |c| lg(c.kappa.max),
        bound: None,
    },
    Panel {
        suffix: "err-f32",
        title: "f32 error (same inputs)",
        z_label: "rel. error |v_P|",
        z_range: ERR_RANGE,
        linear: false,
        value: |c| lg(c.err.f32),
        bound: None,
    },
    Panel {
        suffix: "err-f32-inputs",
        title: "f32 error (unrounded inputs)",
        z_label: "rel. error |v_P|",
        z_range: ERR_RANGE,
        linear: false,
        value: |c| lg(c.err.f32_in),
        bound: None,
    },
    Panel {
        suffix: "err-fixed",
        title: "fixed-point error",
        z_label: "rel. error |v_P|",
        z_range: ERR_RANGE,
        linear: false,
        value: |c| lg(c.err.fixed_worst()),
        bound: None,
    },
    Panel {
        suffix: "ratio-f32",
        title: "f32: err / (kappa u)",
        z_label: "err / (kappa u)",
        z_range: RATIO_RANGE,
        linear: false,
        value: |c| lg(c.ratio_f32.max.max(c.ratio_f32_in.max)),
        bound: Some(C_F32),
    },
    Panel {
        suffix: "ratio-fixed",
        title: "fixed: err / (kappa u_fx)",
        z_label: "err / (kappa u_fx)",
        z_range: RATIO_RANGE,
        linear: false,
        value: |c| lg(c.ratio_fixed.max),
        bound: Some(C_FIXED),
    },
];

/// The extra panel of the inclination map: the ratio of v1's two terms.
const V1_TERMS: Panel = Panel {
    suffix: "v1-terms",
    title: "v1: cancellation of its two terms",
    z_label: "t (second / first)",
    z_range: (0.0, 0.1),
    linear: true,
    value: |c| c.v1_term_ratio,
    bound: None,
};

/// The kappa panel (each cell's largest kappa) with its colour scale fitted to the map:
/// decades when it spans one or more, linear (whole numbers) otherwise, where a log
/// scale would show one colour.
fn kappa_panel(map: &Map) -> Panel {
    let (lo, hi) = map
        .cells
        .iter()
        .filter(|c| c.n > 0)
        .fold((f64::INFINITY, 0.0f64), |(l, h), c| {
            (l.min(c.kappa.max), h.max(c.kappa.max))
        });
    // Also when the map is empty (lo = inf) or flat.
    if lo.partial_cmp(&hi) != Some(std::cmp::Ordering::Less) || hi / lo >= 10.0 {
        return Panel {
            z_range: (lg(lo).floor().min(0.0), lg(hi).ceil().max(1.0)),
            ..PANELS[0]
        };
    }
    Panel {
        z_range: (lo.floor(), hi.ceil()),
        linear: true,
        value: |c| c.kappa.max,
        ..PANELS[0]
    }
}

/// Writes the PNGs of `map` into `dir`: the panels, the kappa panel fitted to the map,
/// and the inclination map's v1 panel.
pub fn write_pngs(map: &Map, dir: &Path) -> Result<()> {
    let kappa = kappa_panel(map);
    let extra = (map.spec.key == "inclination-latitude").then_some(&V1_TERMS);
    map.write_pngs(
        std::iter::once(&kappa).chain(&PANELS[1..]).chain(extra),
        dir,
    )
}

/// The round-Earth tables' columns.
pub const COLUMNS: [Column<Cell>; 12] = [
    ("cases", |a| a.n.to_string()),
    ("kappa min - max", |a| sig_range(a.kappa_min, a.kappa.max)),
    ("f32 err \\|v\\|", |a| e2(a.err.f32)),
    ("f32 err v1", |a| e2(a.err.f32_v1)),
    ("f32 err, unrounded inputs", |a| e2(a.err.f32_in)),
    ("fixed err \\|v\\|", |a| e2(a.err.fixed_worst())),
    ("fixed err v1", |a| e2(a.err.fixed_v1)),
    ("f32 err/(kappa u)", |a| f2(a.ratio_f32.max)),
    ("f32 unrounded err/(kappa u)", |a| f2(a.ratio_f32_in.max)),
    ("fixed err/(kappa u_fx)", |a| f2(a.ratio_fixed.max)),
    ("kappa q", |a| sig_range(a.kq.0, a.kq.1)),
    ("refused", |a| a.refused.to_string()),
];

/// kappa's parts at a point, largest first, as "roll 6.2, altitude 3.0, ...".
pub fn parts(o: &Outcome) -> String {
    let mut idx: Vec<usize> = (0..INPUTS.len()).collect();
    idx.sort_by(|&a, &b| o.kappa_parts[b].total_cmp(&o.kappa_parts[a]));
    idx.iter()
        .filter(|&&i| o.kappa_parts[i] >= 0.01)
        .map(|&i| format!("{} {}", INPUTS[i], sig(o.kappa_parts[i])))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Least-squares slope of log10(kappa) against log10(q) over the max-kappa samples of
/// the cells of `map` whose line of sight is within `margin_deg` of the limb.
pub fn limb_slope(map: &Map, margin_deg: f64) -> Option<(f64, usize)> {
    let pts: Vec<(f64, f64)> = map
        .cells
        .iter()
        .filter_map(|c| c.kappa.at)
        .filter(|(_, o)| o.margin_rad.to_degrees() < margin_deg)
        .map(|(_, o)| (o.q.log10(), o.kappa.log10()))
        .collect();
    let n = pts.len() as f64;
    if pts.len() < 3 {
        return None;
    }
    let (sx, sy) = pts.iter().fold((0.0, 0.0), |(a, b), (x, y)| (a + x, b + y));
    let (mx, my) = (sx / n, sy / n);
    let (sxy, sxx) = pts.iter().fold((0.0, 0.0), |(a, b), (x, y)| {
        (a + (x - mx) * (y - my), b + (x - mx) * (x - mx))
    });
    Some((sxy / sxx, pts.len()))
}

/// Fills `{{key}}` placeholders; an unknown key is an error.
pub fn fill(template: &str, values: &BTreeMap<String, String>) -> Result<String> {
    let mut out = String::with_capacity(template.len() * 2);
    let mut rest = template;
    while let Some(b) = rest.find("{{") {
        out.push_str(&rest[..b]);
        let e = rest[b..]
            .find("}}")
            .context("stability template: unclosed {{")?
            + b;
        let key = rest[b + 2..e].trim();
        let v = values
            .get(key)
            .with_context(|| format!("stability template: no value for `{key}`"))?;
        out.push_str(v);
        rest = &rest[e + 2..];
    }
    out.push_str(rest);
    Ok(out)
}
