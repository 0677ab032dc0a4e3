//! The route against the march, across the tile's edges.

extern crate std;
use std::boxed::Box;
use std::vec::Vec;

use super::{DemGround, Ray, SampleGround, SegmentRays, MAX_TAN2};
use crate::config::EARTH;
use crate::track::ItrfFrame;
use core_math::earth::dem::{DemGrid, DemTile};
use core_math::vector::{cross, unit};
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

/// The incidence the route takes for a ray (`Located::tan2`, the bound on its q) bounds
/// the true one above: tan^2 of the angle between the ray and the geodetic normal at
/// the point where the ray meets the ellipsoid raised by h, in f64, at latitudes to
/// 85 deg, angles from the vertical to 70 deg, all azimuths. Vertical rays at high
/// latitude are where the quadratic's own incidence falls short (below zero).
#[test]
fn the_incidence_bounds_the_true_one() {
    let (mut worst_margin, mut checked) = (f64::INFINITY, 0);
    for lat in [0.0, 30.0, 50.0, 70.0, 85.0] {
        let lon = 10.0;
        let (side, step) = (31usize, 0.01);
        let half = 0.5 * (side - 1) as f64 * step;
        let grid = DemGrid {
            lat0_deg: lat - half,
            lon0_deg: lon - half,
            dlat_deg: step,
            dlon_deg: step,
            nrows: side,
            ncols: side,
        };
        let heights = std::vec![1_000i16; side * side];
        let tile = DemTile::new(grid, Box::leak(heights.into_boxed_slice())).unwrap();
        let ground = DemGround::new(&tile).unwrap();
        let h_m = 1_000.0;
        let g = itrf(lat, lon, h_m);
        let (la, lo) = (f64::to_radians(lat), f64::to_radians(lon));
        let up = [la.cos() * lo.cos(), la.cos() * lo.sin(), la.sin()];
        let east = unit([-lo.sin(), lo.cos(), 0.0]);
        let north = cross(up, east);
        for zenith in [0.0, 0.5, 5.0, 20.0, 45.0, 70.0] {
            for az in (0..8).map(|k| f64::from(k) * 45.0) {
                let (c, s) = (f64::to_radians(zenith).cos(), f64::to_radians(zenith).sin());
                let (ca, sa) = (f64::to_radians(az).cos(), f64::to_radians(az).sin());
                let look: [f64; 3] =
                    core::array::from_fn(|i| -c * up[i] + s * (ca * north[i] + sa * east[i]));
                let r: [f64; 3] = core::array::from_fn(|i| g[i] - 700e3 / c * look[i]);
                // Camera z = -look: the boresight (p1 = p2 = 0) is the ray.
                let z = look.map(|v| -v);
                let y = unit(cross(z, east));
                let y = if y.iter().all(|v| v.is_finite()) {
                    y
                } else {
                    north
                };
                let x = cross(y, z);
                let b: [[f64; 3]; 3] = core::array::from_fn(|i| [x[i], y[i], z[i]]);
                let frame = ItrfFrame {
                    position_m: r.map(|v| v as f32),
                    camera_to_itrf: b.map(|row| row.map(|v| v as f32)),
                };
                let (focal, r2) = (0.555f64, r.iter().map(|v| v * v).sum::<f64>());
                let rays = SegmentRays::new(
                    &ground,
                    tile.heights_m(),
                    &frame,
                    0.0,
                    focal as f32,
                    (focal * focal) as f32,
                    (r2 - EARTH.a_m * EARTH.a_m) as f32,
                );
                let ray = Ray {
                    d: rays.d0,
                    rd: rays.rd0,
                    uu: rays.uu0,
                    jr: rays.jr0,
                    jc: rays.jc0,
                };
                let at = ground.locate(&rays, &ray, h_m as f32).unwrap();
                // The true incidence where the route's point is.
                let d: [f64; 3] = core::array::from_fn(|i| -b[i][2] * focal);
                let p: [f64; 3] = core::array::from_fn(|i| r[i] + f64::from(at.s) * d[i]);
                let (plat, plon, _) =
                    core_math::earth::frames::geodetic_from_itrf(p, &EARTH).unwrap();
                let n = [plat.cos() * plon.cos(), plat.cos() * plon.sin(), plat.sin()];
                let cos = -(d[0] * n[0] + d[1] * n[1] + d[2] * n[2]) / focal;
                let tan2 = 1.0 / (cos * cos) - 1.0;
                let got = f64::from(at.tan2);
                assert!(
                    got >= tan2 && got <= tan2 + 1e-4 * (1.0 + tan2) && got < f64::from(MAX_TAN2),
                    "lat {lat} zenith {zenith} az {az}: tan^2 {got} vs true {tan2}"
                );
                worst_margin = worst_margin.min(got - tan2);
                checked += 1;
            }
        }
    }
    std::eprintln!("incidence: {checked} rays, tan^2 at least {worst_margin:.2e} above the true");
}

/// Grid coordinates (row, column) of the point where the line r + s d meets the
/// ellipsoid raised by h, in f64: the raised ellipsoid's normal latitude and the
/// longitude (the footprint's coordinates, `DemGround::grid_at`'s, exactly).
fn grid_at_height(grid: &DemGrid, r: [f64; 3], d: [f64; 3], h_m: f64) -> Option<(f64, f64)> {
    let (a, b) = (EARTH.a_m + h_m, EARTH.b_m() + h_m);
    let (a2, b2) = (a * a, b * b);
    let alpha = (d[0] * d[0] + d[1] * d[1]) / a2 + d[2] * d[2] / b2;
    let beta = (r[0] * d[0] + r[1] * d[1]) / a2 + r[2] * d[2] / b2;
    let gamma = (r[0] * r[0] + r[1] * r[1]) / a2 + r[2] * r[2] / b2 - 1.0;
    let disc = beta * beta - alpha * gamma;
    if disc <= 0.0 {
        return None;
    }
    let s = (-beta - disc.sqrt()) / alpha;
    let x: [f64; 3] = core::array::from_fn(|i| r[i] + s * d[i]);
    let p = (x[0] * x[0] + x[1] * x[1]).sqrt();
    let lat = (a2 / b2 * x[2] / p).atan().to_degrees();
    let lon = x[1].atan2(x[0]).to_degrees();
    Some((
        (lat - grid.lat0_deg) / grid.dlat_deg,
        (lon - grid.lon0_deg) / grid.dlon_deg,
    ))
}

/// Rotation of v about the unit axis k by angle (rad): Rodrigues.
fn rotate(v: [f64; 3], k: [f64; 3], angle: f64) -> [f64; 3] {
    let (c, s) = (angle.cos(), angle.sin());
    let kv = cross(k, v);
    let kd = k[0] * v[0] + k[1] * v[1] + k[2] * v[2];
    core::array::from_fn(|i| v[i] * c + kv[i] * s + k[i] * kd * (1.0 - c))
}

/// A segment's footprint carried from the update that made it
/// (`DemGround::carried_footprint`, docs/controller.md, "The DEM ground") against the
/// truth in f64. The rows look across the tile's east edge (partly on it), wholly past
/// it, and past its north-west corner; the satellite then moves along its orbit (7.5
/// km/s) and the camera turns (about its own x and y axes, to 0.2 rad/s, the scene
/// envelope's limit) for 1 ms to 2 s. Wherever the carried footprint is taken:
/// - each end of the row has truly moved, in grid coordinates at mid-band, by no more
///   than the bound the footprint was widened for (w / (1.1 + 4 bow_share) cells): a
///   move beyond it must make the footprint again;
/// - every sample (129 across the row) it puts off the tile has no ground on the tile
///   by `DemTile::first_crossing` in f64 (the reference's ground), and where it puts
///   the whole row beyond an edge, none of the row's samples has.
#[test]
fn a_carried_footprint_holds_within_its_bound() {
    let (lat_c, lon_c, side, step) = (45.0, 10.0, 61usize, 0.02);
    let half = 0.5 * (side - 1) as f64 * step;
    let grid = DemGrid {
        lat0_deg: lat_c - half,
        lon0_deg: lon_c - half,
        dlat_deg: step,
        dlon_deg: step,
        nrows: side,
        ncols: side,
    };
    let heights: Vec<i16> = (0..side * side)
        .map(|k| {
            let (i, j) = ((k / side) as f64, (k % side) as f64);
            (2_000.0 + 1_500.0 * (0.4 * i).sin() * (0.3 * j).cos()) as i16
        })
        .collect();
    let tile = DemTile::new(grid, Box::leak(heights.into_boxed_slice())).unwrap();
    let mut ground = DemGround::new(&tile).unwrap();
    let h_mid = 0.5 * f64::from(ground.frame.lo_m + ground.frame.hi_m);
    let share = 1.1 + 4.0 * f64::from(ground.frame.bow_share);
    let focal = 0.555f64;
    // The row's ends: p2 over +-30 mm, about +-45 km on the ground.
    let (a_m, b_m) = (-0.03f32, 0.03f32);
    let (mut taken, mut refused, mut skipped, mut wholly) = (0, 0, 0, 0);
    let mut tightest = 0f64;
    // Where the row looks: across the east edge, 1.5 deg east of it, past the
    // north-west corner.
    for (look_lat, look_lon) in [
        (lat_c, lon_c + half),
        (lat_c, lon_c + half + 1.5),
        (lat_c + half + 0.4, lon_c - half - 0.4),
    ] {
        let t = itrf(look_lat, look_lon, 2_000.0);
        let up = unit(t);
        let east = unit([-t[1], t[0], 0.0]);
        let north = cross(up, east);
        let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
        // 30 deg from the vertical, looking north-east.
        let look = unit(core::array::from_fn(|i| {
            -c * up[i] + s * (0.6 * north[i] + 0.8 * east[i])
        }));
        let r0: [f64; 3] = core::array::from_fn(|i| t[i] - 700e3 / c * look[i]);
        let z = look.map(|v| -v);
        let ez = east[0] * z[0] + east[1] * z[1] + east[2] * z[2];
        let y = unit(core::array::from_fn(|i| east[i] - ez * z[i]));
        let x = cross(y, z);
        let velocity = unit(cross(r0, east)).map(|v| v * 7_500.0);
        let frame_of = |r: [f64; 3], x: [f64; 3], y: [f64; 3], z: [f64; 3]| ItrfFrame {
            position_m: r.map(|v| v as f32),
            camera_to_itrf: core::array::from_fn(|i| [x[i] as f32, y[i] as f32, z[i] as f32]),
        };
        let rays_of = |ground: &DemGround, frame: &ItrfFrame, r: [f64; 3]| {
            let r2 = r.iter().map(|v| v * v).sum::<f64>();
            SegmentRays::new(
                ground,
                tile.heights_m(),
                frame,
                0.0,
                focal as f32,
                (focal * focal) as f32,
                (r2 - EARTH.a_m * EARTH.a_m) as f32,
            )
        };
        // d = B (0, p2, -f).
        let d_of = |y: [f64; 3], z: [f64; 3], p2: f64| -> [f64; 3] {
            core::array::from_fn(|i| y[i] * p2 - z[i] * focal)
        };
        let frame0 = frame_of(r0, x, y, z);
        let made = {
            let rays = rays_of(&ground, &frame0, r0);
            ground
                .footprint(0, &rays, a_m, b_m)
                .expect("the row's ends place")
        };
        // The bound is set at the first update that looks at the carried footprint.
        let (d0, dy) = SegmentRays::directions(&frame0, 0.0, focal as f32);
        let carried = ground
            .carried_footprint(0, &frame0.position_m, &d0, &dy, a_m, b_m)
            .expect("an unmoved footprint is carried");
        let w = f64::from(carried.row_margin - 1.1 * made.row_margin);
        let allowed_cells = w / share;
        let ends0 = [a_m, b_m]
            .map(|p2| grid_at_height(&grid, r0, d_of(y, z, f64::from(p2)), h_mid).unwrap());
        for axis in [0usize, 1] {
            for rate_rad_s in [0.0, 0.01, 0.2] {
                for dt_s in [1e-3, 3e-3, 1e-2, 2e-2, 5e-2, 0.1, 0.2, 0.5, 1.0, 2.0] {
                    let k = if axis == 0 { x } else { y };
                    let angle = rate_rad_s * dt_s;
                    let (x1, y1, z1) = (
                        rotate(x, k, angle),
                        rotate(y, k, angle),
                        rotate(z, k, angle),
                    );
                    let r1: [f64; 3] = core::array::from_fn(|i| r0[i] + velocity[i] * dt_s);
                    let frame1 = frame_of(r1, x1, y1, z1);
                    let (d0, dy) = SegmentRays::directions(&frame1, 0.0, focal as f32);
                    let moved_cells = [a_m, b_m]
                        .iter()
                        .zip(ends0)
                        .map(|(&p2, (row0, col0))| {
                            let d = d_of(y1, z1, f64::from(p2));
                            let (row, col) = grid_at_height(&grid, r1, d, h_mid).unwrap();
                            (row - row0).abs().max((col - col0).abs())
                        })
                        .fold(0f64, f64::max);
                    let Some(f) =
                        ground.carried_footprint(0, &frame1.position_m, &d0, &dy, a_m, b_m)
                    else {
                        refused += 1;
                        continue;
                    };
                    taken += 1;
                    assert!(
                        moved_cells <= allowed_cells,
                        "look ({look_lat}, {look_lon}), axis {axis}, {rate_rad_s} rad/s over \
                         {dt_s} s: the ends moved {moved_cells} cells, the bound {allowed_cells}"
                    );
                    tightest = tightest.max(moved_cells / allowed_cells);
                    let all_off = f.off_tile_over(a_m, b_m);
                    wholly += usize::from(all_off);
                    for n in -64..=64 {
                        let p2 = f32::from(n as i8) / 64.0 * b_m;
                        if !(all_off || f.off_tile(p2)) {
                            continue;
                        }
                        skipped += 1;
                        let d = d_of(y1, z1, f64::from(p2));
                        let want = tile.first_crossing::<f64>(&EARTH, r1, d);
                        assert!(
                            matches!(want, Err(ModelError::OutsideDem)),
                            "look ({look_lat}, {look_lon}), axis {axis}, {rate_rad_s} rad/s \
                             over {dt_s} s, p2 {p2}: skipped, the reference finds {want:?}"
                        );
                    }
                }
            }
        }
    }
    std::eprintln!(
        "carried footprints: {taken} taken ({wholly} wholly off the tile), {refused} made \
         again; the ends moved at most {tightest:.3} of the bound; {skipped} samples \
         skipped, none with ground on the tile by the reference"
    );
    assert!(taken > 0 && refused > 0 && wholly > 0 && skipped > 0);
}
