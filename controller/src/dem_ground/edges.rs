//! The tile's edges: where a segment's row sees the tile, and the heights at which one
//! sample's line of sight enters and leaves it (the module's documentation, `super`).

use super::*;

impl DemGround {
    /// The footprint of plan segment `k`'s row carried from an earlier update
    /// ([`Carried`]): widened, and only while the rays (r, d0, dy) have moved less than
    /// its bound since; `None`: [`DemGround::footprint`] makes it again.
    #[inline(always)]
    pub(crate) fn carried_footprint(
        &mut self,
        k: usize,
        r: &[f32; 3],
        d0: &[f32; 3],
        dy: &[f32; 3],
        a_m: f32,
        b_m: f32,
    ) -> Option<Footprint> {
        let t = &self.frame;
        let c = self.carried.get_mut(k)?.as_mut()?;
        if c.lim_m2.is_nan() {
            c.bound(t);
        }
        c.holds(r, d0, dy, a_m, b_m).then_some(c.footprint)
    }

    /// Where plan segment `k`'s row sees the tile: its grid coordinates at mid-band as
    /// an affine function of p2, from the samples at p2 `a_m` and `b_m` (the row's
    /// ends), with a margin for the footprint's bow between them (its section by the
    /// rays' plane, and the grid's meridians converging: [`TileFrame`]'s share of the
    /// ends' distance) and for each sample's stretch through the band. A sample the
    /// function puts beyond an edge by more than the margin sees ground off the tile,
    /// for no evaluation. `None`: an end the route cannot place (the samples are each
    /// evaluated). Kept, widened, for later updates ([`DemGround::carried_footprint`]).
    pub(crate) fn footprint(
        &mut self,
        k: usize,
        rays: &SegmentRays,
        a_m: f32,
        b_m: f32,
    ) -> Option<Footprint> {
        *self.carried.get_mut(k)? = None;
        let t = &self.frame;
        let h = 0.5 * (t.lo_m + t.hi_m);
        let ray = |p2: f32| Ray {
            d: core::array::from_fn(|i| rays.d0[i] + p2 * rays.dy[i]),
            rd: rays.rd0 + p2 * rays.rdy,
            uu: rays.uu0 + p2 * p2,
            jr: rays.jr0 + p2 * rays.jry,
            jc: rays.jc0 + p2 * rays.jcy,
        };
        let (ray_a, ray_b) = (ray(a_m), ray(b_m));
        let x = self.locate(rays, &ray_a, h)?;
        let y = self.locate(rays, &ray_b, h)?;
        let t = &self.frame;
        if !(x.tan2 < MAX_TAN2 && y.tan2 < MAX_TAN2 && b_m != a_m) {
            return None;
        }
        let bow = t.bow_share * ((x.row - y.row).abs() + (x.col - y.col).abs()) + 2.0;
        let half = 0.5 * (t.hi_m - t.lo_m) * (1.0 + EDGE_SHARE);
        // Comparisons, not f32::min/max (software calls on the M4F).
        let larger = |p: f32, q: f32| if p > q { p } else { q };
        let per_m = 1.0 / (b_m - a_m);
        let f = Footprint {
            a_m,
            row: x.row,
            col: x.col,
            row_per_m: (y.row - x.row) * per_m,
            col_per_m: (y.col - x.col) * per_m,
            row_margin: bow + larger(x.drow_dh.abs(), y.drow_dh.abs()) * half,
            col_margin: bow + larger(x.dcol_dh.abs(), y.dcol_dh.abs()) * half,
            last_row: t.last_row,
            last_col: t.last_col,
        };
        // Kept for the carried form ([`Carried::bound`], made at the next update).
        let carried = Carried {
            footprint: f,
            b_m,
            r: rays.r,
            d0: rays.d0,
            dy: rays.dy,
            s: [x.s, y.s],
            tan2: larger(x.tan2, y.tan2),
            uu0: rays.uu0,
            c_d: 0.0,
            lim_m2: f32::NAN,
        };
        if let Some(slot) = self.carried.get_mut(k) {
            *slot = Some(carried);
        }
        Some(f)
    }

    /// The stretch of the ray through the band that lies in the tile, from a point of
    /// it `at` height h: its ends from the grid coordinates' rates, the edge it enters
    /// by and the one it leaves by found exactly ([`DemGround::edge_height`]). A ray
    /// entering the tile on or below its surface has not passed from above it there
    /// (the march's rule); where g is `monotone` (q < 1) it then stays below in the
    /// tile, and one leaving the tile above the surface was above all along: no ground
    /// in the tile. `None`: the march in height decides.
    pub(super) fn edges(
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
    pub(super) fn edge_height(
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
    pub(super) fn g_on_edge(&self, rays: &SegmentRays, ray: &Ray, h: f32) -> Option<f32> {
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
}
