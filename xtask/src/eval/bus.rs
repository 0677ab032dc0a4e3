//! Part II of the eval (`shared/EARTH-MODEL.md`, "Eval CSV, Part II", without the DEM):
//! the bus's frames, time and quaternion attitude, and the ground point's geodetic
//! coordinates. A file takes this path only when its header has a `frame` column or a
//! quaternion column; any other file is Part I's, through `eval_rows` exactly as before.

use super::*;

/// `N` of Part I's input columns ([`Columns::INPUTS`] for [`Earth`]) from `start`: the
/// bus path reads the same columns, named once.
const fn part1_columns<const N: usize>(start: usize) -> [&'static str; N] {
    let inputs = <Earth as Columns>::INPUTS;
    let mut out = [""; N];
    let mut i = 0;
    while i < N {
        out[i] = inputs[start + i];
        i += 1;
    }
    out
}

/// Part I's state columns, read in the bus's `frame`.
pub(super) const STATE_COLUMNS: [&str; 6] = part1_columns(0);
/// Part I's attitude columns, replaced by the quaternion where a row has one.
pub(super) const ANGLE_COLUMNS: [&str; 6] = part1_columns(6);
/// Columns every row needs.
pub(super) const COMMON_COLUMNS: [&str; 4] = part1_columns(12);
pub(super) const QUATERNION_COLUMNS: [&str; 4] = ["qw", "qx", "qy", "qz"];
pub(super) const CAMERA_QUATERNION_COLUMNS: [&str; 4] = ["cam_qw", "cam_qx", "cam_qy", "cam_qz"];
pub(super) const BODY_RATE_COLUMNS: [&str; 3] = ["wx_dps", "wy_dps", "wz_dps"];
/// Added after `error` whenever the input has a `frame` column.
pub(super) const GROUND_OUTPUTS: [&str; 3] =
    ["ground_lat_deg", "ground_lon_deg", "ground_height_m"];

/// Whether a CSV text is evaluated as Part II: its header has `frame` or a quaternion
/// column.
pub(super) fn is_part2(text: &str) -> Result<bool> {
    let table = Table::parse(text)?;
    Ok(table
        .header
        .iter()
        .any(|h| h == "frame" || QUATERNION_COLUMNS.contains(&h.as_str())))
}

/// A row's geometry: Part I's angles (the state converted to I) or the bus quaternion.
pub(super) enum BusRowGeometry {
    Angles(EarthGeometry<f64>),
    Quaternion(InertialGeometry<f64>),
}

/// One Part II case: optics, geometry in I at t (f64), pixel.
pub(super) struct BusCase {
    camera: EarthCamera,
    geometry: BusRowGeometry,
    n_px: f64,
}

/// A row's cells by column name; an empty cell is a missing column.
pub(super) struct RowCells<'a> {
    header: &'a [String],
    row: &'a [String],
}

impl RowCells<'_> {
    fn text(&self, name: &str) -> Option<&str> {
        let c = self.header.iter().position(|h| h == name)?;
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

/// The case of a Part II row (see [`eval_bus_rows`] for the order of the checks).
pub(super) fn bus_case(cells: &RowCells) -> Result<BusCase, RowError> {
    let [x, y, z, vx, vy, vz] = STATE_COLUMNS.map(|n| cells.required(n));
    let (position_m, velocity_mps) = ([x?, y?, z?], [vx?, vy?, vz?]);
    let [ground_h_m, focal_m, pixel_m, n_px] = COMMON_COLUMNS.map(|n| cells.required(n));
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
    // The contract: `frame` itrf or gcrf, or a quaternion in gcrf, need `gps_s` (for an
    // ITRF state the time is that of "I = the ITRF at t", even if no C2T is needed).
    let needs_time = frame != StateFrame::Inertial
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
                match cells.header.iter().any(|h| h == n) {
                    // Neither a quaternion nor the angles: the attitude is missing.
                    false => Err(RowError::Invalid),
                    true => cells.required(n).map(f64::to_radians),
                }
            });
            BusRowGeometry::Angles(EarthGeometry {
                state: inertial_state(&state, &time, earth_rate_rad_s)?,
                attitude: Attitude {
                    roll_rad: roll?,
                    pitch_rad: pitch?,
                    yaw_rad: yaw?,
                    roll_rate_rad_s: roll_rate?,
                    pitch_rate_rad_s: pitch_rate?,
                    yaw_rate_rad_s: yaw_rate?,
                },
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

/// The reference's numbers for a Part II case.
pub(super) fn evaluate_bus_reference(case: &BusCase) -> Result<Vec<String>, RowError> {
    let m = match &case.geometry {
        BusRowGeometry::Angles(g) => EarthReference.evaluate(&case.camera, g, case.n_px)?,
        BusRowGeometry::Quaternion(g) => {
            let p = EarthReference.pixel(&case.camera, case.n_px)?;
            EarthReference::motion_of(g, &p)?
        }
    };
    Ok(Earth::numbers(&case.camera, &m)?)
}

/// The general form's numbers for a Part II case, in its own precision: Part I's
/// geometry or the quaternion's (`General::update_inertial`), rounded to `T` once.
pub(super) fn evaluate_bus_general<T: Real + Display>(
    backend: &General<T>,
    case: &BusCase,
) -> Result<Vec<String>, RowError> {
    let p = backend.pixel(&case.camera, case.n_px)?;
    let up = match &case.geometry {
        BusRowGeometry::Angles(g) => backend.update(&g.to::<T>())?,
        BusRowGeometry::Quaternion(g) => backend.update_inertial(&g.to::<T>())?,
    };
    let m = backend.motion(&up, &p)?;
    Ok(Earth::numbers(&case.camera, &m)?)
}

/// G's geodetic latitude and longitude (deg) and height (m) on the row's ellipsoid, for
/// every backend from the f64 reference's chain (`EarthChain::ground_m`): I at t is the
/// ITRF at t, so G's coordinates in I are its ITRF coordinates.
pub(super) fn ground_point(case: &BusCase) -> Result<[f64; 3], RowError> {
    let p = EarthReference.pixel(&case.camera, case.n_px)?;
    let (chain, ellipsoid) = match &case.geometry {
        BusRowGeometry::Angles(g) => (EarthReference::chain(g, &p)?, g.ellipsoid),
        BusRowGeometry::Quaternion(g) => (EarthReference::chain(g, &p)?, g.ellipsoid),
    };
    let (lat, lon, h) = geodetic_from_itrf(chain.ground_m, &ellipsoid)?;
    Ok([lat.to_degrees(), lon.to_degrees(), h])
}

/// The Part II output: as [`eval_rows`], with `ground_lat_deg,ground_lon_deg,
/// ground_height_m` after `error` when the header has `frame`. A row's checks, in
/// order: its numbers (`unparsable_input`); a partial quaternion (some of its four
/// cells), an unknown `frame` or `attitude_frame` (`invalid_input`); the quaternions
/// (`invalid_quaternion`); a missing `gps_s` where the contract needs it
/// (`invalid_input`); the time scales; then core-math's own checks. A row is refused
/// if the backend refuses it or the reference finds no ground point for it.
pub(super) fn eval_bus_rows(
    text: &str,
    eval: impl Fn(&BusCase) -> Result<Vec<String>, RowError>,
) -> Result<String> {
    let table = Table::parse(text)?;
    table.columns(&STATE_COLUMNS)?;
    table.columns(&COMMON_COLUMNS)?;
    if !table
        .header
        .iter()
        .any(|h| QUATERNION_COLUMNS.contains(&h.as_str()))
    {
        table.columns(&ANGLE_COLUMNS)?;
    }
    let with_ground = table.header.iter().any(|h| h == "frame");
    let extra: &[&str] = if with_ground { &GROUND_OUTPUTS } else { &[] };
    let header: Vec<&str> = table
        .header
        .iter()
        .map(String::as_str)
        .chain(Earth::OUTPUTS.iter().copied())
        .chain(extra.iter().copied())
        .collect();
    let mut out = Writer::new("", &header)?;
    let blank = vec![String::new(); Earth::OUTPUTS.len() - 1];
    let blank_ground = vec![String::new(); extra.len()];
    for row in &table.rows {
        let cells = RowCells {
            header: &table.header,
            row,
        };
        let result = bus_case(&cells).and_then(|case| {
            let nums = eval(&case)?;
            let ground = if with_ground {
                ground_point(&case)?.map(|x| x.to_string()).to_vec()
            } else {
                Vec::new()
            };
            Ok((nums, ground))
        });
        let (nums, ground, error) = match result {
            Ok((nums, ground)) => (nums, ground, ""),
            Err(e) => (blank.clone(), blank_ground.clone(), e.name()),
        };
        let fields: Vec<&str> = row
            .iter()
            .chain(&nums)
            .map(String::as_str)
            .chain([error])
            .chain(ground.iter().map(String::as_str))
            .collect();
        out.row(&fields)?;
    }
    out.into_string()
}
