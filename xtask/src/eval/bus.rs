//! The earth model's rows (`shared/EARTH-MODEL.md`, "Eval CSV" and "Eval CSV, Part
//! II"): Part I's state, attitude angles and optics, and Part II's bus columns on top,
//! the bus's frames, time and quaternion attitude, the ground from a DEM tile, and the
//! ground point's geodetic coordinates. A file is Part II's when its header has a
//! `frame` column or a quaternion column, or when a DEM is given; in any other file
//! only Part I's columns are read, and its rows give what they always have.

use super::*;

/// Part I's state, read in the bus's `frame`.
const STATE_COLUMNS: [&str; 6] = ["x_m", "y_m", "z_m", "vx_mps", "vy_mps", "vz_mps"];
/// Part I's attitude, replaced by the quaternion where a row has one.
const ANGLE_COLUMNS: [&str; 6] = [
    "roll_deg",
    "pitch_deg",
    "yaw_deg",
    "roll_rate_dps",
    "pitch_rate_dps",
    "yaw_rate_dps",
];
/// Columns every row needs.
const COMMON_COLUMNS: [&str; 4] = ["ground_h_m", "f_m", "pixel_m", "n_px"];
const QUATERNION_COLUMNS: [&str; 4] = ["qw", "qx", "qy", "qz"];
const CAMERA_QUATERNION_COLUMNS: [&str; 4] = ["cam_qw", "cam_qx", "cam_qy", "cam_qz"];
const BODY_RATE_COLUMNS: [&str; 3] = ["wx_dps", "wy_dps", "wz_dps"];
/// Part I's optional columns; a Part I file's other columns are not read.
const OPTIONAL_COLUMNS: [&str; 4] = ["p1_m", "a_m", "flattening", "earth_rate_rad_s"];
/// Added after `error` whenever the input has a `frame` column.
const GROUND_OUTPUTS: [&str; 3] = ["ground_lat_deg", "ground_lon_deg", "ground_height_m"];

/// A row's geometry: Part I's angles (the state converted to I) or the bus quaternion.
pub(super) enum BusRowGeometry {
    Angles(EarthGeometry<f64>),
    Quaternion(InertialGeometry<f64>),
}

/// One earth row's case: optics, geometry in I at t (f64), pixel.
pub(super) struct BusCase {
    camera: EarthCamera,
    geometry: BusRowGeometry,
    n_px: f64,
}

/// A row's cells by column name; an empty cell is a missing column, and so is a column
/// whose name `header` leaves empty.
pub(super) struct RowCells<'a> {
    header: &'a [&'a str],
    row: &'a [String],
}

impl RowCells<'_> {
    fn text(&self, name: &str) -> Option<&str> {
        let c = self.header.iter().position(|h| *h == name)?;
        self.row
            .get(c)
            .map(String::as_str)
            .filter(|t| !t.is_empty())
    }

    fn number(&self, name: &str) -> Result<Option<f64>, RowError> {
        self.text(name)
            .map(|t| t.parse::<f64>().map_err(|_| RowError::Unparsable))
            .transpose()
    }

    /// A required number (a missing or empty cell cannot be read, as in Part I).
    fn required(&self, name: &str) -> Result<f64, RowError> {
        self.number(name)?.ok_or(RowError::Unparsable)
    }

    fn or(&self, name: &str, default: f64) -> Result<f64, RowError> {
        Ok(self.number(name)?.unwrap_or(default))
    }

    /// All of `names` (`Some`), none of them (`None`), or some: `invalid_input`.
    fn all<const N: usize>(&self, names: [&str; N]) -> Result<Option<[f64; N]>, RowError> {
        let v = names.map(|n| self.number(n));
        let mut out = [0.0; N];
        let mut given = 0;
        for (o, x) in out.iter_mut().zip(v) {
            if let Some(x) = x? {
                *o = x;
                given += 1;
            }
        }
        match given {
            0 => Ok(None),
            g if g == N => Ok(Some(out)),
            _ => Err(RowError::Invalid),
        }
    }
}

/// The case of an earth row (see [`eval_bus_rows`] for the order of the checks). With
/// a DEM (`on_dem`) `ground_h_m` is ignored (0 where absent) and `gps_s` is needed.
pub(super) fn bus_case(cells: &RowCells, on_dem: bool) -> Result<BusCase, RowError> {
    let [x, y, z, vx, vy, vz] = STATE_COLUMNS.map(|n| cells.required(n));
    let (position_m, velocity_mps) = ([x?, y?, z?], [vx?, vy?, vz?]);
    let [ground_h_m, focal_m, pixel_m, n_px] = COMMON_COLUMNS.map(|n| match n {
        "ground_h_m" if on_dem => Ok(0.0),
        _ => cells.required(n),
    });
    let (ground_h_m, focal_m, pixel_m, n_px) = (ground_h_m?, focal_m?, pixel_m?, n_px?);
    let camera = EarthCamera {
        focal_m,
        pixel_m,
        p1_m: cells.or("p1_m", 0.0)?,
    };
    let ellipsoid = Ellipsoid {
        a_m: cells.or("a_m", Ellipsoid::WGS84.a_m)?,
        flattening: cells.or("flattening", Ellipsoid::WGS84.flattening)?,
    };
    let earth_rate_rad_s = cells.or("earth_rate_rad_s", EARTH_RATE_RAD_S)?;
    let time = BusTime {
        gps_s: cells.number("gps_s")?,
        scales: TimeScales {
            gps_utc_s: cells.or("gps_utc_s", TimeScales::DEFAULT.gps_utc_s)?,
            dut1_s: cells.or("dut1_s", TimeScales::DEFAULT.dut1_s)?,
        },
    };
    let quaternion = cells.all(QUATERNION_COLUMNS)?;
    let camera_q = cells
        .all(CAMERA_QUATERNION_COLUMNS)?
        .unwrap_or(IDENTITY_QUATERNION);
    // Body rates default to 0 one by one (a missing or empty cell is 0 deg/s).
    let [wx, wy, wz] = BODY_RATE_COLUMNS.map(|n| cells.or(n, 0.0));
    let body_rate_dps = [wx?, wy?, wz?];
    let frame = match cells.text("frame") {
        None | Some("inertial") => StateFrame::Inertial,
        Some("itrf") => StateFrame::Itrf,
        Some("gcrf") => StateFrame::Gcrf,
        Some(_) => return Err(RowError::Invalid),
    };
    let attitude_frame = match cells.text("attitude_frame") {
        None | Some("gcrf") => AttitudeFrame::Gcrf,
        Some("itrf") => AttitudeFrame::Itrf,
        Some(_) => return Err(RowError::Invalid),
    };
    if let Some(q) = quaternion {
        quaternion_matrix(q, Param::Quaternion)?;
        quaternion_matrix(camera_q, Param::CameraQuaternion)?;
    }
    // The contract: `frame` itrf or gcrf, a quaternion in gcrf, or a DEM need `gps_s`
    // (for an ITRF state or a DEM the time is that of "I = the ITRF at t", even if no
    // C2T is needed).
    let needs_time = on_dem
        || frame != StateFrame::Inertial
        || (quaternion.is_some() && attitude_frame == AttitudeFrame::Gcrf);
    if needs_time && time.gps_s.is_none() {
        return Err(ModelError::InvalidInput(Param::GpsTime).into());
    }
    if time.gps_s.is_some() {
        time.scales.validate()?;
    }
    let state = BusState {
        frame,
        position_m,
        velocity_mps,
    };
    let geometry = match quaternion {
        Some(q) => {
            let attitude = BusAttitude {
                q,
                frame: attitude_frame,
                body_rate_rad_s: dps_to_rad_s(body_rate_dps),
                camera_q,
            };
            BusRowGeometry::Quaternion(bus_geometry(
                &state,
                &attitude,
                &time,
                ground_h_m,
                ellipsoid,
                earth_rate_rad_s,
            )?)
        }
        None => {
            let [roll, pitch, yaw, roll_rate, pitch_rate, yaw_rate] = ANGLE_COLUMNS.map(|n| {
                match cells.header.contains(&n) {
                    // Neither a quaternion nor the angles: the attitude is missing.
                    false => Err(RowError::Invalid),
                    true => cells.required(n).map(f64::to_radians),
                }
            });
            let attitude = Attitude {
                roll_rad: roll?,
                pitch_rad: pitch?,
                yaw_rad: yaw?,
                roll_rate_rad_s: roll_rate?,
                pitch_rate_rad_s: pitch_rate?,
                yaw_rate_rad_s: yaw_rate?,
            };
            // A state in I is Part I's, checked by core-math where Part I's always was.
            let state = match frame {
                StateFrame::Inertial => StateVector {
                    position_m,
                    velocity_mps,
                },
                _ => inertial_state(&state, &time, earth_rate_rad_s)?,
            };
            BusRowGeometry::Angles(EarthGeometry {
                state,
                attitude,
                ground_h_m,
                ellipsoid,
                earth_rate_rad_s,
            })
        }
    };
    Ok(BusCase {
        camera,
        geometry,
        n_px,
    })
}

impl BusCase {
    /// The geometry with the camera's axes in I (a Part I attitude converted), for the
    /// DEM's search, which needs each line of sight in I.
    fn inertial(&self) -> Result<InertialGeometry<f64>, RowError> {
        Ok(match &self.geometry {
            BusRowGeometry::Angles(g) => {
                g.validate()?;
                g.to_inertial()?
            }
            BusRowGeometry::Quaternion(g) => *g,
        })
    }
}

/// The reference's numbers for an earth case, on the ellipsoid or on the DEM.
pub(super) fn evaluate_bus_reference(
    case: &BusCase,
    dem: Option<&DemTile<'_, f64>>,
) -> Result<Vec<String>, RowError> {
    let p = EarthReference.pixel(&case.camera, case.n_px)?;
    let m = match (dem, &case.geometry) {
        (Some(tile), _) => EarthReference::motion_on_dem(&case.inertial()?, &p, tile)?,
        (None, BusRowGeometry::Angles(g)) => EarthReference.evaluate(&case.camera, g, case.n_px)?,
        (None, BusRowGeometry::Quaternion(g)) => EarthReference::motion_of(g, &p)?,
    };
    Ok(earth_numbers(&case.camera, &m)?)
}

/// The general form's numbers for an earth case, in its own precision: Part I's
/// geometry or the quaternion's (`General::update_inertial`), rounded to `T` once; on a
/// DEM, the general form's own search in `T` for the range
/// (`General::dem_inv_range`, `General::motion_at_inv_range`).
pub(super) fn evaluate_bus_general<T: Real + Display>(
    backend: &General<T>,
    case: &BusCase,
    dem: Option<&DemTile<'_, f64>>,
) -> Result<Vec<String>, RowError> {
    let p = backend.pixel(&case.camera, case.n_px)?;
    let m = match (dem, &case.geometry) {
        (Some(tile), _) => {
            let g = case.inertial()?.to::<T>();
            let up = backend.update_inertial(&g)?;
            let inv_s = backend.dem_inv_range(&g, &p, tile)?;
            backend.motion_at_inv_range(&up, &p, inv_s)?
        }
        (None, BusRowGeometry::Angles(g)) => {
            let up = backend.update(&g.to::<T>())?;
            backend.motion(&up, &p)?
        }
        (None, BusRowGeometry::Quaternion(g)) => {
            let up = backend.update_inertial(&g.to::<T>())?;
            backend.motion(&up, &p)?
        }
    };
    Ok(earth_numbers(&case.camera, &m)?)
}

/// The real Earth's fixed-point backend: Part I's angles rounded to its I24F40 input
/// (first, as Part I always has), a quaternion's axes and rates taken in f64 (its update
/// is f64 work); the results widened to f64 (exact) and printed as f64, |v|, the period
/// and the drift in f64.
pub(super) fn evaluate_bus_fixed(case: &BusCase) -> Result<Vec<String>, RowError> {
    let (camera, n_px) = (&case.camera, case.n_px);
    let m = match &case.geometry {
        BusRowGeometry::Angles(g) => crate::accuracy::EARTH_FIXED_MOTION(camera, g, n_px)?,
        BusRowGeometry::Quaternion(g) => {
            let p = EARTH_FIXED.pixel(camera, n_px)?;
            earth_fixed::motion_to_f64(&EARTH_FIXED.motion(&EARTH_FIXED.update_inertial(g)?, &p)?)
        }
    };
    Ok(earth_numbers(camera, &m)?)
}

/// G's geodetic latitude and longitude (deg) and height (m) on the row's ellipsoid, for
/// every backend from the f64 reference's chain (`EarthChain::ground_m`, on the DEM
/// where one is given): I at t is the ITRF at t, so G's coordinates in I are its ITRF
/// coordinates.
pub(super) fn ground_point(
    case: &BusCase,
    dem: Option<&DemTile<'_, f64>>,
) -> Result<[f64; 3], RowError> {
    let p = EarthReference.pixel(&case.camera, case.n_px)?;
    let (chain, ellipsoid) = match (dem, &case.geometry) {
        (Some(tile), _) => {
            let g = case.inertial()?;
            (EarthReference::chain_on_dem(&g, &p, tile)?, g.ellipsoid)
        }
        (None, BusRowGeometry::Angles(g)) => (EarthReference::chain(g, &p)?, g.ellipsoid),
        (None, BusRowGeometry::Quaternion(g)) => (EarthReference::chain(g, &p)?, g.ellipsoid),
    };
    let (lat, lon, h) = geodetic_from_itrf(chain.ground_m, &ellipsoid)?;
    Ok([lat.to_degrees(), lon.to_degrees(), h])
}

/// A DEM CSV (`shared/EARTH-MODEL.md`, "The ground from a DEM"): line 1
/// `lat0_deg,lon0_deg,dlat_deg,dlon_deg,nrows,ncols`, line 2 their values, then nrows
/// lines of ncols heights (row i at lat0 + i dlat, from the south). The tile's own
/// checks are `DemTile::new`'s.
pub(super) fn parse_dem(text: &str) -> Result<(DemGrid, Vec<f64>)> {
    let table = Table::parse(text)?;
    const HEAD: [&str; 6] = [
        "lat0_deg", "lon0_deg", "dlat_deg", "dlon_deg", "nrows", "ncols",
    ];
    if table.header != HEAD {
        bail!("line 1 must be `{}`", HEAD.join(","));
    }
    let number = |line: usize, cell: &str| -> Result<f64> {
        cell.trim()
            .parse::<f64>()
            .with_context(|| format!("line {line}: `{cell}` is not a number"))
    };
    let mut rows = table.rows.iter();
    let grid_row = rows.next().context("line 2 (the grid) is missing")?;
    if grid_row.len() != 6 {
        bail!("line 2 must hold 6 values");
    }
    let g: Vec<f64> = (0..6)
        .map(|k| number(2, &grid_row[k]))
        .collect::<Result<_>>()?;
    let count = |x: f64, name: &str| -> Result<usize> {
        if x.fract() != 0.0 || !(1.0..=1e6).contains(&x) {
            bail!("line 2: {name} must be a whole count, not {x}");
        }
        Ok(x as usize)
    };
    let grid = DemGrid {
        lat0_deg: g[0],
        lon0_deg: g[1],
        dlat_deg: g[2],
        dlon_deg: g[3],
        nrows: count(g[4], "nrows")?,
        ncols: count(g[5], "ncols")?,
    };
    let mut heights = Vec::with_capacity(grid.nrows * grid.ncols);
    for (i, row) in rows.enumerate() {
        if row.len() != grid.ncols {
            bail!(
                "line {}: {} heights, ncols is {}",
                i + 3,
                row.len(),
                grid.ncols
            );
        }
        for cell in row {
            heights.push(number(i + 3, cell)?);
        }
    }
    if heights.len() != grid.nrows * grid.ncols {
        bail!(
            "{} rows of heights, nrows is {}",
            heights.len() / grid.ncols.max(1),
            grid.nrows
        );
    }
    Ok((grid, heights))
}

/// The earth model's output text: [`write_rows`] with its outputs, and
/// `ground_lat_deg,ground_lon_deg,ground_height_m` after `error` when the header has
/// `frame` or a DEM is given. A row's checks, in order: its numbers (`unparsable_input`); a partial quaternion (some of its four
/// cells), an unknown `frame` or `attitude_frame` (`invalid_input`); the quaternions
/// (`invalid_quaternion`); a missing `gps_s` where the contract needs it
/// (`invalid_input`); the time scales; then core-math's own checks. A row is refused
/// if the backend refuses it or the reference finds no ground point for it.
pub(super) fn eval_bus_rows(
    text: &str,
    dem: Option<&DemTile<'_, f64>>,
    eval: impl Fn(&BusCase) -> Result<Vec<String>, RowError>,
) -> Result<String> {
    let table = Table::parse(text)?;
    let has = |names: &[&str]| table.header.iter().any(|h| names.contains(&h.as_str()));
    let (with_frame, with_q) = (has(&["frame"]), has(&QUATERNION_COLUMNS));
    // Part I's columns, in Part I's order; the angles unless a quaternion replaces them.
    let angles: &[&str] = if with_q { &[] } else { &ANGLE_COLUMNS };
    let common = COMMON_COLUMNS
        .iter()
        .filter(|c| dem.is_none() || **c != "ground_h_m");
    let required: Vec<&str> = STATE_COLUMNS
        .iter()
        .chain(angles)
        .chain(common)
        .copied()
        .collect();
    table.columns(&required)?;
    // In a Part I file only Part I's columns are read (an empty name is no column).
    let part1 = [
        &STATE_COLUMNS[..],
        &ANGLE_COLUMNS,
        &COMMON_COLUMNS,
        &OPTIONAL_COLUMNS,
    ]
    .concat();
    let part2 = with_frame || with_q || dem.is_some();
    let read = |h: &String| part2 || part1.contains(&h.as_str());
    let header: Vec<&str> = (table.header.iter())
        .map(|h| if read(h) { h.as_str() } else { "" })
        .collect();
    let with_ground = with_frame || dem.is_some();
    let extra: &[&str] = if with_ground { &GROUND_OUTPUTS } else { &[] };
    write_rows(&table, &EARTH_OUTPUTS, extra, |row| {
        let cells = RowCells {
            header: &header,
            row,
        };
        let case = bus_case(&cells, dem.is_some())?;
        let nums = eval(&case)?;
        let ground = match with_ground {
            true => ground_point(&case, dem)?.map(|x| x.to_string()).to_vec(),
            false => Vec::new(),
        };
        Ok((nums, ground))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const TILE: &str = include_str!("../../../core-math/tests/data/dem_tile.csv");
    const GOLDEN: &str = include_str!("../../../core-math/tests/data/dem_cases.csv");
    const PART2: &str = include_str!("../../../core-math/tests/data/part2_motion.csv");
    /// The golden file's own outputs, left out of the eval's input.
    const GOLDEN_OUTPUTS: [&str; 11] = [
        "error",
        "ground_x_m",
        "ground_y_m",
        "ground_z_m",
        "ground_lat_deg",
        "ground_lon_deg",
        "ground_height_m",
        "v1_mps",
        "v2_mps",
        "kind",
        "ground_h_m",
    ];

    /// The golden rows without the columns `outputs` names (its own results, and for the
    /// DEM goldens `ground_h_m`, which a DEM makes optional), as an eval input.
    fn input(golden: &Table, outputs: &[&str]) -> String {
        let keep: Vec<usize> = (0..golden.header.len())
            .filter(|&c| !outputs.contains(&golden.header[c].as_str()))
            .collect();
        let head: Vec<&str> = keep.iter().map(|&c| golden.header[c].as_str()).collect();
        let mut w = Writer::new("", &head).unwrap();
        for row in &golden.rows {
            let fields: Vec<&str> = keep.iter().map(|&c| row[c].as_str()).collect();
            w.row(&fields).unwrap();
        }
        w.into_string().unwrap()
    }

    /// `eval --model earth` without a DEM on the independent goldens of
    /// `tools/goldens/part2_motion.py` (the three state frames, quaternions relative to
    /// the GCRF and the ITRF, body rates, camera mountings), every backend, C2T the
    /// crate's own: the motion within core-math's golden tolerances (1e-9 for the
    /// reference and f64, 2e-6 for f32 and the fixed backend's far-from-limb target) plus
    /// 2.9e-8, the largest effect of C2T's documented error on these rows
    /// (`docs/earth-model.md`, "Part II: bus inputs"). This is the bus columns' parsing
    /// (frames, time, quaternions, rates, mounting) checked end to end; core-math's
    /// `tests/part2.rs` holds the same goldens against its own API.
    #[test]
    fn bus_eval_matches_the_independent_goldens() {
        let golden = Table::parse(PART2).unwrap();
        let mut outputs = vec!["v1_mps", "v2_mps"];
        let c2t: Vec<String> = (0..9).map(|k| format!("c2t_{}{}", k / 3, k % 3)).collect();
        outputs.extend(c2t.iter().map(String::as_str));
        let text = input(&golden, &outputs);
        for (backend, tol) in [
            ("reference", 1e-9),
            ("f64", 1e-9),
            ("f32", 2e-6),
            ("fixed", 2e-6),
        ] {
            let out = Table::parse(&eval_earth(backend, &text, None).unwrap()).unwrap();
            assert_eq!(out.rows.len(), golden.rows.len());
            assert!(golden.rows.len() >= 300);
            for i in 0..out.rows.len() {
                let case = golden.field(i, "case");
                assert_eq!(out.field(i, "error"), "", "{backend} case {case}");
                let dv = (out.num(i, "v1_mps") - golden.num(i, "v1_mps"))
                    .hypot(out.num(i, "v2_mps") - golden.num(i, "v2_mps"));
                let v = golden.num(i, "v1_mps").hypot(golden.num(i, "v2_mps"));
                assert!(
                    dv <= (tol + 2.9e-8) * v,
                    "{backend} case {case}: {:e}",
                    dv / v
                );
                // The ground point, the reference's for every backend, is on the row's
                // ellipsoid (a + h, a + h, b + h): its geodetic height is h to a few mm at
                // these heights (up to 3 km).
                let dh = out.num(i, "ground_height_m") - golden.num(i, "ground_h_m");
                assert!(dh.abs() < 0.01, "{backend} case {case}: {dh:e} m");
            }
        }
    }

    /// `eval --model earth --dem` on the independent goldens of
    /// `tools/goldens/dem_crossing.py`, every backend: the same errors, the motion within
    /// 1e-9 (reference, f64) or 5e-6 (f32) of |v|, the ground point's latitude and
    /// longitude within 1e-9 deg and its height within 0.01 m.
    #[test]
    fn dem_eval_matches_the_independent_goldens() {
        let golden = Table::parse(GOLDEN).unwrap();
        let (grid, heights) = parse_dem(TILE).unwrap();
        let tile = DemTile::new(grid, &heights).unwrap();
        let text = input(&golden, &GOLDEN_OUTPUTS);
        for (backend, tol) in [("reference", 1e-9), ("f64", 1e-9), ("f32", 5e-6)] {
            let out = Table::parse(&eval_earth(backend, &text, Some(&tile)).unwrap()).unwrap();
            assert_eq!(out.rows.len(), golden.rows.len());
            let mut hits = 0;
            for i in 0..out.rows.len() {
                let (case, error) = (golden.field(i, "case"), golden.field(i, "error"));
                assert_eq!(out.field(i, "error"), error, "{backend} case {case}");
                if !error.is_empty() {
                    continue;
                }
                let dv = (out.num(i, "v1_mps") - golden.num(i, "v1_mps"))
                    .hypot(out.num(i, "v2_mps") - golden.num(i, "v2_mps"));
                let v = golden.num(i, "v1_mps").hypot(golden.num(i, "v2_mps"));
                assert!(dv <= tol * v, "{backend} case {case}: {:e}", dv / v);
                // The ground columns are the reference's for every backend.
                for (name, gtol) in [
                    ("ground_lat_deg", 1e-9),
                    ("ground_lon_deg", 1e-9),
                    ("ground_height_m", 0.01),
                ] {
                    let d = (out.num(i, name) - golden.num(i, name)).abs();
                    assert!(d <= gtol, "{backend} case {case} {name}: {d:e}");
                }
                hits += 1;
            }
            assert!(hits >= 40, "{backend}: {hits}");
        }
    }

    /// A DEM makes `gps_s` necessary (`invalid_input`), `ground_h_m` optional, and the
    /// ground columns appear; a bad DEM file is refused whole.
    #[test]
    fn dem_rows_need_time_and_bad_files_are_refused() {
        let golden = Table::parse(GOLDEN).unwrap();
        let (grid, heights) = parse_dem(TILE).unwrap();
        let tile = DemTile::new(grid, &heights).unwrap();
        let text = input(&golden, &GOLDEN_OUTPUTS).replace("1500000000.0", "");
        let out = Table::parse(&eval_earth("f64", &text, Some(&tile)).unwrap()).unwrap();
        let e = out.columns(&["error"]).unwrap()[0];
        assert!(out.rows.iter().all(|r| r[e] == "invalid_input"));
        assert!(out
            .columns(&["ground_lat_deg", "ground_lon_deg", "ground_height_m"])
            .is_ok());
        assert!(parse_dem("lat0_deg,lon0_deg\n1,2\n").is_err());
        let short = TILE
            .rsplit_once('\n')
            .unwrap()
            .0
            .rsplit_once('\n')
            .unwrap()
            .0;
        assert!(parse_dem(short).is_err(), "a missing row of heights");
        let ragged = TILE.replacen(",", ";", 20);
        assert!(parse_dem(&ragged).is_err());
    }
}
