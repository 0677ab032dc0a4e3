//! The search for one sample's ground: the certified step, Newton's steps in their
//! bracket, the march in height, and the tile's bilinear surface under a point (the
//! module's documentation, `super`).

use super::*;

impl DemGround {
    /// The ground of sample `j` of plan segment `k` at pixel p2 (m) on `rays`: see the
    /// module. `terrain_h_m` starts the search on the first update.
    #[inline(always)]
    pub(crate) fn sample(
        &mut self,
        k: usize,
        j: usize,
        rays: &SegmentRays,
        p2_m: f32,
        terrain_h_m: f32,
    ) -> Result<SampleGround, ModelError> {
        if k * MAX_SAMPLES + j == self.ahead_slot {
            self.ahead_slot = usize::MAX;
            let s = self.ahead_range;
            return Ok(if s.is_nan() {
                SampleGround::Outside
            } else {
                SampleGround::Range(s)
            });
        }
        self.find(k, j, rays, p2_m, terrain_h_m)
    }

    /// [`DemGround::sample`]'s work, where no answer was found ahead.
    #[inline(never)]
    fn find(
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
        let [last, step] = self.slot(k, j);
        if last.is_finite() {
            // The steady state: the search's first step alone, from the last height and
            // its change, where it certifies (as the search below would at n = 1).
            let h = clamp(last + step, self.frame.lo_m, self.frame.hi_m);
            if let Evaluation::At { at, g, q2, .. } = self.evaluate(rays, &ray, h) {
                let tol = HEIGHT_TOLERANCE_M;
                let a = g.abs() + tol;
                let reach = g.abs() * 5.0 + 1.0;
                if q2 * a * a <= tol * tol && self.inside_over(&at, -reach, reach) {
                    self.stats.searched += 1;
                    self.stats.evaluations += 1;
                    self.remember(k, j, h + g);
                    return Ok(SampleGround::Range(at.s + g * at.ds_dh));
                }
            }
            return self.search(k, j, rays, &ray, last + step);
        }
        self.search(k, j, rays, &ray, terrain_h_m)
    }

    /// [`DemGround::sample`] of sample `j` of plan segment `k` now, ahead of its
    /// segment (for the yaw request, when the boresight is that sample): its segment's
    /// sweep then takes this answer instead of searching again, in this update.
    #[inline(never)]
    pub(crate) fn sample_ahead(
        &mut self,
        k: usize,
        j: usize,
        rays: &SegmentRays,
        terrain_h_m: f32,
    ) -> Option<f32> {
        self.ahead_slot = usize::MAX;
        // A refusal is left for the segment's own search to meet.
        let found = match self.find(k, j, rays, 0.0, terrain_h_m).ok()? {
            SampleGround::Range(s) => Some(s),
            SampleGround::Outside => None,
        };
        self.ahead_slot = k * MAX_SAMPLES + j;
        self.ahead_range = found.unwrap_or(f32::NAN);
        found
    }

    /// [`DemGround::sample`]'s search from the height `start` (m).
    #[inline(never)]
    fn search(
        &mut self,
        k: usize,
        j: usize,
        rays: &SegmentRays,
        ray: &Ray,
        start: f32,
    ) -> Result<SampleGround, ModelError> {
        let (band_lo, band_hi) = (self.frame.lo_m, self.frame.hi_m);
        let mut h = clamp(start, band_lo, band_hi);
        let (mut lo, mut hi) = (band_lo, band_hi);
        let mut edges_done = false;
        for n in 1..MAX_EVALUATIONS + 1 {
            let found = match self.evaluate(rays, ray, h) {
                Evaluation::Outside => {
                    // The ray's stretch through the band lies off the tile: nothing
                    // settled at an edge.
                    self.stats.outside += 1;
                    self.remember(k, j, f32::NAN);
                    return Ok(SampleGround::Outside);
                }
                Evaluation::March => break,
                Evaluation::Off(at) if !edges_done => {
                    edges_done = true;
                    let monotone = self.frame.slope2 * at.tan2 < MAX_CONTRACTION * MAX_CONTRACTION;
                    match self.edges(rays, ray, h, &at, monotone) {
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
                        match self.edges(rays, ray, h, &at, true) {
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
        Ok(match self.trace(rays, ray) {
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
    pub(super) fn trace(&self, rays: &SegmentRays, ray: &Ray) -> Option<SampleGround> {
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

    /// Notes sample `j` of plan segment `k` as off the tile by its segment's footprint.
    pub(crate) fn off_tile(&mut self, k: usize, j: usize) {
        self.stats.outside += 1;
        self.remember(k, j, f32::NAN);
    }

    /// Notes the first `n` samples of plan segment `k` as off the tile by its
    /// segment's footprint, all at once ([`DemGround::off_tile`] each).
    pub(crate) fn segment_off_tile(&mut self, k: usize, n: usize) {
        if let Some(history) = self.history_m.get_mut(k) {
            let n = n.min(MAX_SAMPLES);
            history[..n].fill([f32::NAN, 0.0]);
            self.stats.outside += n as u32;
        }
    }

    /// Whether the first `n` samples of plan segment `k` all found their ground on the
    /// tile at the last update: the footprint, which only spares evaluations of
    /// samples off the tile, is then not worth making ([`DemGround::sample`] places a
    /// sample that has since left the tile by itself).
    pub(crate) fn all_on_tile(&self, k: usize, n: usize) -> bool {
        self.history_m
            .get(k)
            .and_then(|history| history.get(..n))
            .is_some_and(|history| history.iter().all(|h| h[0].is_finite()))
    }

    /// Sample `j` of plan segment `k`'s height at the last update (NaN: none) and its
    /// change over it (m).
    pub(super) fn slot(&self, k: usize, j: usize) -> [f32; 2] {
        self.history_m
            .get(k)
            .and_then(|s| s.get(j))
            .copied()
            .unwrap_or([f32::NAN, 0.0])
    }

    /// Notes the sample's height for the next update's start, and its change.
    #[cfg_attr(all(target_arch = "arm", not(target_abi = "eabihf")), inline(never))]
    pub(super) fn remember(&mut self, k: usize, j: usize, h_m: f32) {
        let Some(slot) = self.history_m.get_mut(k).and_then(|s| s.get_mut(j)) else {
            return;
        };
        let last = slot[0];
        let step = if last.is_finite() && h_m.is_finite() {
            h_m - last
        } else {
            0.0
        };
        *slot = [h_m, step];
    }

    /// Whether the ray's points from h + dh_lo to h + dh_hi (linear in h from the grid
    /// coordinates `at` h, with the rates' margin) lie in the tile.
    pub(super) fn inside_over(&self, at: &Located, dh_lo: f32, dh_hi: f32) -> bool {
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
    pub(super) fn outside_over(&self, at: &Located, h: f32) -> bool {
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
    pub(super) fn locate(&self, rays: &SegmentRays, ray: &Ray, h: f32) -> Option<Located> {
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
        let kappa = big_a / big_b;
        let (row, col) = self.grid_at(kappa, x)?;
        // The raised ellipsoid's normal at X, (x, y, kappa^2 z): the incidence from the
        // quadratic's discriminant would be the sphere's in coordinates stretched along
        // z, short of the true one by up to 0.05 of sec^2, below zero near the vertical.
        let nz = kappa * kappa * x[2];
        let dn = d[0] * x[0] + d[1] * x[1] + d[2] * nz;
        let nn = x[0] * x[0] + x[1] * x[1] + nz * nz;
        Some(Located {
            s,
            ds_dh,
            row,
            col,
            drow_dh: ray.jr * ds_dh,
            dcol_dh: ray.jc * ds_dh,
            // tan^2(theta) = |d|^2 |n|^2 / (d.n)^2 - 1, raised by its rounding.
            tan2: ray.uu * nn * (1.0 + TAN2_ROUNDING) / (dn * dn) - 1.0,
        })
    }

    /// The tile at height h on the ray: [`DemGround::locate`], then the bilinear height
    /// and its gradient along the ray.
    // Out of line on the M3 (docs/target.md, `m3-flash3`): inlined in two or three
    // places, a soft-float copy in each.
    #[cfg_attr(all(target_arch = "arm", not(target_abi = "eabihf")), inline(never))]
    #[cfg_attr(
        not(all(target_arch = "arm", not(target_abi = "eabihf"))),
        inline(always)
    )]
    pub(super) fn evaluate(&self, rays: &SegmentRays, ray: &Ray, h: f32) -> Evaluation {
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
    pub(super) fn grid_at(&self, k: f32, x: [f32; 3]) -> Option<(f32, f32)> {
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
    /// and per column. Out of line without an FPU: there a call is lost in the soft
    /// float of the route, and inlined it was three copies (docs/target.md, flash).
    #[cfg_attr(all(target_arch = "arm", not(target_abi = "eabihf")), inline(never))]
    #[cfg_attr(
        not(all(target_arch = "arm", not(target_abi = "eabihf"))),
        inline(always)
    )]
    pub(super) fn bilinear(&self, heights: &[i16], row: f32, col: f32) -> (f32, f32, f32) {
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
