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
/// The route's slot of the boresight's ray (the yaw request's ground), after the plan
/// segments': its sample 0.
pub(crate) const BORESIGHT_SLOT: usize = MAX_SEGMENTS;
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
/// Share of sec^2(theta) added to the incidence [`DemGround::locate`] finds, for its
/// f32 rounding (a few units in the last place): tan^2(theta), and so q, then bounds
/// the true one above, and stays above zero for a vertical ray (whose q's square root
/// would otherwise be NaN, stalling the march at its 1 cm floor: docs/controller.md,
/// "The DEM ground").
const TAN2_ROUNDING: f32 = 1e-5;
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
    /// Samples the march in height decided (`DemGround::trace`).
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
#[derive(Clone, Copy, Debug, Default)]
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
    /// Rows per metre along the raised ellipsoids at most: rows per radian over the
    /// least meridian radius of curvature, a (1 - e^2) at the band's foot, with 1 %
    /// for the chord's length against the arc's ([`Carried`]).
    rows_per_m_max: f32,
}

/// The DEM tile in force and what the route keeps between updates.
#[derive(Clone, Debug)]
pub struct DemGround {
    frame: TileFrame,
    /// Whether `frame` is a tile's, in force ([`DemGround::install`]).
    active: bool,
    /// Each plan segment's samples' heights at the last update (NaN: none) and their
    /// change over it (m); after them, at [`BORESIGHT_SLOT`], the boresight's.
    history_m: [[[f32; 2]; MAX_SAMPLES]; MAX_SEGMENTS + 1],
    /// Each plan segment's footprint as last made, widened to hold while the rays move
    /// by less than its bound ([`Carried`]).
    carried: [Option<Carried>; MAX_SEGMENTS],
    /// A sample's ground found ahead of its segment for the yaw request
    /// ([`DemGround::sample_ahead`]): its slot (k x [`MAX_SAMPLES`] + j, else
    /// `usize::MAX`) and range (NaN: outside the tile), which its segment's sweep takes.
    ahead_slot: usize,
    ahead_range: f32,
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
        let mut ground = DemGround::blank();
        ground.install(tile)?;
        Ok(ground)
    }

    /// A route with no tile ([`DemGround::install`] gives it one): what the controller
    /// holds from its construction, in place (the route is 3 KB: made as a value for
    /// each new tile, it passed through the stack of whoever put it in force,
    /// docs/target.md, "Size and time per board").
    #[inline(always)]
    pub(crate) fn blank() -> DemGround {
        DemGround {
            frame: TileFrame::default(),
            active: false,
            // Zeros (a fill), set by `install` before any use.
            history_m: [[[0.0; 2]; MAX_SAMPLES]; MAX_SEGMENTS + 1],
            carried: [None; MAX_SEGMENTS],
            ahead_slot: usize::MAX,
            ahead_range: f32::NAN,
            stats: DemStats::default(),
        }
    }

    /// No tile: the TERRAIN heights are the ground.
    pub(crate) fn clear(&mut self) {
        self.active = false;
    }

    /// Puts the route on `tile` in force in place: its constants (f64 trigonometry,
    /// once per tile), no heights or footprints kept, the counts from zero. On a
    /// refusal nothing changes.
    #[inline(never)]
    pub(crate) fn install(&mut self, tile: &DemTile<'_, i16>) -> Result<(), TileRefusal> {
        self.frame = Self::frame_for(tile)?;
        self.active = true;
        // A loop: the array's literal of NaN pairs was unrolled into stores (flash).
        for pair in self.history_m.iter_mut().flatten() {
            *pair = [f32::NAN, 0.0];
        }
        self.carried.fill(None);
        self.ahead_slot = usize::MAX;
        self.stats = DemStats::default();
        Ok(())
    }

    /// Whether a tile is in force ([`DemGround::install`]).
    pub(crate) fn active(&self) -> bool {
        self.active
    }

    fn frame_for(tile: &DemTile<'_, i16>) -> Result<TileFrame, TileRefusal> {
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
        // One sin_cos each (the same bits as `sin` and `cos` apart, which the flight
        // binary then does not link: docs/target.md, flash).
        let (sl, cl) = core_math::trig_f64::sin_cos(lat_c);
        let (so, co) = core_math::trig_f64::sin_cos(lon_c);
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
            bow_share: (0.02 + 0.02 * tan_small(libm::fabs(lat_c) + MAX_TILE_HALF_DEG.to_radians()))
                as f32,
            rows_per_m_max: (1.01 * rows_per_rad / (EARTH.a_m * (1.0 - e2) + min_m - BAND_MARGIN_M))
                as f32,
        };
        Ok(frame)
    }
}

/// tan(x) for |x| below pi/2, from the sine and cosine the flight binary links anyway:
/// `libm::tan` brings its own argument reduction for huge arguments (6 KB of flash,
/// docs/target.md) that a latitude never needs.
fn tan_small(x: f64) -> f64 {
    let (s, c) = core_math::trig_f64::sin_cos(x);
    s / c
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
    #[cfg(test)]
    pub(crate) fn new(
        ground: &DemGround,
        heights_m: &'h [i16],
        frame: &ItrfFrame,
        p1_m: f32,
        focal_m: f32,
        uu0_m2: f32,
        r2_minus_a2_m2: f32,
    ) -> SegmentRays<'h> {
        let (d0, dy) = Self::directions(frame, p1_m, focal_m);
        Self::from_directions(
            ground,
            heights_m,
            frame.position_m,
            d0,
            dy,
            uu0_m2,
            r2_minus_a2_m2,
        )
    }

    /// d0 = B (p1, 0, -f) and dy = B (0, 1, 0).
    // Out of line on the M3 (docs/target.md, `m3-flash3`): inlined in two or three
    // places, a soft-float copy in each.
    #[cfg_attr(all(target_arch = "arm", not(target_abi = "eabihf")), inline(never))]
    #[cfg_attr(
        not(all(target_arch = "arm", not(target_abi = "eabihf"))),
        inline(always)
    )]
    pub(crate) fn directions(frame: &ItrfFrame, p1_m: f32, focal_m: f32) -> ([f32; 3], [f32; 3]) {
        let b = &frame.camera_to_itrf;
        (
            core::array::from_fn(|i| b[i][0] * p1_m - b[i][2] * focal_m),
            core::array::from_fn(|i| b[i][1]),
        )
    }

    /// [`SegmentRays::new`] from r and the [`SegmentRays::directions`].
    // Out of line on the M3, where each product is a software call: the DEM route's
    // boresight and extremes held a copy each (docs/target.md, `m3-flash`).
    #[cfg_attr(all(target_arch = "arm", not(target_abi = "eabihf")), inline(never))]
    #[cfg_attr(
        not(all(target_arch = "arm", not(target_abi = "eabihf"))),
        inline(always)
    )]
    pub(crate) fn from_directions(
        ground: &DemGround,
        heights_m: &'h [i16],
        r: [f32; 3],
        d0: [f32; 3],
        dy: [f32; 3],
        uu0_m2: f32,
        r2_minus_a2_m2: f32,
    ) -> SegmentRays<'h> {
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

mod edges;
mod footprint;
mod search;

use footprint::Carried;
pub(crate) use footprint::Footprint;
#[cfg(test)]
mod tests;

/// One sample's ray: d, r.d, |d|^2 = |u|^2, and rows and columns per unit of s.
#[derive(Clone, Copy)]
struct Ray {
    d: [f32; 3],
    rd: f32,
    uu: f32,
    jr: f32,
    jc: f32,
}

// Out of line on the M3 (three copies inlined there).
#[cfg_attr(all(target_arch = "arm", not(target_abi = "eabihf")), inline(never))]
#[cfg_attr(
    not(all(target_arch = "arm", not(target_abi = "eabihf"))),
    inline(always)
)]
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

/// atan(t): for |t| <= 0.1 (the tile and its surroundings) by its series to t^5,
/// beyond by `core_math::trig::atan_f32` (points far off the tile, whose coordinates
/// only place them there); `None` for NaN. The terms left out are below t^7/7: in the
/// tile (|t| <= tan 2.5 deg, [`MAX_TILE_HALF_DEG`]) 1.0e-9 of t, under f32's rounding;
/// at |t| = 0.1 (off the tile) 1.4e-8 rad, 9 cm on the ground.
#[inline(always)]
fn atan_small(t: f32) -> Option<f32> {
    if !(t.abs() <= 0.1) {
        return t.is_finite().then(|| atan_far(t));
    }
    let t2 = t * t;
    Some(t * (1.0 - t2 * (1.0 / 3.0 - t2 * 0.2)))
}

/// `atan_f32`'s value, as a call (it inlined a copy here).
#[cold]
fn atan_far(t: f32) -> f32 {
    core_math::trig::atan_reduced(t)
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
