//! The three maps of the paper's round Earth: which variables span each, where the
//! others sit, and what a cell keeps.

use super::doc::describe;
use super::grid::{self, Spec, Worst};
use super::point::{evaluate, Outcome, Point, RelErrors, Skip, EARTH_RADIUS_M};
use super::{C_F32, C_FIXED};

/// Sun-synchronous inclination of the paper's orbit (deg).
pub const I0_SSO_DEG: f64 = 97.98;

/// Inclination and argument of latitude (deg) the sub-samples of map A cycle through.
const OTHERS_A: [(f64, f64); 6] = [
    (I0_SSO_DEG, 0.0),
    (I0_SSO_DEG, 135.0),
    (50.0, 270.0),
    (0.0, 0.0),
    (150.0, 45.0),
    (85.0, 90.0),
];

/// Map A: altitude x distance from the line of sight to the limb (log).
fn point_a(h_km: f64, log_margin_deg: f64, s: usize) -> Option<Point> {
    let h = h_km * 1e3;
    let limb_deg = libm::asin(EARTH_RADIUS_M / (EARTH_RADIUS_M + h)).to_degrees();
    let margin = 10f64.powf(log_margin_deg);
    if margin >= limb_deg {
        return None; // past the nadir: the other side's margin
    }
    // Both limbs, and three ways to share eta between roll and field angle.
    let side = [1.0, -1.0][s % 2];
    let eta = side * (limb_deg - margin);
    let a = eta.abs();
    let (roll, field) = match (s / 6 + s / 2) % 3 {
        0 => (0.5 * a, 0.5 * a),
        1 => (a.min(45.0), a - a.min(45.0)),
        _ => (a - a.min(40.0), a.min(40.0)),
    };
    let (i0, g0) = OTHERS_A[s % OTHERS_A.len()];
    Some(Point::circular(side * roll, side * field, i0, g0, h_km))
}

/// Map B: roll x field angle at 645 km, sun-synchronous, g0 over the sub-samples.
fn point_b(roll_deg: f64, field_deg: f64, s: usize) -> Option<Point> {
    let g0 = 60.0 * (s % 6) as f64;
    Some(Point::circular(roll_deg, field_deg, I0_SSO_DEG, g0, 645.0))
}

/// The lines of sight map C takes the maximum over: 1 deg from the left limb (roll
/// +45 deg), 1 deg from the right limb (roll -45 deg), nadir, a mid-swath point.
fn los_c(s: usize, h_km: f64) -> (f64, f64) {
    let limb_deg = libm::asin(EARTH_RADIUS_M / (EARTH_RADIUS_M + h_km * 1e3)).to_degrees();
    match s % 4 {
        0 => (45.0, limb_deg - 1.0 - 45.0),
        1 => (-45.0, -(limb_deg - 1.0 - 45.0)),
        2 => (0.0, 0.0),
        _ => (20.0, -30.0),
    }
}

/// Map C: inclination x argument of latitude at 2 000 km (where the Earth-rotation
/// terms are largest against the orbital rate).
fn point_c(i0_deg: f64, g0_deg: f64, s: usize) -> Option<Point> {
    let h_km = 2000.0;
    let (roll, field) = los_c(s, h_km);
    Some(Point::circular(roll, field, i0_deg, g0_deg, h_km))
}

pub const MAPS: [Spec<Point>; 3] = [
    Spec {
        key: "altitude-limb",
        letter: "A",
        title: "altitude x distance to the limb",
        x_label: "altitude (km)",
        y_label: "limb margin (deg)",
        x_range: (200.0, 2000.0),
        y_range: (-5.0, 2.0),
        y_decades: true,
        nx: 120,
        ny: 112,
        sub: 12,
        point: point_a,
        others: "both limbs alternately; eta shared between roll and field angle three ways \
                 (half each, roll up to 45 deg, field up to 40 deg); (i0, g0) cycling through \
                 (97.98, 0), (97.98, 135), (50, 270), (0, 0), (150, 45), (85, 90) deg",
        missing: "past nadir",
    },
    Spec {
        key: "roll-field",
        letter: "B",
        title: "roll x field angle, 645 km",
        x_label: "roll (deg)",
        y_label: "field angle (deg)",
        x_range: (-45.0, 45.0),
        y_range: (-40.0, 40.0),
        y_decades: false,
        nx: 180,
        ny: 160,
        sub: 6,
        point: point_b,
        others: "altitude 645 km, i0 97.98 deg; g0 = 0, 60, ..., 300 deg over the sub-samples",
        missing: "beyond the limb",
    },
    Spec {
        key: "inclination-latitude",
        letter: "C",
        title: "inclination x arg. of latitude, 2000 km",
        x_label: "inclination (deg)",
        y_label: "argument of latitude (deg)",
        x_range: (0.0, 180.0),
        y_range: (0.0, 360.0),
        y_decades: false,
        nx: 144,
        ny: 144,
        sub: 8,
        point: point_c,
        others: "altitude 2 000 km; lines of sight 1 deg from the left limb (roll +45 deg), \
                 1 deg from the right limb (roll -45 deg), nadir, and roll 20 / field -30 deg",
        missing: "",
    },
];

/// A sample of a round-Earth map: where, and what it measured.
pub type Sample = (Point, Outcome);

/// What a cell (or an aggregate of cells) keeps of its samples: maxima, each with the
/// sample behind it where the document quotes one.
#[derive(Clone, Debug, Default)]
pub struct Cell {
    pub n: u32,
    pub refused: u32,
    pub refused_by: Option<&'static str>,
    /// Quote `err.fixed_worst()` for the fixed |v_P| error, as the maps do.
    pub err: RelErrors,
    pub kappa: Worst<Sample>,
    pub kappa_min: f64,
    /// err/(kappa u) of f32 (at the same and at the unrounded inputs) and of fixed.
    pub ratio_f32: Worst<Sample>,
    pub ratio_f32_in: Worst<Sample>,
    pub ratio_fixed: Worst<Sample>,
    pub v1_term_ratio: f64,
    pub min_margin_rad: f64,
    /// min and max of kappa q over the max-kappa sample of each cell.
    pub kq: (f64, f64),
}

impl grid::Cell for Cell {
    type Point = Point;

    fn empty() -> Self {
        Cell {
            kappa_min: f64::INFINITY,
            min_margin_rad: f64::INFINITY,
            v1_term_ratio: f64::NEG_INFINITY,
            kq: (f64::INFINITY, 0.0),
            ..Cell::default()
        }
    }

    fn sample(&mut self, pt: &Point) {
        match evaluate(pt) {
            Ok(o) => self.add(pt, &o),
            Err(Skip::Outside) => {}
            Err(Skip::Refused(by)) => {
                self.refused += 1;
                self.refused_by = Some(by);
            }
        }
    }

    fn n(&self) -> u64 {
        self.n.into()
    }

    /// A cell without samples adds nothing (not even its refusals).
    fn merge(&mut self, o: &Cell) {
        if o.n == 0 {
            return;
        }
        self.n += o.n;
        self.refused += o.refused;
        self.refused_by = self.refused_by.or(o.refused_by);
        self.err.max_assign(&o.err);
        self.kappa_min = self.kappa_min.min(o.kappa_min);
        self.min_margin_rad = self.min_margin_rad.min(o.min_margin_rad);
        self.v1_term_ratio = self.v1_term_ratio.max(o.v1_term_ratio);
        self.kq = (self.kq.0.min(o.kq.0), self.kq.1.max(o.kq.1));
        self.ratio_f32.merge(&o.ratio_f32);
        self.ratio_f32_in.merge(&o.ratio_f32_in);
        self.ratio_fixed.merge(&o.ratio_fixed);
        self.kappa.merge(&o.kappa);
    }

    fn broken(&self) -> Vec<String> {
        let mut bad = Vec::new();
        for (name, w, c) in [
            ("f32", &self.ratio_f32, C_F32),
            ("f32 (unrounded inputs)", &self.ratio_f32_in, C_F32),
            ("fixed", &self.ratio_fixed, C_FIXED),
        ] {
            if w.max > c {
                let at = w.at.map(|(p, o)| describe(&p, &o)).unwrap_or_default();
                bad.push(format!("{name} err/(kappa u) = {:.3} > {c} at {at}", w.max));
            }
        }
        if self.refused > 0 {
            let by = self.refused_by.unwrap_or("a backend");
            bad.push(format!(
                "{} case(s) the reference accepts refused by {by}",
                self.refused
            ));
        }
        bad
    }
}

impl Cell {
    fn add(&mut self, pt: &Point, o: &Outcome) {
        self.n += 1;
        self.err.max_assign(&o.err);
        self.kappa_min = self.kappa_min.min(o.kappa);
        self.min_margin_rad = self.min_margin_rad.min(o.margin_rad);
        self.v1_term_ratio = self.v1_term_ratio.max(o.v1_term_ratio);
        let w = (*pt, *o);
        self.ratio_f32.offer(o.ratio_f32(), w);
        self.ratio_f32_in.offer(o.ratio_f32_in(), w);
        self.ratio_fixed.offer(o.ratio_fixed(), w);
        self.kappa.offer(o.kappa, w);
        if let Some((_, m)) = self.kappa.at {
            self.kq = (m.kappa * m.q, m.kappa * m.q);
        }
    }
}

/// A swept map of the round Earth.
pub type Map = grid::Map<Cell>;
