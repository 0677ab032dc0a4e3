//! The DEM's ground point by a search in height, for a controller's budget: a few
//! evaluations of the tile instead of the march's hundreds, where the geometry allows
//! it, and a typed refusal (take [`DemTile::first_crossing`]) where it does not.
//!
//! Write X(H) for the point where the ray r + s d enters the ellipsoid raised by H
//! (semi-axes a + H, b + H: geodetic height H to 1.41e-6 |H|, `docs/earth-model.md`),
//! D(H) for the tile's height under X(H), and g(H) = D(H) - H. The ground point is
//! X(H*) with g(H*) = 0. Between the tile's lowest and highest nodes, lowering H moves
//! X(H) along the ray by dH / cos(theta) (theta the ray's angle from the vertical) and
//! its foot by tan(theta) dH, so D changes by at most q dH with q = S tan(theta), S the
//! tile's steepest slope. Where q < 1:
//! - g is strictly decreasing, so the ray crosses the surface once in the band: no
//!   ridge can hide the crossing (an occlusion needs terrain steeper than the ray);
//! - g(H_max + m) < 0 < g(H_min - m): the bracket costs nothing;
//! - |H - H*| <= |g(H)| / (1 - q): each evaluation certifies its own error.
//!
//! The search starts from a hint (the previous update's height for that pixel), takes
//! the fixed-point step H <- D(H) (a contraction by q), then secant steps kept inside
//! the bracket, and stops when the certified error is within the tolerance or after
//! [`MAX_HEIGHT_EVALUATIONS`]. Refusals: [`HeightRefusal::Steep`] where q >=
//! [`MAX_CONTRACTION`], [`HeightRefusal::Outside`] where the ray's stretch through the
//! band does not lie in the tile's box, and the model's own (a ray that misses the
//! band).

use super::{DemHeight, DemTile, BAND_MARGIN_M};
use crate::earth::Ellipsoid;
use crate::error::ModelError;
use crate::real::Real;

/// Largest q = S tan(theta) the height search takes: at 0.8 each evaluation still
/// certifies a fifth of its own residual, and the fixed-point step gains a factor 0.8.
pub const MAX_CONTRACTION: f64 = 0.8;
/// Most evaluations of the tile in one search.
pub const MAX_HEIGHT_EVALUATIONS: u32 = 8;

/// Why the height search declined a ray.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HeightRefusal {
    /// q = S tan(theta) >= [`MAX_CONTRACTION`]: terrain as steep as the ray could hide a
    /// crossing; the march ([`DemTile::first_crossing`]) decides.
    Steep,
    /// The ray's stretch through the band of the tile's heights leaves the tile's box.
    Outside,
    /// The model's refusal (the ray misses the band: [`ModelError::LineOfSightMissesEarth`]).
    Model(ModelError),
}

/// What the height search found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HeightCrossing<T> {
    /// The ray parameter s of the ground point r + s d.
    pub s: T,
    /// Its geodetic height (m, within 1.41e-6 |H| of exact).
    pub h_m: T,
    /// The certified bound on |h_m - H*| (m): |g| / (1 - q).
    pub error_bound_m: T,
    /// Evaluations of the tile it took.
    pub evaluations: u32,
}

/// Largest |argument| of the arctangents about the tile's centre (a point further than
/// atan(0.1) = 5.7 deg from it in latitude or longitude counts as outside the tile).
pub const MAX_CENTRE_TAN: f64 = 0.1;

/// The height search's constants for one tile and ellipsoid, in `T`: made once (per
/// tile upload, or per update), used for every ray.
#[derive(Clone, Copy, Debug)]
pub struct HeightSearch<'t, 'a, H, T> {
    tile: &'t DemTile<'a, H>,
    a_m: T,
    b_m: T,
    /// The band: the lowest and highest node, less and plus the margin.
    lo_m: T,
    hi_m: T,
    /// The tile's steepest slope (m/m), one percent on top.
    slope: T,
    /// The tile's centre: tan of its latitude, cos and sin of its longitude, and its
    /// grid coordinates (row, column).
    tan_lat_c: T,
    cos_lon_c: T,
    sin_lon_c: T,
    row_c: T,
    col_c: T,
    /// Rows per radian of latitude, columns per radian of longitude.
    rows_per_rad: T,
    cols_per_rad: T,
    last_row: T,
    last_col: T,
}

impl<'a, H: DemHeight> DemTile<'a, H> {
    /// The height search's constants for this tile on ellipsoid `e`, in `T`.
    pub fn height_search<T: Real>(&self, e: &Ellipsoid) -> HeightSearch<'_, 'a, H, T> {
        let g = &self.grid;
        let (rows, cols) = ((g.nrows - 1) as f64, (g.ncols - 1) as f64);
        let lat_c = (g.lat0_deg + 0.5 * rows * g.dlat_deg).to_radians();
        let lon_c = (g.lon0_deg + 0.5 * cols * g.dlon_deg).to_radians();
        let m = BAND_MARGIN_M;
        HeightSearch {
            tile: self,
            a_m: T::from_f64(e.a_m),
            b_m: T::from_f64(e.b_m()),
            lo_m: T::from_f64(self.min_m - m),
            hi_m: T::from_f64(self.max_m + m),
            slope: T::from_f64(self.slope_metric(e) * 1.01),
            tan_lat_c: T::from_f64(libm::tan(lat_c)),
            cos_lon_c: T::from_f64(crate::trig_f64::cos(lon_c)),
            sin_lon_c: T::from_f64(crate::trig_f64::sin(lon_c)),
            row_c: T::from_f64(0.5 * rows),
            col_c: T::from_f64(0.5 * cols),
            rows_per_rad: T::from_f64(1.0 / g.dlat_deg.to_radians()),
            cols_per_rad: T::from_f64(1.0 / g.dlon_deg.to_radians()),
            last_row: T::from_f64(rows),
            last_col: T::from_f64(cols),
        }
    }

    /// [`HeightSearch::crossing`] with the constants made for this one ray.
    pub fn crossing_by_height<T: Real>(
        &self,
        e: &Ellipsoid,
        r: [T; 3],
        d: [T; 3],
        hint_h_m: Option<T>,
        tolerance_m: T,
    ) -> Result<HeightCrossing<T>, HeightRefusal> {
        self.height_search(e).crossing(r, d, hint_h_m, tolerance_m)
    }

    /// The tile's steepest slope (m/m), bounded as the march bounds it: the largest
    /// height step per radian of latitude over the smallest meridian radius, plus the
    /// same along longitude over the smallest parallel radius in the tile.
    pub(super) fn slope_metric(&self, e: &Ellipsoid) -> f64 {
        let f = e.flattening;
        let e2 = f * (2.0 - f);
        let g = &self.grid;
        let lat_max = libm::fabs(g.lat0_deg)
            .max(libm::fabs(g.lat_deg(g.nrows - 1)))
            .to_radians();
        let low = self.min_m.min(0.0);
        self.slope_lat_m_per_rad / (e.a_m * (1.0 - e2) + low)
            + self.slope_lon_m_per_rad / ((e.a_m + low) * crate::trig_f64::cos(lat_max))
    }
}

impl<H: DemHeight, T: Real> HeightSearch<'_, '_, H, T> {
    /// The ground point of r + s d (r, d in the ITRF) by the search in height (see the
    /// module), starting from `hint_h_m` (the previous update's height for this pixel;
    /// `None`: the middle of the band), to within `tolerance_m` of height.
    pub fn crossing(
        &self,
        r: [T; 3],
        d: [T; 3],
        hint_h_m: Option<T>,
        tolerance_m: T,
    ) -> Result<HeightCrossing<T>, HeightRefusal> {
        let (lo_h, hi_h) = (self.lo_m, self.hi_m);
        // X(H): the near root with the raised ellipsoid.
        let x_at = |h: T| -> Option<(T, [T; 3])> {
            let (s, _) = super::roots(self.a_m + h, self.b_m + h, r, d)?;
            (s > T::ZERO).then(|| (s, [r[0] + s * d[0], r[1] + s * d[1], r[2] + s * d[2]]))
        };
        let miss = HeightRefusal::Model(ModelError::LineOfSightMissesEarth);
        let (_, top) = x_at(hi_h).ok_or(miss)?;
        // A ray that reaches the top of the band but not its bottom turns back up inside
        // it (a grazing ray): no single crossing to search for.
        let (_, bottom) = x_at(lo_h).ok_or(HeightRefusal::Steep)?;
        // Both ends of the stretch in the box: the stretch is a few kilometres, its
        // track nearly straight, and the box a rectangle in latitude and longitude.
        let (Some(_), Some(_)) = (self.grid_at(hi_h, top), self.grid_at(lo_h, bottom)) else {
            return Err(HeightRefusal::Outside);
        };
        // tan(theta) from the stretch: its length against the height it descends.
        let span = hi_h - lo_h;
        let len2 = (0..3).fold(T::ZERO, |acc, k| {
            acc + (top[k] - bottom[k]) * (top[k] - bottom[k])
        });
        let horizontal2 = len2 - span * span;
        let tan_theta = if horizontal2 > T::ZERO {
            horizontal2.sqrt() / span
        } else {
            T::ZERO
        };
        let q = self.slope * tan_theta;
        if !(q < T::from_f64(MAX_CONTRACTION)) {
            return Err(HeightRefusal::Steep);
        }
        let certify = T::ONE / (T::ONE - q);
        let g_at = |h: T| -> Result<(T, T), HeightRefusal> {
            let (s, x) = x_at(h).ok_or(miss)?;
            let (row, col) = self.grid_at(h, x).ok_or(HeightRefusal::Outside)?;
            Ok((self.tile.bilinear_grid(row, col) - h, s))
        };
        // Bracket: g(lo_h) > 0 > g(hi_h) whatever the tile (D lies in [min, max]).
        let (mut lo, mut hi) = (lo_h, hi_h);
        let mut h = match hint_h_m {
            Some(x) if x > lo && x < hi => x,
            _ => (lo_h + hi_h) * T::from_f64(0.5),
        };
        let mut prev: Option<(T, T)> = None;
        let mut evaluations = 0;
        loop {
            let (g, s) = g_at(h)?;
            evaluations += 1;
            let bound = g.abs() * certify;
            if bound <= tolerance_m || evaluations >= MAX_HEIGHT_EVALUATIONS {
                return Ok(HeightCrossing {
                    s,
                    h_m: h,
                    error_bound_m: bound,
                    evaluations,
                });
            }
            if g > T::ZERO {
                lo = h;
            } else {
                hi = h;
            }
            // The secant through the last two points, else the fixed-point step
            // H <- D(H) = H + g; bisection if either leaves the bracket.
            let next = match prev {
                Some((hp, gp)) if gp != g => h - g * (h - hp) / (g - gp),
                _ => h + g,
            };
            prev = Some((h, g));
            h = if next > lo && next < hi {
                next
            } else {
                (lo + hi) * T::from_f64(0.5)
            };
        }
    }

    /// The grid coordinates (row, column) of a point X of the ellipsoid raised by `h_m`,
    /// `None` outside the tile. Its latitude is that of the raised ellipsoid's normal,
    /// tan(lat) = ((a + H)/(b + H))^2 z/p (it and the geodetic normal through the point
    /// differ by about e^2 H / a: 1e-8 rad at 9 000 m). Both angles are taken from the
    /// tile's centre, atan((tan lat - tan lat_c) / (1 + tan lat tan lat_c)) and the
    /// longitude in the centre meridian's frame, by a series (their arguments are at
    /// most [`MAX_CENTRE_TAN`]): no call, and in f32 the offsets keep their own
    /// precision (2e-9 rad) instead of an absolute latitude's (3.6e-8 rad).
    pub fn grid_at(&self, h_m: T, x: [T; 3]) -> Option<(T, T)> {
        let p = (x[0] * x[0] + x[1] * x[1]).sqrt();
        let k = (self.a_m + h_m) / (self.b_m + h_m);
        let t = k * k * x[2] / p;
        let dlat = atan_small((t - self.tan_lat_c) / (T::ONE + t * self.tan_lat_c))?;
        let along = x[0] * self.cos_lon_c + x[1] * self.sin_lon_c;
        let across = x[1] * self.cos_lon_c - x[0] * self.sin_lon_c;
        if !(along > T::ZERO) {
            return None;
        }
        let dlon = atan_small(across / along)?;
        let row = self.row_c + dlat * self.rows_per_rad;
        let col = self.col_c + dlon * self.cols_per_rad;
        (row >= T::ZERO && row <= self.last_row && col >= T::ZERO && col <= self.last_col)
            .then_some((row, col))
    }
}

/// atan(t) for |t| <= [`MAX_CENTRE_TAN`] by its series to t^9 (the first term left out,
/// t^11/11, is below 1e-12 there); `None` beyond (and for NaN).
#[inline(always)]
fn atan_small<T: Real>(t: T) -> Option<T> {
    if !(t.abs() <= T::from_f64(MAX_CENTRE_TAN)) {
        return None;
    }
    let t2 = t * t;
    let c = |x: f64| T::from_f64(x);
    Some(
        t * (T::ONE
            - t2 * (c(1.0 / 3.0) - t2 * (c(0.2) - t2 * (c(1.0 / 7.0) - t2 * c(1.0 / 9.0))))),
    )
}
