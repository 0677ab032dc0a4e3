//! The built-in passes' DEM tile as a GeoTIFF (`xtask/data/pass-dem.tif`): int16 heights
//! (m above the WGS 84 ellipsoid) on a grid of geodetic latitude and longitude in
//! degrees, placed by ModelTiepoint (33922) and ModelPixelScale (33550), its GeoKeys
//! saying geographic WGS 84 and pixel-is-point (each pixel a node). Read with image-rs's
//! `tiff`; written once by `cargo xtask run --write-dem FILE.tif`.

use anyhow::{anyhow, bail, Context, Result};
use core_math::earth::dem::{DemGrid, DemTile};
use core_math::earth::frames::{self, TimeScales};
use core_math::earth::{Attitude, EarthGeometry};
use core_math::vector::{add, dot, scale};
use core_math::EARTH_RATE_RAD_S;
use std::path::Path;
use tiff::decoder::{Decoder, DecodingResult};
use tiff::tags::Tag;

use super::bus::{mat_vec, transpose};
use super::scenario::{self, Manoeuvres};

/// The tile shipped with the repository, relative to the workspace root.
pub const PASS_DEM_PATH: &str = "xtask/data/pass-dem.tif";

/// GeoKey ids: the model type (2: geographic), the raster type (1: pixel is area, 2:
/// pixel is point) and the geographic system (4326: WGS 84).
const MODEL_TYPE: u16 = 1024;
const RASTER_TYPE: u16 = 1025;
const GEOGRAPHIC_TYPE: u16 = 2048;

/// Reads a geographic int16 GeoTIFF as a DEM tile (rows from the south).
pub fn read(path: &Path) -> Result<(DemGrid, Vec<i16>)> {
    let what = || format!("DEM {}", path.display());
    let file = std::fs::File::open(path).with_context(what)?;
    let mut d = Decoder::new(std::io::BufReader::new(file)).with_context(what)?;
    let (ncols, nrows) = d.dimensions().with_context(what)?;
    let scale = d
        .get_tag_f64_vec(Tag::ModelPixelScaleTag)
        .with_context(what)?;
    let tie = d
        .get_tag_f64_vec(Tag::ModelTiepointTag)
        .with_context(what)?;
    let keys: Vec<u16> = d
        .find_tag_unsigned_vec(Tag::GeoKeyDirectoryTag)
        .with_context(what)?
        .unwrap_or_default();
    // Key entries after the 4-value header: id, location (0: the value itself), count,
    // value.
    let key = |id: u16| {
        keys.chunks_exact(4)
            .skip(1)
            .find(|k| k[0] == id && k[1] == 0)
            .map(|k| k[3])
    };
    if key(MODEL_TYPE).is_some_and(|m| m != 2) {
        bail!("{}: not in geographic coordinates", what());
    }
    if key(GEOGRAPHIC_TYPE).is_some_and(|g| g != 4326) {
        bail!("{}: a datum other than WGS 84", what());
    }
    if tie.len() < 6 || scale.len() < 2 {
        bail!("{}: no tie point or pixel scale", what());
    }
    let (i, j, lon, lat, dlon, dlat) = (tie[0], tie[1], tie[3], tie[4], scale[0], scale[1]);
    // Pixel is area (GeoTIFF's default): the tie point is a pixel's corner and the node
    // its centre.
    let centre = if key(RASTER_TYPE) == Some(2) {
        0.0
    } else {
        0.5
    };
    let heights = match d.read_image().with_context(what)? {
        DecodingResult::I16(h) => h,
        _ => bail!("{}: heights are not int16", what()),
    };
    let (nrows, ncols) = (nrows as usize, ncols as usize);
    let north_deg = lat - (centre - j) * dlat;
    let grid = DemGrid {
        lat0_deg: north_deg - (nrows - 1) as f64 * dlat,
        lon0_deg: lon + (centre - i) * dlon,
        dlat_deg: dlat,
        dlon_deg: dlon,
        nrows,
        ncols,
    };
    // GeoTIFF rows run from the north, the tile's from the south.
    let heights: Vec<i16> = heights.chunks(ncols).rev().flatten().copied().collect();
    DemTile::new(grid, &heights).map_err(|e| anyhow!("{}: {}", what(), e.name()))?;
    Ok((grid, heights))
}

/// Nodes per side, spacing (deg): 127 cells span 4.95 deg, within the DEM route's 2.5 deg
/// half-extent.
const NODES: usize = 128;
const STEP_DEG: f64 = 0.039;

/// Writes the passes' tile: centred on what the short pass's roll slew and the default
/// pass's forward stereo look see, a plain at a few hundred metres crossed by a ridge
/// rising to 4 800 m, slanting across the ground track.
pub fn write(path: &Path) -> Result<()> {
    let (lat_c, lon_c) = look_centre()?;
    let (lat_c, lon_c) = (
        (lat_c * 100.0).round() / 100.0,
        (lon_c * 100.0).round() / 100.0,
    );
    let half = (NODES - 1) as f64 / 2.0 * STEP_DEG;
    let (north, west) = (lat_c + half, lon_c - half);
    let mut rows = Vec::with_capacity(NODES * NODES);
    for r in 0..NODES {
        for c in 0..NODES {
            // Coordinates from the centre in tile half-widths.
            let y = (north - r as f64 * STEP_DEG - lat_c) / half;
            let x = (west + c as f64 * STEP_DEG - lon_c) / half;
            let ridge = (y - 0.3 * x) / 0.12;
            let h = 300.0
                + 150.0 * (4.0 * x + 2.0 * y).sin()
                + 4_350.0 * (-ridge * ridge).exp() * (1.0 + 0.1 * (9.0 * x).sin())
                + 600.0 * (-((x - 0.5).powi(2) + (y + 0.5).powi(2)) / 0.02).exp();
            rows.push(h.round() as i16);
        }
    }
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)?;
    }
    let file = std::fs::File::create(path).with_context(|| format!("{}", path.display()))?;
    let mut enc = tiff::encoder::TiffEncoder::new(std::io::BufWriter::new(file))?;
    let mut image =
        enc.new_image::<tiff::encoder::colortype::GrayI16>(NODES as u32, NODES as u32)?;
    let tags = image.encoder();
    tags.write_tag(Tag::ModelPixelScaleTag, &[STEP_DEG, STEP_DEG, 0.0][..])?;
    tags.write_tag(
        Tag::ModelTiepointTag,
        &[0.0, 0.0, 0.0, west, north, 0.0][..],
    )?;
    // The header (version 1.1.0, 3 keys), then each key: id, location, count, value.
    let keys: [[u16; 4]; 4] = [
        [1, 1, 0, 3],
        [MODEL_TYPE, 0, 1, 2],
        [RASTER_TYPE, 0, 1, 2],
        [GEOGRAPHIC_TYPE, 0, 1, 4326],
    ];
    tags.write_tag(Tag::GeoKeyDirectoryTag, keys.as_flattened())?;
    image.write_data(&rows)?;
    let (min, max) = rows
        .iter()
        .fold((i16::MAX, i16::MIN), |(a, b), &h| (a.min(h), b.max(h)));
    println!(
        "wrote {}: {NODES} x {NODES} nodes at {STEP_DEG} deg from {:.3} N {:.3} E, heights {min}..{max} m",
        path.display(),
        north - 2.0 * half,
        west
    );
    Ok(())
}

/// The centre (deg) of the boresight's points on a sphere of 6 371 km over the short
/// pass and the default pass's forward look (250..310 s). (The swath is wider than a
/// tile: its outer segments fall back to TERRAIN.)
fn look_centre() -> Result<(f64, f64)> {
    let scales = TimeScales {
        gps_utc_s: 18.0,
        dut1_s: 0.0,
    };
    let gps0_s = scenario::EPOCH_GPS_US as f64 * 1e-6;
    let c2t0 = frames::c2t(gps0_s, &scales).map_err(|e| anyhow!(e.name()))?;
    let (mut lat, mut lon) = ((f64::MAX, f64::MIN), (f64::MAX, f64::MIN));
    let looks = |m: Manoeuvres, from_s: f64, to_s: f64| {
        let orbit = scenario::sun_synchronous(m.start_s, m.duration_s);
        (0..=20).map(move |k| {
            let t_s = from_s + (to_s - from_s) * f64::from(k) / 20.0;
            (
                m.start_s + t_s,
                orbit.state(t_s),
                m.roll.at(t_s).0,
                m.pitch.at(t_s).0,
            )
        })
    };
    let samples = looks(scenario::short_manoeuvres(), 0.0, 60.0).chain(looks(
        scenario::default_manoeuvres(),
        250.0,
        310.0,
    ));
    for (orbit_s, state, roll, pitch) in samples {
        let g = EarthGeometry {
            state,
            attitude: Attitude {
                roll_rad: roll,
                pitch_rad: pitch,
                ..Attitude::default()
            },
            ground_h_m: 0.0,
            ellipsoid: controller::EARTH,
            earth_rate_rad_s: EARTH_RATE_RAD_S,
        }
        .to_inertial()
        .map_err(|e| anyhow!(e.name()))?;
        let c2t = frames::c2t(gps0_s + orbit_s, &scales).map_err(|e| anyhow!(e.name()))?;
        let b = g.attitude.camera_to_inertial;
        let r = state.position_m;
        let d: [f64; 3] = std::array::from_fn(|i| -b[i][2]);
        let (dd, rd, rr) = (dot(d, d), dot(r, d), dot(r, r));
        let s = (-rd - (rd * rd - dd * (rr - 6.371e6f64.powi(2))).sqrt()) / dd;
        // I (the ITRF at the epoch) to the ITRF at the instant.
        let x = mat_vec(&c2t, mat_vec(&transpose(&c2t0), add(r, scale(s, d))));
        let (la, lo, _) =
            frames::geodetic_from_itrf(x, &controller::EARTH).map_err(|e| anyhow!(e.name()))?;
        let (la, lo) = (la.to_degrees(), lo.to_degrees());
        lat = (lat.0.min(la), lat.1.max(la));
        lon = (lon.0.min(lo), lon.1.max(lo));
    }
    println!(
        "the looks span {:.2}..{:.2} N, {:.2}..{:.2} E",
        lat.0, lat.1, lon.0, lon.1
    );
    Ok(((lat.0 + lat.1) / 2.0, (lon.0 + lon.1) / 2.0))
}
