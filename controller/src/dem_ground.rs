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
/// The march in height stops this close above the surface (m; the f32 march's 0.5 m
/// with the f32 geodetic height's rounding).
pub const TRACE_TOLERANCE_M: f32 = 1.0;
/// Most evaluations of the march in height.
pub const MAX_TRACE: u32 = 128;
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
    /// Samples the march in height decided ([`DemGround::trace`]).
    pub traced: u32,
    /// Samples neither could place (grazing rays, traces too long): the segment's
    /// TERRAIN height.
    pub unresolved: u32,
    /// Samples outside the tile: the segment's TERRAIN height.
    pub outside: u32,
    /// Samples whose ray's stretch through the band meets the tile's edge, settled by
    /// its entry and exit heights (counted also as searched or outside).
    pub edges: u32,
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
    /// A row's footprint bows from its chord in grid coordinates by at most this share
    /// of the chord ([`DemGround::footprint`]): an eighth of L/R for the rays' plane's
    /// section (R over 5 000 km for pitches to 40 deg), and L tan(lat) / (2R) for the
    /// converging meridians, with L at most 500 km: 0.02 + 0.02 tan(lat) at the tile's
    /// largest |latitude|.
    bow_share: f32,
}

/// The DEM tile in force and what the route keeps between updates.
#[derive(Clone, Debug)]
pub struct DemGround {
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
    pub fn new(tile: &DemTile<'_, i16>) -> Result<DemGround, TileRefusal> {
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
            bow_share: (0.02 + 0.02 * libm::tan(libm::fabs(lat_c) + MAX_TILE_HALF_DEG.to_radians()))
                as f32,
        };
        Ok(DemGround {
            frame,
            last_h_m: [[f32::NAN; MAX_SAMPLES]; MAX_SEGMENTS],
            step_h_m: [[0.0; MAX_SAMPLES]; MAX_SEGMENTS],
            stats: DemStats::default(),
        })
    }
}

/// A segment's row's view of the tile ([`DemGround::footprint`]).
#[derive(Clone, Copy)]
pub(crate) struct Footprint {
    a_m: f32,
    row: f32,
    col: f32,
    row_per_m: f32,
    col_per_m: f32,
    row_margin: f32,
    col_margin: f32,
    last_row: f32,
    last_col: f32,
}

impl Footprint {
    /// Whether the sample at p2 sees ground off the tile.
    #[inline(always)]
    pub(crate) fn off_tile(&self, p2_m: f32) -> bool {
        let dp = p2_m - self.a_m;
        let row = self.row + self.row_per_m * dp;
        let col = self.col + self.col_per_m * dp;
        row + self.row_margin < 0.0
            || row - self.row_margin > self.last_row
            || col + self.col_margin < 0.0
            || col - self.col_margin > self.last_col
    }
}

/// One segment's rays at one update: d = d0 + p2 dy (the camera's row p1 turned into
/// the ITRF), with what every evaluation reads.
pub(crate) struct SegmentRays<'h> {
    /// The heights of the tile the route was made for (its grid's, row-major): lent
    /// per update by whoever holds the tile.
    heights_m: &'h [i16],
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

impl<'h> SegmentRays<'h> {
    pub(crate) fn new(
        ground: &DemGround,
        heights_m: &'h [i16],
        frame: &ItrfFrame,
        p1_m: f32,
        focal_m: f32,
        uu0_m2: f32,
        r2_minus_a2_m2: f32,
    ) -> SegmentRays<'h> {
        let b = &frame.camera_to_itrf;
        let r = frame.position_m;
        // B (p1, 0, -f) and B (0, 1, 0).
        let d0: [f32; 3] = core::array::from_fn(|i| b[i][0] * p1_m - b[i][2] * focal_m);
        let dy: [f32; 3] = core::array::from_fn(|i| b[i][1]);
        let dot = |x: [f32; 3], y: [f32; 3]| x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
        let t = &ground.frame;
        SegmentRays {
            heights_m,
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

/// Where the ray meets the ellipsoid raised by h: its range, the point's grid
/// coordinates, and the changes of both per metre of h.
#[derive(Clone, Copy)]
struct Located {
    s: f32,
    ds_dh: f32,
    row: f32,
    col: f32,
    drow_dh: f32,
    dcol_dh: f32,
    /// tan^2 of the ray's angle from the vertical there.
    tan2: f32,
}

/// One evaluation of the tile at height h on one ray.
enum Evaluation {
    /// In the tile: g = D - h and dg/dh, q^2 = S^2 tan^2(theta).
    At {
        at: Located,
        g: f32,
        dg_dh: f32,
        q2: f32,
    },
    /// The ray's stretch through the band lies outside the tile.
    Outside,
    /// Outside the tile, its stretch through the band reaching into it.
    Off(Located),
    /// The march decides (grazing or steep).
    March,
}

/// What the tile's edges leave of a ray's search.
enum Edges {
    Done(SampleGround),
    /// The stretch in the tile, as the heights of its ends (m), and whether the ray
    /// enters the tile on or below its surface.
    Within(f32, f32, bool),
}

/// Grid coordinates within this many cells outside the tile count as on its edge.
const EDGE_SLACK_CELLS: f32 = 1e-3;
/// The edges' heights are found to this (m of height).
const EDGE_TOLERANCE_M: f32 = 0.5;

impl DemGround {
    /// The ground of sample `j` of plan segment `k` at pixel p2 (m) on `rays`: see the
    /// module. `terrain_h_m` starts the search on the first update.
    #[inline(never)]
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
        let (band_lo, band_hi) = (self.frame.lo_m, self.frame.hi_m);
        let (last, step) = (self.slot(k, j, true), self.slot(k, j, false));
        let start = if last.is_finite() {
            last + step
        } else {
            terrain_h_m
        };
        let mut h = clamp(start, band_lo, band_hi);
        let (mut lo, mut hi) = (band_lo, band_hi);
        let mut edges_done = false;
        for n in 1..=MAX_EVALUATIONS {
            let found = match self.evaluate(rays, &ray, h) {
                Evaluation::Outside => Some(SampleGround::Outside),
                Evaluation::March => break,
                Evaluation::Off(at) if !edges_done => {
                    edges_done = true;
                    let monotone = self.frame.slope2 * at.tan2 < MAX_CONTRACTION * MAX_CONTRACTION;
                    match self.edges(rays, &ray, h, &at, monotone) {
                        Some(Edges::Done(found)) => Some(found),
                        Some(Edges::Within(l, u, false)) if monotone => {
                            self.stats.edges += 1;
                            (lo, hi) = (l, u);
                            h = 0.5 * (l + u);
                            None
                        }
                        _ => break,
                    }
                }
                // An iterate off the tile once its edges are known: rounding at them.
                Evaluation::Off(_) => break,
                Evaluation::At { at, g, dg_dh, q2 } => {
                    let tol = HEIGHT_TOLERANCE_M;
                    // q (|g| + tol) <= tol: the fixed-point step h + g is within
                    // q |g| / (1 - q) <= tol of H*.
                    let a = g.abs() + tol;
                    if q2 * a * a <= tol * tol {
                        // H* lies within |g| / (1 - q) of h: where that stretch lies in
                        // the tile, the crossing there is the only one in it.
                        let reach = g.abs() * 5.0 + 1.0;
                        if self.inside_over(&at, -reach, reach) {
                            self.stats.searched += 1;
                            self.stats.evaluations += n;
                            self.remember(k, j, h + g);
                            return Ok(SampleGround::Range(at.s + g * at.ds_dh));
                        }
                        if edges_done {
                            break;
                        }
                        edges_done = true;
                        match self.edges(rays, &ray, h, &at, true) {
                            Some(Edges::Done(found)) => Some(found),
                            Some(Edges::Within(l, u, false)) => {
                                self.stats.edges += 1;
                                (lo, hi) = (l, u);
                                h = clamp(h + g, l, u);
                                None
                            }
                            _ => break,
                        }
                    } else {
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
                        None
                    }
                }
            };
            if let Some(found) = found {
                // Only the edges' route settles a sample here: off the tile.
                self.stats.outside += 1;
                self.stats.edges += 1;
                self.remember(k, j, f32::NAN);
                return Ok(found);
            }
        }
        self.remember(k, j, f32::NAN);
        Ok(match self.trace(rays, &ray) {
            Some(found) => {
                self.stats.traced += 1;
                found
            }
            None => {
                self.stats.unresolved += 1;
                SampleGround::Outside
            }
        })
    }

    /// The march in height, for what the search in height cannot certify (steep
    /// terrain, the steps not settling): from the top of the band (or where the ray
    /// enters the tile) down, steps of |g| / (1 + q) in h, which cannot pass a crossing
    /// (g changes by at most 1 + q per metre of h in the tile), until the ray is within
    /// [`TRACE_TOLERANCE_M`] above the surface (the march's own test), leaves the tile,
    /// or [`MAX_TRACE`] evaluations. `None` (the segment's TERRAIN height, counted
    /// `unresolved`): a ray beyond 72 deg from the vertical, where the descending half of
    /// the ray is not the whole story, or a trace too long.
    #[inline(never)]
    fn trace(&self, rays: &SegmentRays, ray: &Ray) -> Option<SampleGround> {
        let t = &self.frame;
        let (mut h, mut lo) = (t.hi_m, t.lo_m);
        let mut edges_done = false;
        // A crossing is a passage from above: the top of the band is above the surface,
        // a ray entering through the tile's edge may not be.
        let mut above = true;
        for _ in 0..MAX_TRACE {
            let at = self.locate(rays, ray, h)?;
            if !(at.tan2 < MAX_TAN2) {
                return None;
            }
            let (row, col) = (at.row, at.col);
            if !(row >= 0.0 && row <= t.last_row && col >= 0.0 && col <= t.last_col) {
                if edges_done || self.outside_over(&at, h) {
                    // Left the tile above its surface, or never in it.
                    return Some(SampleGround::Outside);
                }
                edges_done = true;
                match self.edges(rays, ray, h, &at, false)? {
                    Edges::Done(found) => return Some(found),
                    Edges::Within(l, u, below) => {
                        // Just inside the entry, found to within EDGE_TOLERANCE_M.
                        (h, lo, above) = (u - 2.0 * EDGE_TOLERANCE_M, l, !below);
                        continue;
                    }
                }
            }
            let (height, _, _) = self.bilinear(rays.heights_m, row, col);
            let g = height - h;
            if g >= -TRACE_TOLERANCE_M {
                if above {
                    return Some(SampleGround::Range(at.s));
                }
            } else {
                above = true;
            }
            // From below the surface the same step cannot pass the point the ray comes
            // out above it.
            let q = Real::sqrt(t.slope2 * at.tan2);
            let step = g.abs() / (1.0 + q);
            h -= if step > 0.01 { step } else { 0.01 };
            if h < lo {
                return Some(SampleGround::Outside);
            }
        }
        None
    }

    /// Where a segment's row sees the tile: its grid coordinates at mid-band as an
    /// affine function of p2, from the samples at p2 `a_m` and `b_m` (the row's ends),
    /// with a margin for the footprint's bow between them (its section by the rays'
    /// plane, and the grid's meridians converging: [`TileFrame`]'s share of the ends'
    /// distance) and for each sample's stretch through the band. A sample the function
    /// puts beyond an edge by more than the margin sees ground off the tile, for no
    /// evaluation. `None`: an end the route cannot place (the samples are each
    /// evaluated).
    pub(crate) fn footprint(&self, rays: &SegmentRays, a_m: f32, b_m: f32) -> Option<Footprint> {
        let t = &self.frame;
        let h = 0.5 * (t.lo_m + t.hi_m);
        let ray = |p2: f32| Ray {
            d: core::array::from_fn(|i| rays.d0[i] + p2 * rays.dy[i]),
            rd: rays.rd0 + p2 * rays.rdy,
            uu: rays.uu0 + p2 * p2,
            jr: rays.jr0 + p2 * rays.jry,
            jc: rays.jc0 + p2 * rays.jcy,
        };
        let x = self.locate(rays, &ray(a_m), h)?;
        let y = self.locate(rays, &ray(b_m), h)?;
        if !(x.tan2 < MAX_TAN2 && y.tan2 < MAX_TAN2 && b_m != a_m) {
            return None;
        }
        let bow = t.bow_share * ((x.row - y.row).abs() + (x.col - y.col).abs()) + 2.0;
        let half = 0.5 * (t.hi_m - t.lo_m) * (1.0 + EDGE_SHARE);
        let larger = |p: f32, q: f32| if p.abs() > q.abs() { p.abs() } else { q.abs() };
        let per_m = 1.0 / (b_m - a_m);
        Some(Footprint {
            a_m,
            row: x.row,
            col: x.col,
            row_per_m: (y.row - x.row) * per_m,
            col_per_m: (y.col - x.col) * per_m,
            row_margin: bow + larger(x.drow_dh, y.drow_dh) * half,
            col_margin: bow + larger(x.dcol_dh, y.dcol_dh) * half,
            last_row: t.last_row,
            last_col: t.last_col,
        })
    }

    /// The stretch of the ray through the band that lies in the tile, from a point of
    /// it `at` height h: its ends from the grid coordinates' rates, the edge it enters
    /// by and the one it leaves by found exactly ([`DemGround::edge_height`]). A ray
    /// entering the tile on or below its surface has not passed from above it there
    /// (the march's rule); where g is `monotone` (q < 1) it then stays below in the
    /// tile, and one leaving the tile above the surface was above all along: no ground
    /// in the tile. `None`: the march in height decides.
    fn edges(
        &self,
        rays: &SegmentRays,
        ray: &Ray,
        h: f32,
        at: &Located,
        monotone: bool,
    ) -> Option<Edges> {
        let t = &self.frame;
        let (mut lo, mut hi) = (t.lo_m, t.hi_m);
        let (mut top, mut bottom) = (None, None);
        for (axis, x, dx, last) in [
            (0, at.row, at.drow_dh, t.last_row),
            (1, at.col, at.dcol_dh, t.last_col),
        ] {
            if !(dx.abs() > 1e-9) {
                if !(x >= 0.0 && x <= last) {
                    return None;
                }
                continue;
            }
            // The heights where the coordinate reaches 0 and `last`.
            let (h0, h1) = (h - x / dx, h + (last - x) / dx);
            let (a, edge_a, b, edge_b) = if h0 < h1 {
                (h0, 0.0, h1, last)
            } else {
                (h1, last, h0, 0.0)
            };
            if a > lo {
                lo = a;
                bottom = Some((axis, edge_a));
            }
            if b < hi {
                hi = b;
                top = Some((axis, edge_b));
            }
        }
        // Clearly no stretch in the tile (the rates' error, 10 %, on the way there).
        let way = (hi - h).abs() + (lo - h).abs();
        if lo - hi > EDGE_SHARE * way + 10.0 {
            return Some(Edges::Done(SampleGround::Outside));
        }
        let mut below = false;
        if let Some((axis, edge)) = top {
            let h_in = self.edge_height(rays, ray, axis, edge, hi)?;
            let g = self.g_on_edge(rays, ray, h_in)?;
            // Entering on or below the surface is no crossing (one is a passage from
            // above); where g is monotone the ray stays below in the tile.
            below = g >= -TRACE_TOLERANCE_M;
            if below && monotone {
                return Some(Edges::Done(SampleGround::Outside));
            }
            hi = h_in;
        }
        if let Some((axis, edge)) = bottom {
            let h_out = self.edge_height(rays, ray, axis, edge, lo)?;
            // Leaving above the surface where g is monotone: it was above all along.
            if monotone && self.g_on_edge(rays, ray, h_out)? < 0.0 {
                return Some(Edges::Done(SampleGround::Outside));
            }
            lo = h_out;
        }
        (lo < hi).then_some(Edges::Within(lo, hi, below))
    }

    /// The height where the ray's grid coordinate `axis` (0: row, 1: column) equals
    /// `edge`, from the estimate `h_est`: a Newton step on the coordinate's rate, then
    /// secant steps on exact points, to [`EDGE_TOLERANCE_M`].
    fn edge_height(
        &self,
        rays: &SegmentRays,
        ray: &Ray,
        axis: u8,
        edge: f32,
        h_est: f32,
    ) -> Option<f32> {
        let mut h = h_est;
        let mut prev: Option<(f32, f32)> = None;
        for _ in 0..4 {
            let at = self.locate(rays, ray, h)?;
            let (x, dx) = if axis == 0 {
                (at.row, at.drow_dh)
            } else {
                (at.col, at.dcol_dh)
            };
            let next = match prev {
                Some((hp, xp)) if xp != x => h + (edge - x) * (h - hp) / (x - xp),
                _ => h + (edge - x) / dx,
            };
            if (next - h).abs() <= EDGE_TOLERANCE_M {
                return Some(next);
            }
            prev = Some((h, x));
            h = next;
        }
        None
    }

    /// g = D - h at a point of the ray on the tile's edge (its grid coordinates within
    /// [`EDGE_SLACK_CELLS`] of the tile, clamped onto it).
    fn g_on_edge(&self, rays: &SegmentRays, ray: &Ray, h: f32) -> Option<f32> {
        let t = &self.frame;
        let at = self.locate(rays, ray, h)?;
        let e = EDGE_SLACK_CELLS;
        if !(at.row >= -e && at.row <= t.last_row + e && at.col >= -e && at.col <= t.last_col + e) {
            return None;
        }
        let row = clamp(at.row, 0.0, t.last_row);
        let col = clamp(at.col, 0.0, t.last_col);
        let (height, _, _) = self.bilinear(rays.heights_m, row, col);
        Some(height - h)
    }

    /// Notes sample `j` of plan segment `k` as off the tile by its segment's footprint.
    pub(crate) fn off_tile(&mut self, k: usize, j: usize) {
        self.stats.outside += 1;
        self.remember(k, j, f32::NAN);
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
    /// coordinates `at` h, with the rates' margin) lie in the tile.
    fn inside_over(&self, at: &Located, dh_lo: f32, dh_hi: f32) -> bool {
        let t = &self.frame;
        let span = |x: f32, dx: f32, last: f32| {
            let (a, b) = (x + dx * dh_lo, x + dx * dh_hi);
            let margin = EDGE_SHARE * (a - b).abs();
            let (lo, hi) = if a < b { (a, b) } else { (b, a) };
            lo - margin >= 0.0 && hi + margin <= last
        };
        span(at.row, at.drow_dh, t.last_row) && span(at.col, at.dcol_dh, t.last_col)
    }

    /// Whether the ray's points over the whole band lie on one side outside the tile.
    fn outside_over(&self, at: &Located, h: f32) -> bool {
        let t = &self.frame;
        let (dh_lo, dh_hi) = (t.lo_m - h, t.hi_m - h);
        let beyond = |x: f32, dx: f32, last: f32| {
            let (a, b) = (x + dx * dh_lo, x + dx * dh_hi);
            let margin = EDGE_SHARE * (a - b).abs() + 1.0;
            let (lo, hi) = if a < b { (a, b) } else { (b, a) };
            hi + margin < 0.0 || lo - margin > last
        };
        beyond(at.row, at.drow_dh, t.last_row) || beyond(at.col, at.dcol_dh, t.last_col)
    }

    /// Where the ray meets the ellipsoid raised by h (the general form's quadratic,
    /// written in the ITRF), and that point's grid coordinates; `None` where it misses
    /// that ellipsoid, or the point is beyond the grid coordinates' reach.
    #[inline(never)]
    fn locate(&self, rays: &SegmentRays, ray: &Ray, h: f32) -> Option<Located> {
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
            return None;
        }
        let sq = Real::sqrt(disc);
        let s = c / (sq - beta);
        let ds_dh = -big_a / sq;
        let x: [f32; 3] = core::array::from_fn(|i| r[i] + s * d[i]);
        let (row, col) = self.grid_at(big_a / big_b, x)?;
        Some(Located {
            s,
            ds_dh,
            row,
            col,
            drow_dh: ray.jr * ds_dh,
            dcol_dh: ray.jc * ds_dh,
            // tan^2(theta) = |d|^2 A^2 / disc - 1 (the incidence on the raised
            // ellipsoid).
            tan2: ray.uu * big_a * big_a / disc - 1.0,
        })
    }

    /// The tile at height h on the ray: [`DemGround::locate`], then the bilinear height
    /// and its gradient along the ray.
    #[inline(always)]
    fn evaluate(&self, rays: &SegmentRays, ray: &Ray, h: f32) -> Evaluation {
        let t = &self.frame;
        let Some(at) = self.locate(rays, ray, h) else {
            // A miss of this raised ellipsoid (a grazing ray), or a point a quarter of
            // the globe from the tile.
            return Evaluation::March;
        };
        // Beyond 72 deg from the vertical the straight-line reach is not trusted.
        if !(at.tan2 < MAX_TAN2) {
            return Evaluation::March;
        }
        let (row, col) = (at.row, at.col);
        if !(row >= 0.0 && row <= t.last_row && col >= 0.0 && col <= t.last_col) {
            return if self.outside_over(&at, h) {
                Evaluation::Outside
            } else {
                Evaluation::Off(at)
            };
        }
        // Outside checked first: a tile with steep cells sends the rays it covers to
        // the march, not those it does not.
        let q2 = t.slope2 * at.tan2;
        if !(q2 < MAX_CONTRACTION * MAX_CONTRACTION) {
            return Evaluation::March;
        }
        let (height, per_row, per_col) = self.bilinear(rays.heights_m, row, col);
        Evaluation::At {
            at,
            g: height - h,
            dg_dh: per_row * at.drow_dh + per_col * at.dcol_dh - 1.0,
            q2,
        }
    }

    /// Grid coordinates (row, column) of a point X of the ellipsoid raised by H (with
    /// k = (a + H)/(b + H)), by the arctangents about the tile's centre
    /// (`HeightSearch::grid_at`'s method); `None` for a point a quarter of the globe
    /// from the tile's meridian.
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
    fn bilinear(&self, heights: &[i16], row: f32, col: f32) -> (f32, f32, f32) {
        let t = &self.frame;
        let i = (row as u32).min(t.last_row_cell);
        let j = (col as u32).min(t.last_col_cell);
        let (u, v) = (row - i as f32, col - j as f32);
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

/// atan(t): for |t| <= 0.1 (the tile and its surroundings) by its series to t^9
/// (below 1e-12 left out), beyond by `core_math::trig::atan_f32` (points far off the
/// tile, whose coordinates only place them there); `None` for NaN.
#[inline(always)]
fn atan_small(t: f32) -> Option<f32> {
    if !(t.abs() <= 0.1) {
        return t.is_finite().then(|| atan_far(t));
    }
    let t2 = t * t;
    Some(t * (1.0 - t2 * (1.0 / 3.0 - t2 * (0.2 - t2 * (1.0 / 7.0 - t2 * (1.0 / 9.0))))))
}

#[cold]
#[inline(never)]
fn atan_far(t: f32) -> f32 {
    core_math::trig::atan_f32(t)
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

#[cfg(test)]
mod tests {
    extern crate std;
    use std::boxed::Box;
    use std::vec::Vec;

    use super::{DemGround, SampleGround, SegmentRays};
    use crate::config::EARTH;
    use crate::track::ItrfFrame;
    use core_math::earth::dem::{DemGrid, DemTile};
    use core_math::ModelError;

    /// ITRF point of geodetic (lat, lon, h) on WGS 84 (deg, deg, m).
    fn itrf(lat_deg: f64, lon_deg: f64, h_m: f64) -> [f64; 3] {
        let (lat, lon) = (lat_deg.to_radians(), lon_deg.to_radians());
        let e2 = EARTH.flattening * (2.0 - EARTH.flattening);
        let n = EARTH.a_m / (1.0 - e2 * lat.sin() * lat.sin()).sqrt();
        [
            (n + h_m) * lat.cos() * lon.cos(),
            (n + h_m) * lat.cos() * lon.sin(),
            (n * (1.0 - e2) + h_m) * lat.sin(),
        ]
    }

    fn unit(x: [f64; 3]) -> [f64; 3] {
        let n = (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
        x.map(|v| v / n)
    }

    fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    }

    /// Rays swept across each edge of a tile whose relief rises to 5 000 m along its
    /// edges, from a satellite 700 km up looking 40 deg from the vertical into the
    /// tile (entering it through the edge) and out of it (leaving through the edge):
    /// each sample's range against `DemTile::first_crossing` in f64 (the march, the
    /// reference's ground), the ray's side of the tile included.
    #[test]
    fn rays_across_the_edges_match_the_march() {
        // A rim rising to 5 000 m over 6 cells (slopes to 0.6 with the ripple: the march
        // in height), and to 3 500 m over 12 cells (0.35: the search in height).
        let searched = edges_against_the_march(4_000.0, 6.0);
        assert_eq!(searched, 0);
        let searched = edges_against_the_march(2_500.0, 12.0);
        assert!(searched > 1_000, "{searched}");
    }

    /// [`rays_across_the_edges_match_the_march`] over a rim of `rim_m` falling off over
    /// `width` cells; the samples the search in height took.
    fn edges_against_the_march(rim_m: f64, width: f64) -> u32 {
        let (lat_c, lon_c, side, step) = (45.0, 10.0, 61usize, 0.01);
        let half = 0.5 * (side - 1) as f64 * step;
        let grid = DemGrid {
            lat0_deg: lat_c - half,
            lon0_deg: lon_c - half,
            dlat_deg: step,
            dlon_deg: step,
            nrows: side,
            ncols: side,
        };
        let last = (side - 1) as f64;
        let heights: Vec<i16> = (0..side * side)
            .map(|k| {
                let (i, j) = ((k / side) as f64, (k % side) as f64);
                let d = i.min(j).min(last - i).min(last - j);
                (1_000.0 + rim_m * (-d / width).exp() + 300.0 * (0.3 * i + 0.2 * j).sin()) as i16
            })
            .collect();
        let tile = DemTile::new(grid, Box::leak(heights.into_boxed_slice())).unwrap();
        let mut ground = DemGround::new(&tile).unwrap();
        let focal = 0.555f64;
        let (mut checked, mut walls, mut worst_m) = (0, 0, 0f64);
        // (edge point, direction into the tile) for the west, east, south, north edges.
        let edges = [
            ((lat_c, lon_c - half), (0.0, 1.0)),
            ((lat_c, lon_c + half), (0.0, -1.0)),
            ((lat_c - half, lon_c), (1.0, 0.0)),
            ((lat_c + half, lon_c), (-1.0, 0.0)),
        ];
        for ((lat, lon), (north_in, east_in)) in edges {
            for inward in [1.0, -1.0] {
                let t = itrf(lat, lon, 3_000.0);
                let up = unit(t);
                let east = unit([-t[1], t[0], 0.0]);
                let north = cross(up, east);
                let across: [f64; 3] =
                    core::array::from_fn(|i| inward * (north_in * north[i] + east_in * east[i]));
                // The satellite 700 km along the ray back from the edge point.
                let (c, s) = (40f64.to_radians().cos(), 40f64.to_radians().sin());
                let look = unit(core::array::from_fn(|i| -c * up[i] + s * across[i]));
                let r: [f64; 3] = core::array::from_fn(|i| t[i] - 700e3 / c * look[i]);
                // Camera axes: z = -look, y across the edge's normal plane (so the row
                // sweeps across the edge), x = y cross z.
                let z = look.map(|v| -v);
                let y = unit(cross(z, cross(across, z)));
                let x = cross(y, z);
                let b: [[f64; 3]; 3] = core::array::from_fn(|i| [x[i], y[i], z[i]]);
                let frame = ItrfFrame {
                    position_m: r.map(|v| v as f32),
                    camera_to_itrf: b.map(|row| row.map(|v| v as f32)),
                };
                let r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
                let rays = SegmentRays::new(
                    &ground,
                    tile.heights_m(),
                    &frame,
                    0.0,
                    focal as f32,
                    (focal * focal) as f32,
                    (r2 - EARTH.a_m * EARTH.a_m) as f32,
                );
                for n in -400..=400 {
                    // p2 over +-8 mm: +-10 km across the edge at 700 km.
                    let p2 = n as f64 * 2e-5;
                    let d: [f64; 3] = core::array::from_fn(|i| b[i][1] * p2 - b[i][2] * focal);
                    let want = tile.first_crossing::<f64>(&EARTH, r, d);
                    let got = ground.sample(0, 0, &rays, p2 as f32, 0.0).unwrap();
                    let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
                    match (got, want) {
                        (SampleGround::Range(s), Ok(s_ref)) => {
                            let off_m = (f64::from(s) - s_ref).abs() * len;
                            worst_m = worst_m.max(off_m);
                            assert!(off_m <= 10.0, "p2 {p2}: {s} vs {s_ref} ({off_m} m)");
                        }
                        (SampleGround::Outside, Err(ModelError::OutsideDem)) => {}
                        (g, w) => {
                            // Either outcome only where the march's answer is a hair
                            // from the edge (the contract's rule at the tile's edge).
                            let g = match g {
                                SampleGround::Range(s) => Some(s),
                                SampleGround::Outside => None,
                            };
                            let geo = w.ok().map(|s| {
                                let x: [f64; 3] = core::array::from_fn(|i| r[i] + s * d[i]);
                                core_math::earth::frames::geodetic_from_itrf(x, &EARTH)
                                    .map(|(la, lo, h)| (la.to_degrees(), lo.to_degrees(), h))
                            });
                            panic!(
                                "edge ({lat}, {lon}) inward {inward} p2 {p2}: route {g:?}, \
                                 march {w:?} at {geo:?}; {:?}",
                                ground.stats
                            );
                        }
                    }
                    checked += 1;
                }
                walls += ground.stats.edges;
                ground.stats.edges = 0;
            }
        }
        std::eprintln!(
            "edges (rim {rim_m} m over {width} cells): {checked} rays, worst range \
             {worst_m:.2} m from the march's, {walls} settled at the edge; {:?}",
            ground.stats
        );
        assert!(walls > 0, "no ray's stretch met the tile's edge");
        ground.stats.searched
    }
}
