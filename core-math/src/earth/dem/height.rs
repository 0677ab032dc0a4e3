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

use super::{DemTile, BAND_MARGIN_M};
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

impl<H: Copy + Into<f64>> DemTile<'_, H> {
    /// The ground point of r + s d (r, d in the ITRF) by the search in height (see the
    /// module), starting from `hint_h_m` (the previous update's height for this pixel;
    /// `None`: the middle of the band), to within `tolerance_m` of height.
    pub fn crossing_by_height<T: Real>(
        &self,
        e: &Ellipsoid,
        r: [T; 3],
        d: [T; 3],
        hint_h_m: Option<T>,
        tolerance_m: T,
    ) -> Result<HeightCrossing<T>, HeightRefusal> {
        let (a, b) = (T::from_f64(e.a_m), T::from_f64(e.b_m()));
        let m = T::from_f64(BAND_MARGIN_M);
        let (lo_h, hi_h) = (T::from_f64(self.min_m) - m, T::from_f64(self.max_m) + m);
        // X(H): the near root with the raised ellipsoid.
        let x_at = |h: T| -> Option<(T, [T; 3])> {
            let (s, _) = super::roots(a + h, b + h, r, d)?;
            (s > T::ZERO).then(|| (s, [r[0] + s * d[0], r[1] + s * d[1], r[2] + s * d[2]]))
        };
        let miss = HeightRefusal::Model(ModelError::LineOfSightMissesEarth);
        let (_, top) = x_at(hi_h).ok_or(miss)?;
        // A ray that reaches the top of the band but not its bottom turns back up inside
        // it (a grazing ray): no single crossing to search for.
        let (_, bottom) = x_at(lo_h).ok_or(HeightRefusal::Steep)?;
        let box_ = self.grid.box_in::<T>();
        let at = |h: T, x: [T; 3]| -> Option<T> {
            let (lat, lon) = lat_lon_on_raised(a + h, b + h, x);
            box_.contains(lat, lon)
                .then(|| self.bilinear(&box_, lat, lon))
        };
        // Both ends of the stretch in the box: the stretch is a few kilometres, its
        // track nearly straight, and the box a rectangle in latitude and longitude.
        let (Some(_), Some(_)) = (at(hi_h, top), at(lo_h, bottom)) else {
            return Err(HeightRefusal::Outside);
        };
        // tan(theta) from the stretch: its length against the height it descends.
        let span = hi_h - lo_h;
        let len2: T = (0..3).fold(T::ZERO, |acc, k| {
            acc + (top[k] - bottom[k]) * (top[k] - bottom[k])
        });
        let horizontal2 = len2 - span * span;
        let tan_theta = if horizontal2 > T::ZERO {
            horizontal2.sqrt() / span
        } else {
            T::ZERO
        };
        // One percent on top for the track's curvature over the stretch.
        let q = T::from_f64(self.slope_metric(e) * 1.01) * tan_theta;
        if !(q < T::from_f64(MAX_CONTRACTION)) {
            return Err(HeightRefusal::Steep);
        }
        let certify = T::ONE / (T::ONE - q);
        let g_at = |h: T| -> Result<(T, T), HeightRefusal> {
            let (s, x) = x_at(h).ok_or(miss)?;
            let dem = at(h, x).ok_or(HeightRefusal::Outside)?;
            Ok((dem - h, s))
        };
        // Bracket: g(lo_h) > 0 > g(hi_h) whatever the tile (D lies in [min, max]).
        let (mut lo, mut hi) = (lo_h, hi_h);
        let mid = (lo_h + hi_h) * T::from_f64(0.5);
        let mut h = match hint_h_m {
            Some(x) if x > lo && x < hi => x,
            _ => mid,
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

    /// The tile's steepest slope (m/m), bounded as the march bounds it: the largest
    /// height step per radian of latitude over the smallest meridian radius, plus the
    /// same along longitude over the smallest parallel radius in the tile.
    fn slope_metric(&self, e: &Ellipsoid) -> f64 {
        let f = e.flattening;
        let e2 = f * (2.0 - f);
        let g = &self.grid;
        let lat_max = libm::fabs(g.lat0_deg)
            .max(libm::fabs(g.lat_deg(g.nrows - 1)))
            .to_radians();
        let low = self.min_m.min(0.0);
        self.slope_lat_m_per_rad / (e.a_m * (1.0 - e2) + low)
            + self.slope_lon_m_per_rad / ((e.a_m + low) * libm::cos(lat_max))
    }
}

/// Geodetic latitude and longitude (rad) of a point of the ellipsoid with semi-axes
/// (A, A, B): the latitude of its normal there, tan(lat) = (A/B)^2 z / p. The normal of
/// the raised ellipsoid and the geodetic normal through the point differ by about
/// e^2 H / a (1e-8 rad at 9 000 m, 6 cm on the ground).
fn lat_lon_on_raised<T: Real>(a: T, b: T, x: [T; 3]) -> (T, T) {
    let p = x[0].hypot(x[1]);
    let k = a / b;
    let lat = (k * k * x[2]).atan2(p);
    (lat, x[1].atan2(x[0]))
}
