//! The ground of every plan sample on the DEM tile in force (Part II of
//! `shared/EARTH-MODEL.md`, "The ground from a DEM"), per update, for a controller's
//! budget: one evaluation of the tile per sample in the steady state, a typed route to
//! the never-skipping march where one is not certain, the segment's TERRAIN height where
//! no tile covers the sample (docs/controller.md, "The DEM ground").
//!
//! For one sample's line of sight r + s d (ITRF of the update instant, d = B u), write
//! X(H) for the point where it enters the ellipsoid raised by H (semi-axes a + H,
//! b + H), D(H) for the tile's bilinear height under X(H), g(H) = D(H) - H. The ground
//! point is X(H*), g(H*) = 0. With q = S tan(theta) (S the tile's steepest slope, theta
//! the ray's angle from the vertical) below [`MAX_CONTRACTION`], g falls at least
//! (1 - q) per metre of H while X(H) is in the tile: the crossing in the tile is unique
//! (no ridge can hide it: `core_math::earth::dem::height`), and the fixed-point step
//! D(H) is within q |g| / (1 - q) of H*. An evaluation whose step is certified within
//! [`HEIGHT_TOLERANCE_M`] is the answer: the range s + g ds/dH at H + g.
//!
//! The start is the sample's height at the previous update plus its change over that
//! update (the footprint moves smoothly; on the first update, the segment's TERRAIN
//! height), so that in the steady state one evaluation settles; otherwise Newton steps
//! on g (the bilinear cell's gradient along the ray), kept in the bracket the signs of g
//! give, up to [`MAX_EVALUATIONS`]. The march ([`DemTile::first_crossing`], which never
//! skips a crossing) decides where q is too large, where the ray's stretch through the
//! band of the tile's heights meets the tile's edge, or where the steps do not settle.

use core_math::earth::dem::{DemGrid, DemTile, BAND_MARGIN_M};
use core_math::earth::{GeneralRowMotion, MIN_V1_MPS};
use core_math::{ImageMotion, ModelError, Real};

use crate::config::EARTH;
use crate::plan::MAX_SAMPLES;
use crate::scene::MAX_SEGMENTS;
use crate::track::ItrfFrame;

/// Certified bound on a sample's ground height (m): 5 m moves a period by 5 / range,
/// 1e-5 at 500 km, a tenth of the budget against the DEM truth.
pub const HEIGHT_TOLERANCE_M: f32 = 5.0;
/// Largest q = S tan(theta) the search in height takes (as the core-math height search).
pub const MAX_CONTRACTION: f32 = core_math::earth::dem::MAX_CONTRACTION as f32;
/// Most evaluations of the tile per sample before the march decides.
pub const MAX_EVALUATIONS: u32 = 4;
/// Largest half-extent of a tile in latitude and longitude (deg) the route takes: the
/// grid coordinates come from arctangent series about the tile's centre, and the
/// along-ray Jacobian taken at the centre is within 5 % anywhere in it.
pub const MAX_TILE_HALF_DEG: f64 = 2.5;
/// Share of the ray's stretch, in cells, added to the margin of the tile-edge test (the
/// Jacobian's error over the tile, doubled).
const EDGE_SHARE: f32 = 0.1;
/// Largest tan^2(theta) for which the tile-edge tests extrapolate along the ray (72 deg
/// from the vertical; beyond, the march).
const MAX_TAN2: f32 = 9.0;

/// How each sample's ground was found, counted since the tile was set (tests, bench).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DemStats {
    /// Samples whose ground came from the tile by the search in height.
    pub searched: u32,
    /// Evaluations of the tile those took (the samples off the tile or marched take
    /// one or more too, not counted).
    pub evaluations: u32,
    /// Samples the march decided.
    pub marched: u32,
    /// Samples outside the tile: the segment's TERRAIN height.
    pub outside: u32,
}

/// The tile's constants for the route, in f32, made once per tile.
#[derive(Clone, Copy, Debug)]
struct TileFrame {
    tan_lat_c: f32,
    cos_lon_c: f32,
    sin_lon_c: f32,
    row_c: f32,
    col_c: f32,
    rows_per_rad: f32,
    cols_per_rad: f32,
    last_row: f32,
    last_col: f32,
    last_row_cell: u32,
    last_col_cell: u32,
    ncols: usize,
    /// The band of the tile's heights with the march's margin (m).
    lo_m: f32,
    hi_m: f32,
    /// (1.01 S)^2, S the tile's steepest slope (m/m).
    slope2: f32,
    /// Rows and columns per metre of ITRF displacement at the tile's centre.
    rows_per_m: [f32; 3],
    cols_per_m: [f32; 3],
}

/// The DEM tile in force and what the route keeps between updates.
#[derive(Clone, Debug)]
pub struct DemGround {
    tile: DemTile<'static, i16>,
    frame: TileFrame,
    /// Each plan segment's samples' heights at the last update (NaN: none) and their
    /// change over it (m).
    last_h_m: [[f32; MAX_SAMPLES]; MAX_SEGMENTS],
    step_h_m: [[f32; MAX_SAMPLES]; MAX_SEGMENTS],
    pub stats: DemStats,
}

/// Why the DEM route refuses a tile: it is then not in force (the TERRAIN heights are).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TileRefusal {
    /// Wider than [`MAX_TILE_HALF_DEG`] either way from its centre.
    TooWide,
}

impl DemGround {
    /// The route's constants for `tile` (f64 trigonometry, once per tile).
    pub fn new(tile: DemTile<'static, i16>) -> Result<DemGround, TileRefusal> {
        let g: DemGrid = *tile.grid();
        let (rows, cols) = ((g.nrows - 1) as f64, (g.ncols - 1) as f64);
        if 0.5 * rows * g.dlat_deg > MAX_TILE_HALF_DEG
            || 0.5 * cols * g.dlon_deg > MAX_TILE_HALF_DEG
        {
            return Err(TileRefusal::TooWide);
        }
        let lat_c = (g.lat0_deg + 0.5 * rows * g.dlat_deg).to_radians();
        let lon_c = (g.lon0_deg + 0.5 * cols * g.dlon_deg).to_radians();
        let (min_m, max_m) = tile.height_range_m();
        let (sl, cl) = (
            core_math::trig_f64::sin(lat_c),
            core_math::trig_f64::cos(lat_c),
        );
        let (so, co) = (
            core_math::trig_f64::sin(lon_c),
            core_math::trig_f64::cos(lon_c),
        );
        let f = EARTH.flattening;
        let e2 = f * (2.0 - f);
        let w = libm::sqrt(1.0 - e2 * sl * sl);
        let h_mid = 0.5 * (min_m + max_m);
        let meridian_m = EARTH.a_m * (1.0 - e2) / (w * w * w) + h_mid;
        let parallel_m = (EARTH.a_m / w + h_mid) * cl;
        let rows_per_rad = 1.0 / g.dlat_deg.to_radians();
        let cols_per_rad = 1.0 / g.dlon_deg.to_radians();
        let north = [-sl * co, -sl * so, cl];
        let east = [-so, co, 0.0];
        let slope = tile.steepest_slope(&EARTH) * 1.01;
        let frame = TileFrame {
            tan_lat_c: (sl / cl) as f32,
            cos_lon_c: co as f32,
            sin_lon_c: so as f32,
            row_c: (0.5 * rows) as f32,
            col_c: (0.5 * cols) as f32,
            rows_per_rad: rows_per_rad as f32,
            cols_per_rad: cols_per_rad as f32,
            last_row: rows as f32,
            last_col: cols as f32,
            last_row_cell: (g.nrows - 2) as u32,
            last_col_cell: (g.ncols - 2) as u32,
            ncols: g.ncols,
            lo_m: (min_m - BAND_MARGIN_M) as f32,
            hi_m: (max_m + BAND_MARGIN_M) as f32,
            slope2: (slope * slope) as f32,
            rows_per_m: north.map(|x| (x * rows_per_rad / meridian_m) as f32),
            cols_per_m: east.map(|x| (x * cols_per_rad / parallel_m) as f32),
        };
        Ok(DemGround {
            tile,
            frame,
            last_h_m: [[f32::NAN; MAX_SAMPLES]; MAX_SEGMENTS],
            step_h_m: [[0.0; MAX_SAMPLES]; MAX_SEGMENTS],
            stats: DemStats::default(),
        })
    }

    pub fn tile(&self) -> &DemTile<'static, i16> {
        &self.tile
    }
}

/// One segment's rays at one update: d = d0 + p2 dy (the camera's row p1 turned into
/// the ITRF), with what every evaluation reads.
pub(crate) struct SegmentRays {
    r: [f32; 3],
    d0: [f32; 3],
    dy: [f32; 3],
    /// r.d and its change per metre of p2; |u|^2 at p2 = 0.
    rd0: f32,
    rdy: f32,
    uu0: f32,
    /// Rows and columns per unit of s along d, and their change per metre of p2.
    jr0: f32,
    jry: f32,
    jc0: f32,
    jcy: f32,
    /// |r|^2 - a^2 (m^2, formed in f64 by the propagator).
    r2_minus_a2_m2: f32,
}

impl SegmentRays {
    pub(crate) fn new(
        ground: &DemGround,
        frame: &ItrfFrame,
        p1_m: f32,
        focal_m: f32,
        uu0_m2: f32,
        r2_minus_a2_m2: f32,
    ) -> SegmentRays {
        let b = &frame.camera_to_itrf;
        let r = frame.position_m;
        // B (p1, 0, -f) and B (0, 1, 0).
        let d0: [f32; 3] = core::array::from_fn(|i| b[i][0] * p1_m - b[i][2] * focal_m);
        let dy: [f32; 3] = core::array::from_fn(|i| b[i][1]);
        let dot = |x: [f32; 3], y: [f32; 3]| x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
        let t = &ground.frame;
        SegmentRays {
            r,
            d0,
            dy,
            rd0: dot(r, d0),
            rdy: dot(r, dy),
            uu0: uu0_m2,
            jr0: dot(t.rows_per_m, d0),
            jry: dot(t.rows_per_m, dy),
            jc0: dot(t.cols_per_m, d0),
            jcy: dot(t.cols_per_m, dy),
            r2_minus_a2_m2,
        }
    }
}

/// What the route found for one sample.
pub(crate) enum SampleGround {
    /// The ground point's range s (r + s d) on the tile.
    Range(f32),
    /// No tile under the sample: the segment's TERRAIN height holds.
    Outside,
}

/// One evaluation of the tile at height h on one ray.
enum Evaluation {
    At {
        s: f32,
        /// g = D - h, dg/dh, ds/dh.
        g: f32,
        dg_dh: f32,
        ds_dh: f32,
        /// q^2 = S^2 tan^2(theta).
        q2: f32,
        /// The point's grid coordinates and their change per metre of h.
        row: f32,
        col: f32,
        drow_dh: f32,
        dcol_dh: f32,
    },
    /// The ray's stretch through the band lies outside the tile.
    Outside,
    /// The march decides (grazing, steep, or the tile's edge within reach).
    March,
}

impl DemGround {
    /// The ground of sample `j` of plan segment `k` at pixel p2 (m) on `rays`: see the
    /// module. `terrain_h_m` starts the search on the first update.
    pub(crate) fn sample(
        &mut self,
        k: usize,
        j: usize,
        rays: &SegmentRays,
        p2_m: f32,
        terrain_h_m: f32,
    ) -> Result<SampleGround, ModelError> {
        let d: [f32; 3] = core::array::from_fn(|i| rays.d0[i] + p2_m * rays.dy[i]);
        let ray = Ray {
            d,
            rd: rays.rd0 + p2_m * rays.rdy,
            uu: rays.uu0 + p2_m * p2_m,
            jr: rays.jr0 + p2_m * rays.jry,
            jc: rays.jc0 + p2_m * rays.jcy,
        };
        let t = self.frame;
        let (last, step) = (self.slot(k, j, true), self.slot(k, j, false));
        let start = if last.is_finite() {
            last + step
        } else {
            terrain_h_m
        };
        let mut h = clamp(start, t.lo_m, t.hi_m);
        let (mut lo, mut hi) = (t.lo_m, t.hi_m);
        for n in 1..=MAX_EVALUATIONS {
            match self.evaluate(rays, &ray, h) {
                Evaluation::Outside => {
                    self.stats.outside += 1;
                    self.remember(k, j, f32::NAN);
                    return Ok(SampleGround::Outside);
                }
                Evaluation::March => break,
                Evaluation::At {
                    s,
                    g,
                    dg_dh,
                    ds_dh,
                    q2,
                    row,
                    col,
                    drow_dh,
                    dcol_dh,
                } => {
                    let tol = HEIGHT_TOLERANCE_M;
                    // q (|g| + tol) <= tol: the fixed-point step h + g is within
                    // q |g| / (1 - q) <= tol of H*.
                    let a = g.abs() + tol;
                    if q2 * a * a <= tol * tol {
                        // H* lies within |g| / (1 - q) of h: that stretch must lie in
                        // the tile, where the crossing is then the only one.
                        let reach = g.abs() * 5.0 + 1.0;
                        if !self.inside_over(row, col, drow_dh, dcol_dh, -reach, reach) {
                            break;
                        }
                        self.stats.searched += 1;
                        self.stats.evaluations += n;
                        self.remember(k, j, h + g);
                        return Ok(SampleGround::Range(s + g * ds_dh));
                    }
                    if g > 0.0 {
                        lo = h;
                    } else {
                        hi = h;
                    }
                    // Newton on g (dg/dh <= q - 1 < 0), else bisection.
                    let next = h - g / dg_dh;
                    h = if next > lo && next < hi {
                        next
                    } else {
                        0.5 * (lo + hi)
                    };
                }
            }
        }
        self.stats.marched += 1;
        self.remember(k, j, f32::NAN);
        match self.tile.first_crossing(&EARTH, rays.r, d) {
            Ok(s) => Ok(SampleGround::Range(s)),
            Err(ModelError::OutsideDem) => Ok(SampleGround::Outside),
            Err(e) => Err(e),
        }
    }

    fn slot(&self, k: usize, j: usize, last: bool) -> f32 {
        let table = if last { &self.last_h_m } else { &self.step_h_m };
        table
            .get(k)
            .and_then(|s| s.get(j))
            .copied()
            .unwrap_or(f32::NAN)
    }

    /// Notes the sample's height for the next update's start, and its change.
    fn remember(&mut self, k: usize, j: usize, h_m: f32) {
        let (Some(last), Some(step)) = (
            self.last_h_m.get_mut(k).and_then(|s| s.get_mut(j)),
            self.step_h_m.get_mut(k).and_then(|s| s.get_mut(j)),
        ) else {
            return;
        };
        *step = if last.is_finite() && h_m.is_finite() {
            h_m - *last
        } else {
            0.0
        };
        *last = h_m;
    }

    /// Whether the ray's points from h + dh_lo to h + dh_hi (linear in h from the grid
    /// coordinates at h, with the Jacobian's margin) lie in the tile.
    fn inside_over(&self, row: f32, col: f32, dr: f32, dc: f32, dh_lo: f32, dh_hi: f32) -> bool {
        let t = &self.frame;
        let span = |x: f32, dx: f32, last: f32| {
            let (a, b) = (x + dx * dh_lo, x + dx * dh_hi);
            let margin = EDGE_SHARE * (a - b).abs();
            let (lo, hi) = if a < b { (a, b) } else { (b, a) };
            lo - margin >= 0.0 && hi + margin <= last
        };
        span(row, dr, t.last_row) && span(col, dc, t.last_col)
    }

    /// Whether the ray's points over the whole band lie on one side outside the tile.
    fn outside_over(&self, row: f32, col: f32, dr: f32, dc: f32, h: f32) -> bool {
        let t = &self.frame;
        let (dh_lo, dh_hi) = (t.lo_m - h, t.hi_m - h);
        let beyond = |x: f32, dx: f32, last: f32| {
            let (a, b) = (x + dx * dh_lo, x + dx * dh_hi);
            let margin = EDGE_SHARE * (a - b).abs() + 1.0;
            let (lo, hi) = if a < b { (a, b) } else { (b, a) };
            hi + margin < 0.0 || lo - margin > last
        };
        beyond(row, dr, t.last_row) || beyond(col, dc, t.last_col)
    }

    /// The tile at height h on the ray: the raised ellipsoid's near root (the general
    /// form's quadratic, written in the ITRF), the point's grid coordinates, the
    /// bilinear height and its gradient along the ray.
    #[inline(always)]
    fn evaluate(&self, rays: &SegmentRays, ray: &Ray, h: f32) -> Evaluation {
        let t = &self.frame;
        let a = EARTH.a_m as f32;
        let big_a = a + h;
        let big_b = EARTH.b_m() as f32 + h;
        // kappa^2 - 1 = (A - B)(A + B)/B^2, A - B = a f; C = |r|^2 - A^2 + (kappa^2 - 1)
        // r_z^2 without forming A^2 (as `General::ground`).
        let k = a * EARTH.flattening as f32 * (big_a + big_b) / (big_b * big_b);
        let (r, d) = (rays.r, ray.d);
        let c = rays.r2_minus_a2_m2 - (a + big_a) * h + k * r[2] * r[2];
        let alpha = ray.uu + k * d[2] * d[2];
        let beta = ray.rd + k * r[2] * d[2];
        let disc = beta * beta - alpha * c;
        if !(beta < 0.0 && disc > 0.0) {
            return Evaluation::March;
        }
        let sq = Real::sqrt(disc);
        let s = c / (sq - beta);
        // tan^2(theta) = |d|^2 A^2 / disc - 1 (the incidence on the raised ellipsoid).
        let tan2 = ray.uu * big_a * big_a / disc - 1.0;
        // Beyond 72 deg from the vertical the straight-line reach below is not trusted.
        if !(tan2 < MAX_TAN2) {
            return Evaluation::March;
        }
        let ds_dh = -big_a / sq;
        let (drow_dh, dcol_dh) = (ray.jr * ds_dh, ray.jc * ds_dh);
        let x: [f32; 3] = core::array::from_fn(|i| r[i] + s * d[i]);
        let Some((row, col)) = self.grid_at(big_a / big_b, x) else {
            // Beyond the arctangents' reach: far outside the tile unless the ray's
            // stretch through the band spans degrees, which only a grazing one does.
            let stretch_rad = (drow_dh / t.rows_per_rad).abs() + (dcol_dh / t.cols_per_rad).abs();
            return if stretch_rad * (t.hi_m - t.lo_m) < 0.01 {
                Evaluation::Outside
            } else {
                Evaluation::March
            };
        };
        if !(row >= 0.0 && row <= t.last_row && col >= 0.0 && col <= t.last_col) {
            return if self.outside_over(row, col, drow_dh, dcol_dh, h) {
                Evaluation::Outside
            } else {
                Evaluation::March
            };
        }
        // Outside checked first: a tile with steep cells sends the rays it covers to
        // the march, not those it does not.
        let q2 = t.slope2 * tan2;
        if !(q2 < MAX_CONTRACTION * MAX_CONTRACTION) {
            return Evaluation::March;
        }
        let (height, per_row, per_col) = self.bilinear(row, col);
        Evaluation::At {
            s,
            g: height - h,
            dg_dh: per_row * drow_dh + per_col * dcol_dh - 1.0,
            ds_dh,
            q2,
            row,
            col,
            drow_dh,
            dcol_dh,
        }
    }

    /// Grid coordinates (row, column) of a point X of the ellipsoid raised by H (with
    /// k = (a + H)/(b + H)), by the arctangents about the tile's centre
    /// (`HeightSearch::grid_at`'s method); `None` beyond their series' reach.
    #[inline(always)]
    fn grid_at(&self, k: f32, x: [f32; 3]) -> Option<(f32, f32)> {
        let t = &self.frame;
        let p = Real::sqrt(x[0] * x[0] + x[1] * x[1]);
        let tan_lat = k * k * x[2] / p;
        let dlat = atan_small((tan_lat - t.tan_lat_c) / (1.0 + tan_lat * t.tan_lat_c))?;
        let along = x[0] * t.cos_lon_c + x[1] * t.sin_lon_c;
        let across = x[1] * t.cos_lon_c - x[0] * t.sin_lon_c;
        if !(along > 0.0) {
            return None;
        }
        let dlon = atan_small(across / along)?;
        Some((
            t.row_c + dlat * t.rows_per_rad,
            t.col_c + dlon * t.cols_per_rad,
        ))
    }

    /// The bilinear height at grid coordinates in the tile, and its derivatives per row
    /// and per column.
    #[inline(always)]
    fn bilinear(&self, row: f32, col: f32) -> (f32, f32, f32) {
        let t = &self.frame;
        let i = (row as u32).min(t.last_row_cell);
        let j = (col as u32).min(t.last_col_cell);
        let (u, v) = (row - i as f32, col - j as f32);
        let heights = self.tile.heights_m();
        let base = i as usize * t.ncols + j as usize;
        // In range by the tile's construction (nrows x ncols heights); 0 is never read.
        let at = |n: usize| f32::from(heights.get(n).copied().unwrap_or(0));
        let (h00, h01) = (at(base), at(base + 1));
        let (h10, h11) = (at(base + t.ncols), at(base + t.ncols + 1));
        let (east_s, east_n) = (h01 - h00, h11 - h10);
        let south = h00 + east_s * v;
        let north = h10 + east_n * v;
        (
            south + (north - south) * u,
            north - south,
            east_s + (east_n - east_s) * u,
        )
    }
}

/// One sample's ray: d, r.d, |d|^2 = |u|^2, and rows and columns per unit of s.
struct Ray {
    d: [f32; 3],
    rd: f32,
    uu: f32,
    jr: f32,
    jc: f32,
}

#[inline(always)]
fn clamp(x: f32, lo: f32, hi: f32) -> f32 {
    if x > lo {
        if x < hi {
            x
        } else {
            hi
        }
    } else {
        lo
    }
}

/// atan(t) for |t| <= 0.1 by its series to t^9 (below 1e-12 left out); `None` beyond
/// (and for NaN).
#[inline(always)]
fn atan_small(t: f32) -> Option<f32> {
    if !(t.abs() <= 0.1) {
        return None;
    }
    let t2 = t * t;
    Some(t * (1.0 - t2 * (1.0 / 3.0 - t2 * (0.2 - t2 * (1.0 / 7.0 - t2 * (1.0 / 9.0))))))
}

/// (v1, v2) at the row's pixel p2 with the ground at range s: the row form
/// ([`GeneralRowMotion::motion_at_facing`]) with q = C / s in place of the ellipsoid's
/// root, C the one the row was formed with.
#[inline(always)]
pub(crate) fn motion_at_range(
    row: &GeneralRowMotion<f32>,
    c_m2: f32,
    p2_m: f32,
    s: f32,
) -> Result<ImageMotion<f32>, ModelError> {
    let q = c_m2 / s;
    let v1 = row.v1[0] + row.v1[1] * p2_m - row.v1[2] * q;
    if !(v1.abs() >= MIN_V1_MPS as f32) {
        return Err(ModelError::NoAlongTrackMotion);
    }
    let c = &row.v2;
    Ok(ImageMotion {
        v1_mps: v1,
        v2_mps: c[0] + p2_m * (c[1] + c[2] * p2_m) - (c[3] + c[4] * p2_m) * q,
    })
}
