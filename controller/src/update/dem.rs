//! The update's DEM route: a segment's samples each on their own ground on the tile in
//! force (`crate::dem_ground`), and the controller's hold of that route.

use super::sweep::{extremes, sweep, Extremes};
use super::*;

/// The segment's [`Extremes`] with every sample's ground on the DEM tile (or, where the
/// tile does not cover it, at the segment's TERRAIN height `terrain_h_m`, which `update`
/// is made for): [`DemGround::sample`] per sample, then the row form at that range.
/// Out of line: the flat route's registers stay as they were.
#[inline(never)]
#[allow(clippy::too_many_arguments)]
pub(super) fn dem_extremes(
    dem: &mut DemGround,
    heights_m: &[i16],
    k: usize,
    frame: &ItrfFrame,
    update: &GeneralUpdate<f32>,
    seg: &SegmentPlan,
    r2_minus_a2_m2: f32,
    terrain_h_m: f32,
) -> Result<Extremes, Fault> {
    let r = &seg.row;
    let (d0, dy) = SegmentRays::directions(frame, r.p1_m, r.focal_m);
    let ends = match (seg.samples.get(1), seg.samples.last()) {
        (Some(a), Some(b)) if !dem.all_on_tile(k, seg.samples.len()) => Some((a.p2_m, b.p2_m)),
        _ => None,
    };
    // The footprint carried from an earlier update while the rays stay within its
    // bound, else made again from the rays.
    let mut footprint =
        ends.and_then(|(a, b)| dem.carried_footprint(k, &frame.position_m, &d0, &dy, a, b));
    // A segment wholly off the tile is the flat route's, at its TERRAIN height.
    if let (Some(f), Some((a, b))) = (&footprint, ends) {
        if f.off_tile_over(a, b) {
            dem.segment_off_tile(k, seg.samples.len());
            return extremes(update, seg);
        }
    }
    let made = footprint.is_none();
    let rays = SegmentRays::from_directions(
        dem,
        heights_m,
        frame.position_m,
        d0,
        dy,
        r.uu0_m2,
        r2_minus_a2_m2,
    );
    if made {
        if let Some((a, b)) = ends {
            footprint = dem.footprint(k, &rays, a, b);
            if footprint.is_some_and(|f| f.off_tile_over(a, b)) {
                dem.segment_off_tile(k, seg.samples.len());
                return extremes(update, seg);
            }
        }
    }
    let row = GENERAL_F32.row_motion(update, &seg.row);
    sweep(seg, |j, p2| {
        if footprint.is_some_and(|f| f.off_tile(p2)) {
            dem.off_tile(k, j);
            return row.motion_at(p2);
        }
        match dem.sample(k, j, &rays, p2, terrain_h_m)? {
            SampleGround::Range(s) => motion_at_range(&row, update.c_m2, p2, s),
            SampleGround::Outside => row.motion_at(p2),
        }
    })
}

impl Controller {
    /// [`dem_extremes`] of plan segment `k`, whose TERRAIN height `update` is made for.
    #[inline(always)]
    pub(super) fn dem_segment(
        &mut self,
        k: usize,
        frame: &ItrfFrame,
        update: &Ground,
        instant: &GeneralInstant<f32>,
        terrain_h_m: f32,
    ) -> Result<Extremes, Fault> {
        let heights_m = tile_heights(&self.dem_given, &self.dem);
        let dem = &mut self.dem_ground;
        let (true, Some(seg)) = (dem.active(), self.plan.segments.get(k)) else {
            return Err(Fault::InvalidScene);
        };
        dem_extremes(
            dem,
            heights_m,
            k,
            frame,
            float(update),
            seg,
            instant.r2_minus_a2_m2,
            terrain_h_m,
        )
    }

    /// The boresight's motion with its ground on the DEM tile in force, for the yaw
    /// request (atan(v2/v1) at the boresight over the ground it sees), at that ground's
    /// range (`General::motion_at_inv_range`). Where the boresight is a plan sample
    /// (`Plan::boresight_sample`) that sample is searched ahead of its segment, which
    /// then takes the answer; else its own ray is searched as a sample's, in the slot
    /// [`BORESIGHT_SLOT`] (`DemGround::sample_ahead` either way). None without a tile or the ITRF of the instant, or where the
    /// tile does not cover the boresight: the request is then over the boresight
    /// segment's TERRAIN height `terrain_h_m`, which `update` is made for.
    #[inline(never)]
    pub(super) fn dem_boresight(
        &mut self,
        frame: Option<&ItrfFrame>,
        update: &GeneralUpdate<f32>,
        r2_minus_a2_m2: f32,
        terrain_h_m: f32,
    ) -> Option<ImageMotion<f32>> {
        let frame = frame?;
        let heights_m = tile_heights(&self.dem_given, &self.dem);
        let dem = &mut self.dem_ground;
        if !dem.active() {
            return None;
        }
        let px = &self.plan.boresight;
        // The boresight's ray is its row's (p1 = 0) at p2 = 0: a plan row's exactly
        // where it is a plan sample, so that the answer found ahead is the one its
        // segment would find; else the route's own slot, which no segment reads.
        let (k, j, p1_m, focal_m, uu0_m2, h_m) = match self
            .plan
            .boresight_sample
            .and_then(|(k, j)| Some((k, j, self.plan.segments.get(usize::from(k))?)))
        {
            Some((k, j, seg)) => (
                usize::from(k),
                usize::from(j),
                seg.row.p1_m,
                seg.row.focal_m,
                seg.row.uu0_m2,
                self.heights_m
                    .get(usize::from(seg.index))
                    .copied()
                    .unwrap_or(0.0),
            ),
            None => (BORESIGHT_SLOT, 0, 0.0, -px.u_m[2], px.uu_m2, terrain_h_m),
        };
        let (d0, dy) = SegmentRays::directions(frame, p1_m, focal_m);
        let rays = SegmentRays::from_directions(
            dem,
            heights_m,
            frame.position_m,
            d0,
            dy,
            uu0_m2,
            r2_minus_a2_m2,
        );
        let s = dem.sample_ahead(k, j, &rays, h_m)?;
        GENERAL_F32.motion_at_inv_range(update, px, 1.0 / s).ok()
    }

    /// Puts `tile` in force as the ground of every plan sample it covers, in place of
    /// any uploaded tile (tests and the bench, which have no uplink), or (None) goes
    /// back to the uploaded tile in force, if any; the TERRAIN heights hold where no
    /// tile covers a sample, and while the state comes from NAV frames. The route's
    /// constants are made here, once.
    #[doc(hidden)]
    pub fn set_dem_tile(
        &mut self,
        tile: Option<core_math::earth::dem::DemTile<'static, i16>>,
    ) -> Result<(), TileRefusal> {
        match &tile {
            Some(t) => self.dem_ground.install(t)?,
            None => self.dem_ground.clear(),
        }
        self.dem_given = tile;
        if self.dem_given.is_none() {
            self.refresh_dem_ground();
        }
        Ok(())
    }

    /// The route on the tile in force (the given one, else the uploaded one), made
    /// again whenever that tile changes: a commit, a restore, the store lent or taken
    /// back. None when no tile is in force, or when the route refuses it (wider than
    /// it handles): then the TERRAIN heights are the ground.
    // Out of line: the DEM upload's commit and the boot's restore each inlined it.
    #[inline(never)]
    pub(crate) fn refresh_dem_ground(&mut self) {
        let tile = self.dem_given.or_else(|| self.dem.tile());
        // In place (`DemGround::blank`): a refused tile leaves no route.
        if tile.is_none_or(|t| self.dem_ground.install(&t).is_err()) {
            self.dem_ground.clear();
        }
    }

    /// The DEM tile the update's ground comes from, if any: None also when the route
    /// refused the tile in force.
    pub fn dem_tile_in_force(&self) -> Option<core_math::earth::dem::DemTile<'_, i16>> {
        if !self.dem_ground.active() {
            return None;
        }
        self.dem_given.or_else(|| self.dem.tile())
    }

    /// How the DEM route found the samples' ground since the tile was set.
    pub fn dem_stats(&self) -> Option<DemStats> {
        self.dem_ground.active().then_some(self.dem_ground.stats)
    }
}

/// The heights of the tile the DEM route was made for: the one given (tests, bench) or
/// the upload's in force (`Controller::refresh_dem_ground`). Out of line on the M3 (two
/// copies inlined there).
#[cfg_attr(all(target_arch = "arm", not(target_abi = "eabihf")), inline(never))]
fn tile_heights<'a>(
    given: &'a Option<core_math::earth::dem::DemTile<'static, i16>>,
    store: &'a crate::dem::Dem,
) -> &'a [i16] {
    match given {
        Some(t) => t.heights_m(),
        None => store.heights_in_force().unwrap_or(&[]),
    }
}
