//! The ground from a DEM tile (`../shared/EARTH-MODEL.md`, Part II, "The ground from a
//! DEM"): heights above the ellipsoid on a regular grid of geodetic latitude and
//! longitude, bilinear inside a cell, and the first point where a line of sight passes
//! from above that surface to on or below it.
//!
//! The search ([`DemTile::first_crossing`]) marches along the ray r + s d with steps
//! that cannot pass a crossing, in the manner of sphere tracing (Hart 1996), on
//! f(s) = h(s) - H(lat(s), lon(s)), h the exact geodetic height ([`geodetic_in`]):
//! - h is the distance to the ellipsoid, so it changes by at most |d| per unit of s;
//! - H changes by at most G_lat |dlat| + G_lon |dlon|, G the tile's largest height
//!   difference between neighbouring nodes per radian ([`DemTile`] finds them when it is
//!   made), and a point moving a distance l changes its latitude by at most
//!   l / (a (1 - e^2) + h_min) and its longitude by at most l / ((a + h_min) cos lat);
//! - so f is Lipschitz along the ray with a constant L (per unit of s) that holds while
//!   |lat| stays below the tile's largest |lat| plus [`LAT_MARGIN_RAD`], which caps the
//!   step; from a point with f > 0 the step f / L cannot reach a zero of f.
//!
//! Outside the tile's box there is no surface: the step there is the larger of two that
//! cannot enter the box below its highest node (h - H_max while above it) or enter it
//! at all (the latitude or longitude still to cover, at the rates above). Above the
//! band of the tile's heights the ray is skipped in closed form: it starts where it
//! enters the ellipsoid raised by H_max + [`BAND_MARGIN_M`] (a point on the ellipsoid
//! raised by H, semi-axes a + H and b + H, has geodetic height within 2e-6 |H| of H:
//! `core-math/tests/dem.rs`), and any stretch inside the ellipsoid lowered to
//! H_min - [`BAND_MARGIN_M`] is crossed in one step, since no point there is above the
//! surface.
//!
//! The search stops at the first point in the box with f <= the backend's tolerance
//! (1e-3 m in f64, 0.5 m in f32, where the geodetic height itself carries 0.6 m of
//! rounding): a ray that passes within that height of a ridge counts as touching it,
//! the contract's "either outcome" near a grazing ray. It refuses with
//! [`ModelError::OutsideDem`] when the ray reaches the ground but not in the tile, and
//! [`ModelError::LineOfSightMissesEarth`] when no point of it comes as low as H_min.

use crate::earth::frames::geodetic::{geodetic_in, GEODETIC_MAX_FLATTENING};
use crate::earth::Ellipsoid;
use crate::error::{ModelError, Param};
use crate::real::Real;

pub mod height;

pub use height::{
    HeightCrossing, HeightRefusal, HeightSearch, MAX_CONTRACTION, MAX_HEIGHT_EVALUATIONS,
};

/// Lowest node height a tile may hold (m; the Dead Sea's shore is at -430 m).
pub const MIN_DEM_HEIGHT_M: f64 = -500.0;
/// Highest node height a tile may hold (m; Everest is 8 849 m).
pub const MAX_DEM_HEIGHT_M: f64 = 9_000.0;
/// Largest |latitude| of a tile's nodes (deg): near the pole a degree of longitude
/// shrinks to nothing and the march outside the box could stall.
pub const MAX_DEM_ABS_LAT_DEG: f64 = 88.0;
/// Most nodes along either side of a tile (the protocol's tiles are 128 x 128 to 256 x 256).
pub const MAX_DEM_NODES: usize = 4_096;
/// How far beyond the tile's largest |latitude| a step may carry the ray (rad); the
/// longitude rate is bounded with the cosine there.
pub const LAT_MARGIN_RAD: f64 = 0.01;
/// Margin (m) on the band of the tile's heights, far above the 2e-6 |H| by which the
/// raised ellipsoid and the geodetic-height surface differ (0.02 m at 9 000 m).
pub const BAND_MARGIN_M: f64 = 1.0;
/// How far (m of path) the final secant steps may move the march's point.
pub const POLISH_REACH_M: f64 = 1.0;
/// Most steps of one search; a ray needs a few dozen unless it grazes the terrain over
/// a long way, and then [`DemTile::first_crossing`] refuses (`OutOfDomain(DemGrid)`).
pub const MAX_DEM_STEPS: u32 = 200_000;

/// A node height as a tile may store it: `i16` metres (as the protocol uploads them),
/// `f32` or `f64`. Its conversion to the search's scalar is direct (one `vcvt` for
/// `i16` to f32 on the target: no detour through soft f64).
pub trait DemHeight: Copy {
    /// The height (m) as an f64, for the tile's checks and bounds.
    fn to_f64(self) -> f64;
    /// The height (m) in the search's scalar.
    fn to_real<T: Real>(self) -> T;
}

impl DemHeight for i16 {
    #[inline(always)]
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
    #[inline(always)]
    fn to_real<T: Real>(self) -> T {
        T::from_i16(self)
    }
}

impl DemHeight for f32 {
    #[inline(always)]
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
    #[inline(always)]
    fn to_real<T: Real>(self) -> T {
        T::from_f32(self)
    }
}

impl DemHeight for f64 {
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self
    }
    #[inline(always)]
    fn to_real<T: Real>(self) -> T {
        T::from_f64(self)
    }
}

/// The grid of a tile: node (i, j) at latitude lat0 + i dlat, longitude lon0 + j dlon
/// (geodetic, ITRF, degrees), i < nrows (from the south), j < ncols (from the west).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DemGrid {
    pub lat0_deg: f64,
    pub lon0_deg: f64,
    pub dlat_deg: f64,
    pub dlon_deg: f64,
    pub nrows: usize,
    pub ncols: usize,
}

/// A checked tile: the grid, its heights (m above the ellipsoid, row-major, row 0 the
/// southernmost; any [`DemHeight`]), and the bounds the search needs, found once.
#[derive(Clone, Copy, Debug)]
pub struct DemTile<'a, H> {
    grid: DemGrid,
    heights_m: &'a [H],
    min_m: f64,
    max_m: f64,
    /// Largest |H(i+1, j) - H(i, j)| per radian of latitude, and |H(i, j+1) - H(i, j)|
    /// per radian of longitude (m/rad).
    slope_lat_m_per_rad: f64,
    slope_lon_m_per_rad: f64,
}

/// What [`DemTile::new`] finds in one pass over the heights and the search needs: the
/// lowest and highest node (m), and the largest |H(i+1, j) - H(i, j)| (`step_lat_m`) and
/// |H(i, j+1) - H(i, j)| (`step_lon_m`) (m).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DemBounds {
    pub min_m: f64,
    pub max_m: f64,
    pub step_lat_m: f64,
    pub step_lon_m: f64,
}

impl<'a, H: DemHeight> DemTile<'a, H> {
    /// The tile of `grid` with `heights_m` (nrows x ncols, row-major). Refusals:
    /// - `InvalidInput(DemGrid)`: fewer than 2 or more than [`MAX_DEM_NODES`] nodes along
    ///   a side, spacings not positive, or a height count other than nrows x ncols;
    /// - `NonFinite(DemGrid)`, `NonFinite(DemHeight)`;
    /// - `OutOfDomain(DemGrid)`: a node beyond [`MAX_DEM_ABS_LAT_DEG`] (so no tile reaches
    ///   a pole), or a longitude outside [-180, 180) (so none crosses the antimeridian);
    /// - `OutOfDomain(DemHeight)`: a height outside [`MIN_DEM_HEIGHT_M`],
    ///   [`MAX_DEM_HEIGHT_M`].
    pub fn new(grid: DemGrid, heights_m: &'a [H]) -> Result<Self, ModelError> {
        let g = grid;
        g.check()?;
        if heights_m.len() != g.nrows * g.ncols {
            return Err(ModelError::InvalidInput(Param::DemGrid));
        }
        let (mut min_m, mut max_m) = (f64::INFINITY, f64::NEG_INFINITY);
        for &h in heights_m {
            let h = h.to_f64();
            if !h.is_finite() {
                return Err(ModelError::NonFinite(Param::DemHeight));
            }
            if !(MIN_DEM_HEIGHT_M..=MAX_DEM_HEIGHT_M).contains(&h) {
                return Err(ModelError::OutOfDomain(Param::DemHeight));
            }
            min_m = min_m.min(h);
            max_m = max_m.max(h);
        }
        let at = |i: usize, j: usize| -> f64 { heights_m[i * g.ncols + j].to_f64() };
        let (mut step_lat_m, mut step_lon_m) = (0.0f64, 0.0f64);
        for i in 0..g.nrows {
            for j in 0..g.ncols {
                if i + 1 < g.nrows {
                    step_lat_m = step_lat_m.max(libm::fabs(at(i + 1, j) - at(i, j)));
                }
                if j + 1 < g.ncols {
                    step_lon_m = step_lon_m.max(libm::fabs(at(i, j + 1) - at(i, j)));
                }
            }
        }
        Ok(DemTile {
            grid,
            heights_m,
            min_m,
            max_m,
            slope_lat_m_per_rad: step_lat_m / g.dlat_deg.to_radians(),
            slope_lon_m_per_rad: step_lon_m / g.dlon_deg.to_radians(),
        })
    }

    /// The tile of `grid` and `heights_m` whose bounds are already known, without the
    /// pass over every node that [`DemTile::new`] makes: `bounds` must be the heights'
    /// own, as [`DemTile::bounds`] of a tile of the same heights gives them (a
    /// controller that checked each node as it arrived keeps them beside the heights).
    /// The grid and the count are checked as [`DemTile::new`] checks them, and the
    /// bounds for their range (`OutOfDomain(DemHeight)`, `InvalidInput(DemGrid)` for
    /// a negative step).
    pub fn with_bounds(
        grid: DemGrid,
        heights_m: &'a [H],
        bounds: DemBounds,
    ) -> Result<Self, ModelError> {
        grid.check()?;
        if heights_m.len() != grid.nrows * grid.ncols {
            return Err(ModelError::InvalidInput(Param::DemGrid));
        }
        let range = MIN_DEM_HEIGHT_M..=MAX_DEM_HEIGHT_M;
        if !(range.contains(&bounds.min_m)
            && range.contains(&bounds.max_m)
            && bounds.min_m <= bounds.max_m)
        {
            return Err(ModelError::OutOfDomain(Param::DemHeight));
        }
        if !(bounds.step_lat_m >= 0.0 && bounds.step_lon_m >= 0.0) {
            return Err(ModelError::InvalidInput(Param::DemGrid));
        }
        Ok(DemTile {
            grid,
            heights_m,
            min_m: bounds.min_m,
            max_m: bounds.max_m,
            slope_lat_m_per_rad: bounds.step_lat_m / grid.dlat_deg.to_radians(),
            slope_lon_m_per_rad: bounds.step_lon_m / grid.dlon_deg.to_radians(),
        })
    }

    /// The bounds [`DemTile::new`] found: lowest and highest node, and the largest
    /// height step between neighbours along a column and along a row (m).
    pub fn bounds(&self) -> DemBounds {
        DemBounds {
            min_m: self.min_m,
            max_m: self.max_m,
            step_lat_m: self.slope_lat_m_per_rad * self.grid.dlat_deg.to_radians(),
            step_lon_m: self.slope_lon_m_per_rad * self.grid.dlon_deg.to_radians(),
        }
    }

    pub fn grid(&self) -> &DemGrid {
        &self.grid
    }

    /// Lowest and highest node heights (m).
    pub fn height_range_m(&self) -> (f64, f64) {
        (self.min_m, self.max_m)
    }

    /// The node heights (m), row-major, row 0 the southernmost: for a caller that
    /// evaluates the bilinear surface by grid coordinates of its own.
    pub fn heights_m(&self) -> &'a [H] {
        self.heights_m
    }

    /// The tile's steepest slope on ellipsoid `e` (m/m), bounded as the march and the
    /// height search bound it (largest height step between neighbouring nodes over the
    /// smallest radius in the tile).
    pub fn steepest_slope(&self, e: &Ellipsoid) -> f64 {
        self.slope_metric(e)
    }

    /// The bilinear height (m) at a geodetic latitude and longitude (rad) in the closed
    /// box of the tile, `None` outside it.
    pub fn height_at<T: Real>(&self, lat_rad: T, lon_rad: T) -> Option<T> {
        let box_ = self.grid.box_in::<T>();
        if !box_.contains(lat_rad, lon_rad) {
            return None;
        }
        Some(self.bilinear(&box_, lat_rad, lon_rad))
    }

    /// The bilinear height at a point of the closed box.
    fn bilinear<T: Real>(&self, b: &GridBox<T>, lat_rad: T, lon_rad: T) -> T {
        self.bilinear_grid(
            (lat_rad - b.lat0_rad) * b.inv_dlat_per_rad,
            (lon_rad - b.lon0_rad) * b.inv_dlon_per_rad,
        )
    }

    /// The bilinear height at grid coordinates (x, y) = (row, column) in
    /// [0, nrows - 1] x [0, ncols - 1], fractions included.
    fn bilinear_grid<T: Real>(&self, x: T, y: T) -> T {
        let g = &self.grid;
        let (u, i) = cell(x, g.nrows as u32 - 2);
        let (v, j) = cell(y, g.ncols as u32 - 2);
        let (i, j) = (i as usize, j as usize);
        let at = |i: usize, j: usize| -> T { self.heights_m[i * g.ncols + j].to_real() };
        let (h00, h01, h10, h11) = (at(i, j), at(i, j + 1), at(i + 1, j), at(i + 1, j + 1));
        let south = h00 + (h01 - h00) * v;
        let north = h10 + (h11 - h10) * v;
        south + (north - south) * u
    }

    /// The first point of r + s d (s > 0; r, d in the ITRF, m and m per unit of s)
    /// where the ray passes from above the tile's surface to on or below it, as the
    /// parameter s. See the module for the search, its tolerance and its refusals.
    /// `ellipsoid` is the one the heights are above; its flattening must be at most
    /// [`GEODETIC_MAX_FLATTENING`] (`OutOfDomain(Flattening)`), and r must lie above
    /// the tile's lowest node (`SatelliteNotAboveGround`).
    pub fn first_crossing<T: Real>(
        &self,
        ellipsoid: &Ellipsoid,
        r_m: [T; 3],
        d: [T; 3],
    ) -> Result<T, ModelError> {
        self.first_crossing_counted(ellipsoid, r_m, d).0
    }

    /// [`DemTile::first_crossing`] with the number of points of the ray it evaluated
    /// (march steps and polish): the search's cost, for tests and benchmarks.
    pub fn first_crossing_counted<T: Real>(
        &self,
        ellipsoid: &Ellipsoid,
        r_m: [T; 3],
        d: [T; 3],
    ) -> (Result<T, ModelError>, u32) {
        if !(ellipsoid.flattening >= 0.0 && ellipsoid.flattening <= GEODETIC_MAX_FLATTENING) {
            return (Err(ModelError::OutOfDomain(Param::Flattening)), 0);
        }
        let search = Search::<T>::new(self, ellipsoid, d);
        let mut steps = 0;
        let found = search.run(self, r_m, d, &mut steps);
        (found, steps)
    }
}

/// (fraction, index) of a grid coordinate x (in cells) in the closed range [0, last + 1]:
/// the cell index clamped to 0..=last, so that the tile's far edge falls in its last cell.
/// The conversion truncates, which is the floor for x >= 0, and saturates a negative x
/// (a rounding below the edge) to 0 as the floor's conversion would: no `floorf` call.
#[inline(always)]
fn cell<T: Real>(x: T, last: u32) -> (T, u32) {
    let i = x.to_u32().min(last);
    (x - T::from_u32(i), i)
}

impl DemGrid {
    /// The grid's own checks, those of [`DemTile::new`] but the heights':
    /// - `NonFinite(DemGrid)`: an origin or spacing not finite;
    /// - `InvalidInput(DemGrid)`: fewer than 2 or more than [`MAX_DEM_NODES`] nodes along
    ///   a side, or a spacing not positive;
    /// - `OutOfDomain(DemGrid)`: a node beyond [`MAX_DEM_ABS_LAT_DEG`] (so no tile
    ///   reaches a pole), or a longitude outside [-180, 180) (so none crosses the
    ///   antimeridian).
    pub fn check(&self) -> Result<(), ModelError> {
        let g = self;
        let angles = [g.lat0_deg, g.lon0_deg, g.dlat_deg, g.dlon_deg];
        if !angles.iter().all(|x| x.is_finite()) {
            return Err(ModelError::NonFinite(Param::DemGrid));
        }
        let sides = 2..=MAX_DEM_NODES;
        if !(sides.contains(&g.nrows)
            && sides.contains(&g.ncols)
            && g.dlat_deg > 0.0
            && g.dlon_deg > 0.0)
        {
            return Err(ModelError::InvalidInput(Param::DemGrid));
        }
        let (lat1, lon1) = (g.lat_deg(g.nrows - 1), g.lon_deg(g.ncols - 1));
        if !(g.lat0_deg >= -MAX_DEM_ABS_LAT_DEG
            && lat1 <= MAX_DEM_ABS_LAT_DEG
            && g.lon0_deg >= -180.0
            && lon1 < 180.0)
        {
            return Err(ModelError::OutOfDomain(Param::DemGrid));
        }
        Ok(())
    }

    pub fn lat_deg(&self, i: usize) -> f64 {
        self.lat0_deg + i as f64 * self.dlat_deg
    }

    pub fn lon_deg(&self, j: usize) -> f64 {
        self.lon0_deg + j as f64 * self.dlon_deg
    }

    fn box_in<T: Real>(&self) -> GridBox<T> {
        let lat1 = self.lat_deg(self.nrows - 1);
        let lon1 = self.lon_deg(self.ncols - 1);
        GridBox {
            lat0_rad: T::from_f64(self.lat0_deg.to_radians()),
            lat1_rad: T::from_f64(lat1.to_radians()),
            lon0_rad: T::from_f64(self.lon0_deg.to_radians()),
            lon1_rad: T::from_f64(lon1.to_radians()),
            inv_dlat_per_rad: T::from_f64(1.0 / self.dlat_deg.to_radians()),
            inv_dlon_per_rad: T::from_f64(1.0 / self.dlon_deg.to_radians()),
        }
    }
}

/// The tile's closed box in radians, in the search's scalar.
#[derive(Clone, Copy, Debug)]
struct GridBox<T> {
    lat0_rad: T,
    lat1_rad: T,
    lon0_rad: T,
    lon1_rad: T,
    inv_dlat_per_rad: T,
    inv_dlon_per_rad: T,
}

impl<T: Real> GridBox<T> {
    fn contains(&self, lat: T, lon: T) -> bool {
        lat >= self.lat0_rad && lat <= self.lat1_rad && lon >= self.lon0_rad && lon <= self.lon1_rad
    }

    /// How far (rad) the point is outside the box in latitude and in longitude (0 where
    /// it is within the range).
    fn outside(&self, lat: T, lon: T) -> (T, T) {
        let beyond = |x: T, lo: T, hi: T| {
            if x < lo {
                lo - x
            } else if x > hi {
                x - hi
            } else {
                T::ZERO
            }
        };
        (
            beyond(lat, self.lat0_rad, self.lat1_rad),
            beyond(lon, self.lon0_rad, self.lon1_rad),
        )
    }
}

/// A ray/ellipsoid quadratic: (x^2 + y^2)/A^2 + z^2/B^2 = 1 on r + s d, as its two roots.
fn roots<T: Real>(a_m: T, b_m: T, r: [T; 3], d: [T; 3]) -> Option<(T, T)> {
    let (ia2, ib2) = (T::ONE / (a_m * a_m), T::ONE / (b_m * b_m));
    let alpha = (d[0] * d[0] + d[1] * d[1]) * ia2 + d[2] * d[2] * ib2;
    let beta = (r[0] * d[0] + r[1] * d[1]) * ia2 + r[2] * d[2] * ib2;
    let c = (r[0] * r[0] + r[1] * r[1]) * ia2 + r[2] * r[2] * ib2 - T::ONE;
    let disc = beta * beta - alpha * c;
    if !(disc >= T::ZERO) || !(alpha > T::ZERO) {
        return None;
    }
    let q = disc.sqrt();
    // Near root without cancellation: (-beta - q)/alpha = c / (-beta + q) when beta < 0.
    let near = if beta < T::ZERO {
        c / (q - beta)
    } else {
        -(beta + q) / alpha
    };
    Some((near, (q - beta) / alpha))
}

/// The constants of one search.
struct Search<T> {
    a_m: T,
    e2: T,
    b_m: T,
    min_m: T,
    max_m: T,
    box_: GridBox<T>,
    /// The Lipschitz constant of f per unit of s.
    lipschitz: T,
    /// Latitude and longitude rates' inverses per unit of s: a step of s covers at
    /// most s / per_lat rad of latitude and, at |lat| <= phi, s / (per_lon cos phi) of
    /// longitude.
    per_lat: T,
    per_lon: T,
    /// The largest step (a latitude change of at most [`LAT_MARGIN_RAD`]).
    max_step: T,
    tolerance_m: T,
    dn: T,
}

impl<T: Real> Search<T> {
    fn new<H: DemHeight>(tile: &DemTile<'_, H>, e: &Ellipsoid, d: [T; 3]) -> Self {
        let (a, f) = (e.a_m, e.flattening);
        let e2 = f * (2.0 - f);
        let g = &tile.grid;
        let lat_max = libm::fabs(g.lat0_deg)
            .max(libm::fabs(g.lat_deg(g.nrows - 1)))
            .to_radians()
            + LAT_MARGIN_RAD;
        let cos_box = crate::trig_f64::cos(lat_max);
        // Metres per radian of latitude and of longitude (at the equator) at or above
        // the lowest node: the meridian radius a (1 - e^2) / W^3 >= a (1 - e^2), the
        // prime vertical a / W >= a.
        let m_per_rad_lat = a * (1.0 - e2) + tile.min_m.min(0.0);
        let m_per_rad_lon = a + tile.min_m.min(0.0);
        let dn = libm::sqrt(d.iter().map(|x| x.to_f64() * x.to_f64()).sum());
        // Per unit of distance: 1 for h, the slopes at the rates above.
        let per_m = 1.0
            + tile.slope_lat_m_per_rad / m_per_rad_lat
            + tile.slope_lon_m_per_rad / (m_per_rad_lon * cos_box);
        let tolerance_m = if T::EPSILON.to_f64() < 1e-10 {
            1e-3
        } else {
            0.5
        };
        Search {
            a_m: T::from_f64(a),
            e2: T::from_f64(e2),
            b_m: T::from_f64(e.b_m()),
            min_m: T::from_f64(tile.min_m),
            max_m: T::from_f64(tile.max_m),
            box_: g.box_in(),
            // A thousandth on top for the rounding of the bounds themselves.
            lipschitz: T::from_f64(per_m * dn * 1.001),
            per_lat: T::from_f64(m_per_rad_lat * 0.999 / dn),
            per_lon: T::from_f64(m_per_rad_lon * 0.999 / dn),
            max_step: T::from_f64(LAT_MARGIN_RAD * m_per_rad_lat / dn),
            tolerance_m: T::from_f64(tolerance_m),
            dn: T::from_f64(dn),
        }
    }

    /// The roots of the ray with the ellipsoid raised by `h_m`.
    fn raised(&self, h_m: T, r: [T; 3], d: [T; 3]) -> Option<(T, T)> {
        roots(self.a_m + h_m, self.b_m + h_m, r, d)
    }

    fn run<H: DemHeight>(
        &self,
        tile: &DemTile<'_, H>,
        r: [T; 3],
        d: [T; 3],
        steps: &mut u32,
    ) -> Result<T, ModelError> {
        let margin = T::from_f64(BAND_MARGIN_M);
        if !(self.dn > T::ZERO) {
            return Err(ModelError::LineOfSightMissesEarth);
        }
        let outcome = || match self.raised(self.min_m, r, d) {
            Some((_, far)) if far > T::ZERO => ModelError::OutsideDem,
            _ => ModelError::LineOfSightMissesEarth,
        };
        // The stretch of the ray inside the band's upper ellipsoid; none: a miss.
        let Some((top_in, top_out)) = self.raised(self.max_m + margin, r, d) else {
            return Err(ModelError::LineOfSightMissesEarth);
        };
        if !(top_out > T::ZERO) {
            return Err(ModelError::LineOfSightMissesEarth);
        }
        // The stretch inside the lower ellipsoid, crossed in one step.
        let deep = self.raised(self.min_m - margin, r, d);
        // Outside the tile's geodetic domain: the satellite is below the highest node.
        let (_, _, h_r) = geodetic_in(r, self.a_m, self.e2);
        if !(h_r > self.min_m) {
            return Err(ModelError::SatelliteNotAboveGround);
        }
        let mut s = if top_in > T::ZERO { top_in } else { T::ZERO };
        // Whether the last point of the box the search saw lay above the surface: a
        // crossing is a passage from above. The ray enters the band from above.
        let mut above = true;
        // The last point of the box seen above the surface, for the final polish.
        let mut last_above: Option<(T, T)> = None;
        for _ in 0..MAX_DEM_STEPS {
            *steps += 1;
            if !(s <= top_out) {
                return Err(outcome());
            }
            if let Some((deep_in, deep_out)) = deep {
                if s > deep_in && s < deep_out {
                    // Every point here is below the lowest node: below the surface.
                    s = deep_out;
                    above = false;
                    continue;
                }
            }
            let x = [r[0] + s * d[0], r[1] + s * d[1], r[2] + s * d[2]];
            let (lat, lon, h) = geodetic_in(x, self.a_m, self.e2);
            if !h.is_finite() {
                return Err(ModelError::NonFinite(Param::Position));
            }
            let (out_lat, out_lon) = self.box_.outside(lat, lon);
            let step = if out_lat > T::ZERO || out_lon > T::ZERO {
                // Outside the box: no surface. A step that cannot reach the box, or
                // cannot go below the highest node (where it may enter the box above
                // the surface).
                let lat_step = out_lat * self.per_lat;
                let cos_now = (lat.abs() + T::from_f64(LAT_MARGIN_RAD)).sin_cos().1;
                let lon_step = if cos_now > T::ZERO {
                    out_lon * self.per_lon * cos_now
                } else {
                    T::ZERO
                };
                let band_step = (h - self.max_m) / self.dn;
                above = h > self.max_m;
                max3(lat_step, lon_step, band_step)
            } else {
                let f = h - tile.bilinear(&self.box_, lat, lon);
                if f <= self.tolerance_m {
                    if above {
                        return Ok(self.polish(tile, r, d, last_above, (s, f), steps));
                    }
                } else {
                    above = true;
                    last_above = Some((s, f));
                }
                f.abs() / self.lipschitz
            };
            // A step at least a hundredth of the tolerance (below the surface |f| can be
            // 0 where the ray leaves it exactly at a node) and at least two units in the
            // last place of s, so that s moves (in f32 an ulp of s is 0.08 m of path at
            // 700 km: the rounding of the ground point itself).
            let floor = self.tolerance_m / (T::from_f64(100.0) * self.lipschitz);
            let ulps = (T::ONE + T::ONE) * T::EPSILON * s;
            let floor = if ulps > floor { ulps } else { floor };
            let step = if step > floor { step } else { floor };
            s = s + if step < self.max_step {
                step
            } else {
                self.max_step
            };
        }
        Err(ModelError::OutOfDomain(Param::DemGrid))
    }
}

impl<T: Real> Search<T> {
    /// The crossing to rounding from the march's last two points: the march stops
    /// within the tolerance of the surface (1e-3 m in f64, a few times 1e-9 of the
    /// motion), and a few secant steps on f reach the zero it approaches, each kept
    /// within [`POLISH_REACH_M`] of path of the march's point. Only where the scalar resolves the surface far
    /// better than the tolerance (f64); in f32 the march's point is the answer.
    fn polish<H: DemHeight>(
        &self,
        tile: &DemTile<'_, H>,
        r: [T; 3],
        d: [T; 3],
        before: Option<(T, T)>,
        at: (T, T),
        steps: &mut u32,
    ) -> T {
        let Some(mut p) = before else { return at.0 };
        if !(T::EPSILON < T::from_f64(1e-10)) {
            return at.0;
        }
        let mut q = at;
        for _ in 0..4 {
            let (df, ds) = (q.1 - p.1, q.0 - p.0);
            if !(df < T::ZERO) || q.1 == T::ZERO {
                break;
            }
            let next = q.0 - q.1 * ds / df;
            // Within POLISH_REACH_M of path from the march's last point, where a ray
            // within 1e-3 m of the surface cannot pass a feature of a tile whose cells
            // span metres (the contract's limb rule covers a tangent there).
            let lo = if p.0 < q.0 { p.0 } else { q.0 };
            if !(next >= lo && (next - at.0).abs() * self.dn <= T::from_f64(POLISH_REACH_M)) {
                break;
            }
            let x = [r[0] + next * d[0], r[1] + next * d[1], r[2] + next * d[2]];
            *steps += 1;
            let (lat, lon, h) = geodetic_in(x, self.a_m, self.e2);
            if !self.box_.contains(lat, lon) {
                break;
            }
            let f = h - tile.bilinear(&self.box_, lat, lon);
            if !(f.abs() < q.1.abs()) {
                break;
            }
            p = q;
            q = (next, f);
        }
        q.0
    }
}

fn max3<T: Real>(a: T, b: T, c: T) -> T {
    let ab = if a > b { a } else { b };
    if ab > c {
        ab
    } else {
        c
    }
}
