//! A segment's footprint on the tile (which rows and columns its samples' rays can
//! reach) and the footprint carried from the update that made it, with the bound on
//! how far the rays may move before it must be made again.

use super::TileFrame;

/// A segment's row's view of the tile ([`DemGround::footprint`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Footprint {
    pub(super) a_m: f32,
    pub(super) row: f32,
    pub(super) col: f32,
    pub(super) row_per_m: f32,
    pub(super) col_per_m: f32,
    pub(super) row_margin: f32,
    pub(super) col_margin: f32,
    pub(super) last_row: f32,
    pub(super) last_col: f32,
}

impl Footprint {
    /// By how many cells beyond its margins the footprint from p2 `a_m` to `b_m` lies
    /// beyond one edge of the tile (below zero: it reaches the tile).
    pub(super) fn beyond(&self, a_m: f32, b_m: f32) -> f32 {
        let [r_lo, r_hi, c_lo, c_hi] = self.spans(a_m, b_m);
        let larger = |p: f32, q: f32| if p > q { p } else { q };
        larger(
            larger(
                -r_hi - self.row_margin,
                r_lo - self.row_margin - self.last_row,
            ),
            larger(
                -c_hi - self.col_margin,
                c_lo - self.col_margin - self.last_col,
            ),
        )
    }

    /// The rows and columns the footprint from p2 `a_m` to `b_m` spans, without its
    /// margins: [row low, row high, column low, column high] (affine in p2: its ends').
    // Out of line on the M3 (soft float): the carried footprint's check and the
    // extremes' held a copy each (docs/target.md, `m3-flash`).
    #[cfg_attr(all(target_arch = "arm", not(target_abi = "eabihf")), inline(never))]
    #[cfg_attr(
        not(all(target_arch = "arm", not(target_abi = "eabihf"))),
        inline(always)
    )]
    fn spans(&self, a_m: f32, b_m: f32) -> [f32; 4] {
        let (da, db) = (a_m - self.a_m, b_m - self.a_m);
        let (ra, rb) = (
            self.row + self.row_per_m * da,
            self.row + self.row_per_m * db,
        );
        let (ca, cb) = (
            self.col + self.col_per_m * da,
            self.col + self.col_per_m * db,
        );
        let (r_lo, r_hi) = if ra < rb { (ra, rb) } else { (rb, ra) };
        let (c_lo, c_hi) = if ca < cb { (ca, cb) } else { (cb, ca) };
        [r_lo, r_hi, c_lo, c_hi]
    }

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

    /// Whether every sample from p2 `a_m` to `b_m` sees ground off the tile beyond one
    /// and the same edge: the coordinates are affine in p2, so both ends beyond it
    /// put every pixel between them there.
    #[inline(always)]
    pub(crate) fn off_tile_over(&self, a_m: f32, b_m: f32) -> bool {
        let [r_lo, r_hi, c_lo, c_hi] = self.spans(a_m, b_m);
        r_hi + self.row_margin < 0.0
            || r_lo - self.row_margin > self.last_row
            || c_hi + self.col_margin < 0.0
            || c_lo - self.col_margin > self.last_col
    }
}

/// A segment's footprint carried from the update that made it ([`DemGround::footprint`]),
/// its margins widened by `w` cells and by a tenth, with what bounds how far the rays
/// have moved since.
///
/// The bound. Let the ends' rays move from (r, d) to (r', d'), d = d0 + p2 dy
/// (unnormalised, |d| the same for a p2 unless the row changed), by dr = |r' - r| and
/// s |d' - d| at the ray's parameter s at mid-band. The point where a ray meets the
/// raised ellipsoid moves, to first order, by the oblique projection of dr + s (d' - d)
/// along d onto the tangent plane, whose norm is sec(theta): at most
/// sec(theta) (dr + s |d' - d|). [`Carried::holds`] admits a move only while
/// dr^2 + (1.1 s)^2 |d' - d|^2 <= `lim_m2`, which `lim_m2` keeps below (0.005 range)^2
/// and (5 km)^2: dr + s |d' - d| is then under 0.0071 of the range and 7.1 km, the
/// direction turns by at most 0.015 rad (twice |d' - d| / |d|, the unit vector's
/// change), the point moves under 31 km and 0.031 of the range (below), the normal
/// under it turns by under 0.005 rad (radii of curvature above 6 300 km), so theta
/// changes by under 0.02 rad: sec^2 by under 2 tan(theta) 0.02 < 12 % at tan^2 < 9, the
/// first-order step is off by under tan(theta) 0.02 < 6 %, s changes by under 4 %.
/// With 1.25 on sec^2, 1.2 on the step and 1.1 on s, the point moves at most
/// m = 1.2 sec (dr + 1.1 s |d' - d|), m^2 <= 3.6 sec^2 (dr^2 + (1.1 s)^2 |d' - d|^2).
/// Along the raised ellipsoid a point moving m changes latitude by at most m over the
/// least meridian radius, and longitude by at most m over its distance from the axis
/// less 31 km, at least 0.9 of the distance from 310 km on (both with 1 % for chord
/// against arc): each grid coordinate of each end by at most kappa m, kappa the largest
/// of [`TileFrame::rows_per_m_max`], cols per radian over 0.9 of the ends' least
/// distance from the axis, and the tile centre's cols per metre. Every sample's affine
/// coordinate between the ends then moves by at most kappa m; the bow's margin, a share
/// of the ends' L1 distance, by at most 4 `bow_share` kappa m; the band's margin, the
/// rows per metre of height along the ray (the centre's Jacobian, d and sec(theta)) over
/// half the band, by under 6 % through sec(theta) (the 1.1 on the margins) and, through
/// d, by at most kappa sec(theta) |d' - d| / |d| times half the band (5.3 km at most),
/// which is under 0.1 kappa m for ranges above 110 km. So where the carried footprint,
/// its margins 1.1 times the made one's plus w, puts a sample beyond an edge, the
/// footprint made now would put it there too, as long as (1.1 + 4 `bow_share`) kappa m
/// <= w: `lim_m2`.
/// `controller/src/dem_ground/tests.rs`, `a_carried_footprint_holds_within_its_bound`,
/// checks the bound against the ends' true moves in f64 and the samples it skips
/// against `DemTile::first_crossing`.
#[derive(Clone, Copy, Debug)]
pub(super) struct Carried {
    pub(super) footprint: Footprint,
    /// The row's far end (p2, m; the near one is the footprint's `a_m`).
    pub(super) b_m: f32,
    /// r, d0 and dy when the footprint was made.
    pub(super) r: [f32; 3],
    pub(super) d0: [f32; 3],
    pub(super) dy: [f32; 3],
    /// The ends' parameters s at mid-band, their larger tan^2(theta), |u|^2 at p2 = 0.
    pub(super) s: [f32; 2],
    pub(super) tan2: f32,
    pub(super) uu0: f32,
    /// (1.1 s)^2, s the ends' larger parameter at mid-band.
    pub(super) c_d: f32,
    /// The largest dr^2 + c_d |d' - d|^2 (m^2) the widened footprint holds for; NaN
    /// until [`Carried::bound`] (at the update after the one that made it: the first
    /// update over a tile, which makes every segment's, is spared the work).
    pub(super) lim_m2: f32,
}

/// Cells a carried footprint's margins are widened by at least ([`Carried`]): the rays
/// may move a cell's share of it before the footprint is made again.
const CARRY_MIN_CELLS: f32 = 1.0;

impl Carried {
    /// Widens the footprint as made and sets the bound it then holds for.
    #[inline(never)]
    pub(super) fn bound(&mut self, t: &TileFrame) {
        let f = self.footprint;
        let (a_m, b_m) = (f.a_m, self.b_m);
        // Comparisons, not f32::min/max (software calls on the M4F).
        let larger = |p: f32, q: f32| if p > q { p } else { q };
        let smaller = |p: f32, q: f32| if p < q { p } else { q };
        // Wide enough to hold long where the row lies wholly beyond an edge (and
        // still wholly beyond it), a cell otherwise.
        let margin = larger(f.row_margin, f.col_margin);
        let w = larger(CARRY_MIN_CELLS, 0.9 * (f.beyond(a_m, b_m) - 0.1 * margin));
        // The ends' points at mid-band, their squared distances from the axis; from
        // 310 km, that less 31 km is at least 0.9 of it.
        let axis2 = |p2: f32, s: f32| {
            let p: [f32; 2] =
                core::array::from_fn(|i| self.r[i] + s * (self.d0[i] + p2 * self.dy[i]));
            p[0] * p[0] + p[1] * p[1]
        };
        let axis2_m2 = smaller(axis2(a_m, self.s[0]), axis2(b_m, self.s[1]));
        let cols_per_m = 1.01 / 0.9 * t.cols_per_rad;
        let c = t.cols_per_m;
        let kappa2 = larger(
            larger(
                t.rows_per_m_max * t.rows_per_m_max,
                cols_per_m * cols_per_m / axis2_m2,
            ),
            c[0] * c[0] + c[1] * c[1] + c[2] * c[2],
        );
        let share = 1.1 + 4.0 * t.bow_share;
        let range2_m2 = smaller(
            self.s[0] * self.s[0] * (self.uu0 + a_m * a_m),
            self.s[1] * self.s[1] * (self.uu0 + b_m * b_m),
        );
        let lim_m2 = smaller(
            smaller(
                w * w / (share * share * kappa2 * 3.6 * (1.0 + self.tan2)),
                0.005 * 0.005 * range2_m2,
            ),
            5e3 * 5e3,
        );
        let s = 1.1 * larger(self.s[0], self.s[1]);
        self.c_d = s * s;
        // Within 310 km of the axis, no bound: made again at every update.
        self.lim_m2 = if axis2_m2 > 310e3 * 310e3 {
            lim_m2
        } else {
            -1.0
        };
        self.footprint.row_margin = 1.1 * f.row_margin + w;
        self.footprint.col_margin = 1.1 * f.col_margin + w;
    }

    /// Whether the rays at this update (r, d0, dy) and the row's ends are within the
    /// bound the footprint was widened for.
    #[inline(always)]
    pub(super) fn holds(
        &self,
        r: &[f32; 3],
        d0: &[f32; 3],
        dy: &[f32; 3],
        a_m: f32,
        b_m: f32,
    ) -> bool {
        let sq = |x: [f32; 3]| x[0] * x[0] + x[1] * x[1] + x[2] * x[2];
        let dr = sq(core::array::from_fn(|i| r[i] - self.r[i]));
        let dd0: [f32; 3] = core::array::from_fn(|i| d0[i] - self.d0[i]);
        let ddy: [f32; 3] = core::array::from_fn(|i| dy[i] - self.dy[i]);
        let da = sq(core::array::from_fn(|i| dd0[i] + a_m * ddy[i]));
        let db = sq(core::array::from_fn(|i| dd0[i] + b_m * ddy[i]));
        let dd = if da > db { da } else { db };
        a_m == self.footprint.a_m && b_m == self.b_m && dr + self.c_d * dd <= self.lim_m2
    }
}
