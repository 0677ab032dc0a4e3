//! `cargo xtask eval [--model <sphere|earth>] --backend <...> --input CASES.csv`: a model
//! on user-supplied cases, CSV out, so the firmware's numbers can be checked on the
//! ground. `sphere` (the default) is the paper's round Earth, its columns
//! [`SPHERE_INPUTS`]; `earth` the real-Earth model, with the columns
//! `shared/EARTH-MODEL.md` ("Eval CSV") specifies. Every earth file is read by [`bus`],
//! whose columns are Part I's with Part II's ("Eval CSV, Part II": the bus's frames,
//! time, quaternions, a DEM's ground) optional on top. Both models share the output
//! ([`write_rows`]): each input row as given, then its numbers or its error's name.

use std::fmt::Display;

use anyhow::{bail, Context, Result};
use core_math::earth::bus::{
    bus_geometry, dps_to_rad_s, inertial_state, quaternion_matrix, AttitudeFrame, BusAttitude,
    BusState, BusTime, StateFrame, IDENTITY_QUATERNION,
};
use core_math::earth::dem::{DemGrid, DemTile};
use core_math::earth::fixed as earth_fixed;
use core_math::earth::frames::{geodetic_from_itrf, TimeScales};
use core_math::earth::{Attitude, EarthCamera, EarthGeometry, InertialGeometry};
use core_math::sphere::fixed_point::{geometry_from_f64, motion_to_f64};
use core_math::sphere::{
    speed_line_period_s, Geometry, Reference, Sphere, CLOSED_F32, CLOSED_F64, FIXED,
};
use core_math::{
    line_period_s, Backend, Camera, EarthReference, Ellipsoid, General, ImageMotion, ModelError,
    Param, Real, StateVector, EARTH_FIXED, EARTH_RATE_RAD_S, GENERAL_F32, GENERAL_F64,
};

use crate::csv::{Table, Writer};

mod bus;
use bus::*;

/// The Earth of a model.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Model {
    /// The paper's round Earth
    Sphere,
    /// The real-Earth model of shared/EARTH-MODEL.md (WGS 84)
    Earth,
}

#[derive(clap::Args)]
pub struct Args {
    /// The model's Earth
    #[arg(long, value_enum, default_value_t = Model::Sphere)]
    model: Model,
    /// The implementation to run (earth with --dem: no fixed)
    #[arg(long, value_parser = ["reference", "f64", "f32", "fixed"])]
    backend: String,
    /// The cases: a CSV file whose header names the model's input columns (`-`: stdin)
    #[arg(long, value_name = "CASES.csv")]
    input: String,
    /// The ground as a DEM tile (earth model; the DEM CSV of shared/EARTH-MODEL.md,
    /// "The ground from a DEM")
    #[arg(long, value_name = "FILE.csv")]
    dem: Option<String>,
}

pub fn run(args: &Args) -> Result<()> {
    let input = &args.input;
    let text = if input == "-" {
        std::io::read_to_string(std::io::stdin()).context("reading stdin")?
    } else {
        std::fs::read_to_string(input).with_context(|| format!("reading {input}"))?
    };
    let Some(dem) = &args.dem else {
        print!("{}", eval_csv(args.model, &args.backend, &text)?);
        return Ok(());
    };
    if args.model != Model::Earth {
        bail!("eval: --dem needs --model earth");
    }
    let dem_text = std::fs::read_to_string(dem).with_context(|| format!("reading {dem}"))?;
    let (grid, heights) = parse_dem(&dem_text).with_context(|| format!("DEM {dem}"))?;
    let tile = DemTile::new(grid, &heights)
        .map_err(|e| anyhow::anyhow!("DEM {dem}: the tile is refused: {e}"))?;
    print!("{}", eval_earth(&args.backend, &text, Some(&tile))?);
    Ok(())
}

/// The whole command on a CSV text: one output row per input row, always.
pub fn eval_csv(model: Model, backend: &str, text: &str) -> Result<String> {
    match (model, backend) {
        (Model::Sphere, "reference") => sphere_rows(text, |c| evaluate(&Reference, c)),
        (Model::Sphere, "f64") => sphere_rows(text, |c| evaluate(&CLOSED_F64, c)),
        (Model::Sphere, "f32") => sphere_rows(text, |c| evaluate(&CLOSED_F32, c)),
        (Model::Sphere, "fixed") => sphere_rows(text, evaluate_fixed),
        (Model::Sphere, other) => bail!("unknown backend `{other}` (reference|f64|f32|fixed)"),
        (Model::Earth, _) => eval_earth(backend, text, None),
    }
}

/// The earth model on a CSV text, its ground the row's ellipsoid or a DEM tile (`dem`):
/// one output row per input row.
pub fn eval_earth(backend: &str, text: &str, dem: Option<&DemTile<'_, f64>>) -> Result<String> {
    match backend {
        "reference" => eval_bus_rows(text, dem, |c| evaluate_bus_reference(c, dem)),
        "f64" => eval_bus_rows(text, dem, |c| evaluate_bus_general(&GENERAL_F64, c, dem)),
        "f32" => eval_bus_rows(text, dem, |c| evaluate_bus_general(&GENERAL_F32, c, dem)),
        "fixed" if dem.is_none() => eval_bus_rows(text, None, evaluate_bus_fixed),
        "fixed" => bail!(
            "eval: the fixed-point backend has no DEM ground (its per-pixel work is the \
             ellipsoid's root): use --dem with reference|f64|f32, or drop --dem"
        ),
        other if dem.is_some() => bail!(
            "eval: unknown backend `{other}` for the earth model on a DEM (reference|f64|f32)"
        ),
        other => {
            bail!("eval: unknown backend `{other}` for the earth model (reference|f64|f32|fixed)")
        }
    }
}

/// The round Earth's input columns, in the order [`sphere_rows`] reads them.
const SPHERE_INPUTS: [&str; 8] = [
    "n_px",
    "phi_deg",
    "i0_deg",
    "gamma0_deg",
    "h_m",
    "f_m",
    "pixel_m",
    "r_m",
];
/// Output columns, the last of which is `error`.
const SPHERE_OUTPUTS: [&str; 5] = ["v1_mps", "v2_mps", "v_mps", "line_period_s", "error"];
const EARTH_OUTPUTS: [&str; 6] = [
    "v1_mps",
    "v2_mps",
    "v_mps",
    "line_period_s",
    "drift_rad",
    "error",
];

/// One round-Earth case in SI units: optics, geometry (f64, to be rounded by the
/// backend), pixel.
struct SphereCase {
    camera: Camera,
    geometry: Geometry<f64>,
    n_px: f64,
}

/// v1, v2, |v| and the line period pixel/|v|.
fn sphere_numbers<T: Real + Display>(
    c: &Camera,
    m: &ImageMotion<T>,
) -> Result<Vec<String>, ModelError> {
    let speed = m.speed_mps();
    let period = speed_line_period_s(T::from_f64(c.pixel_m), speed)?;
    Ok([m.v1_mps, m.v2_mps, speed, period]
        .map(|x| x.to_string())
        .to_vec())
}

/// v1, v2, |v|, the line period pixel/|v1| and the drift atan(v2/v1).
fn earth_numbers<T: Real + Display>(
    c: &EarthCamera,
    m: &ImageMotion<T>,
) -> Result<Vec<String>, ModelError> {
    let period = line_period_s(T::from_f64(c.pixel_m), m);
    if !period.is_finite() {
        return Err(ModelError::NoAlongTrackMotion);
    }
    let numbers = [m.v1_mps, m.v2_mps, m.speed_mps(), period, m.drift_rad()];
    Ok(numbers.map(|x| x.to_string()).to_vec())
}

/// Why a row has no numbers.
enum RowError {
    Model(ModelError),
    Unparsable,
    /// A Part II input the contract refuses as `invalid_input` that core-math has no
    /// parameter for (an unknown `frame` or `attitude_frame`, a quaternion with some
    /// but not all of its four cells, a row with neither a quaternion nor the angles).
    Invalid,
}

impl RowError {
    fn name(&self) -> &'static str {
        match self {
            RowError::Model(e) => e.name(),
            RowError::Unparsable => "unparsable_input",
            RowError::Invalid => "invalid_input",
        }
    }
}

impl From<ModelError> for RowError {
    fn from(e: ModelError) -> Self {
        RowError::Model(e)
    }
}

/// The round Earth's output text: [`write_rows`] with its outputs, a row's case read
/// from [`SPHERE_INPUTS`] (angles in deg, as the CSV gives them).
fn sphere_rows(
    text: &str,
    eval: impl Fn(&SphereCase) -> Result<Vec<String>, RowError>,
) -> Result<String> {
    let table = Table::parse(text)?;
    let columns = table.columns(&SPHERE_INPUTS)?;
    write_rows(&table, &SPHERE_OUTPUTS, &[], |row| {
        let number = |c: &usize| {
            let text = row.get(*c).map_or("", String::as_str);
            text.parse::<f64>().map_err(|_| RowError::Unparsable)
        };
        let v = columns
            .iter()
            .map(number)
            .collect::<Result<Vec<f64>, _>>()?;
        let &[n_px, phi_deg, i0_deg, gamma0_deg, h_m, f_m, pixel_m, r_m] = v.as_slice() else {
            unreachable!("eight input columns")
        };
        let rad = f64::to_radians;
        let case = SphereCase {
            camera: Camera {
                focal_m: f_m,
                pixel_m,
            },
            geometry: Geometry::circular(rad(phi_deg), rad(i0_deg), rad(gamma0_deg), h_m, r_m),
            n_px,
        };
        Ok((eval(&case)?, Vec::new()))
    })
}

/// The output text: the input header, `outputs` (`error` last) and `extra`, then each
/// input row as given followed by its numbers, an empty error and its extra cells, or by
/// empty numbers, the error's name and empty extra cells.
fn write_rows(
    table: &Table,
    outputs: &[&str],
    extra: &[&str],
    row_out: impl Fn(&[String]) -> Result<(Vec<String>, Vec<String>), RowError>,
) -> Result<String> {
    let input = table.header.iter().map(String::as_str);
    let header: Vec<&str> = input.chain(outputs.iter().chain(extra).copied()).collect();
    let mut out = Writer::new("", &header)?;
    let blank = (
        vec![String::new(); outputs.len() - 1],
        vec![String::new(); extra.len()],
    );
    for row in &table.rows {
        let ((nums, more), error) = match row_out(row) {
            Ok(cells) => (cells, ""),
            Err(e) => (blank.clone(), e.name()),
        };
        let fields = row.iter().chain(&nums).map(String::as_str).chain([error]);
        out.row(
            &fields
                .chain(more.iter().map(String::as_str))
                .collect::<Vec<_>>(),
        )?;
    }
    out.into_string()
}

/// A backend's numbers, the geometry rounded to its precision once, in its own
/// precision (shortest text that reads back to the same value).
fn evaluate<B: Backend<Sphere>>(backend: &B, case: &SphereCase) -> Result<Vec<String>, RowError>
where
    B::Real: Real + Display,
{
    let g = case.geometry.to::<B::Real>();
    let m = backend.evaluate(&case.camera, &g, case.n_px)?;
    Ok(sphere_numbers(&case.camera, &m)?)
}

/// The fixed-point backend: the geometry rounded to I24F40, the results widened to f64
/// (exact) and printed as f64; |v| and the line period in f64 from them.
fn evaluate_fixed(case: &SphereCase) -> Result<Vec<String>, RowError> {
    let g = geometry_from_f64(&case.geometry)?;
    let m = motion_to_f64(&FIXED.evaluate(&case.camera, &g, case.n_px)?);
    Ok(sphere_numbers(&case.camera, &m)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    const CASES: &str = "case,n_px,phi_deg,i0_deg,gamma0_deg,h_m,f_m,pixel_m,r_m
nadir,0,0,97.98,0,645000,0.555,13e-6,6370000
far,30000,25,97.98,45,645000,0.555,13e-6,6370000
beyond_limb,30000,45,97.98,45,645000,0.555,13e-6,6370000
bad_focal,0,0,97.98,0,645000,0,13e-6,6370000
garbled,x,0,97.98,0,645000,0.555,13e-6,6370000
";

    /// A 645 km sun-synchronous state (circular: 7 016 137 m, 7 537.5 m/s), then the same
    /// agile, eccentric and mountainous; a case with the optional columns given, one
    /// beyond the limb, one with a bad focal length, one garbled.
    const EARTH_CASES: &str = "case,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps,roll_deg,pitch_deg,yaw_deg,\
roll_rate_dps,pitch_rate_dps,yaw_rate_dps,ground_h_m,f_m,pixel_m,n_px,p1_m,a_m
nadir,7016137,0,0,0,-1046.6,7464.5,0,0,0,0,0,0,0,0.555,13e-6,0,,
agile,7016137,0,0,150,-1046.6,7464.5,20,-25,7,0.3,-1,0.5,4000,0.555,13e-6,20000,0.01,
sphere,7016137,0,0,0,-1046.6,7464.5,0,0,0,0,0,0,0,0.555,13e-6,0,,6371000
beyond_limb,7016137,0,0,0,-1046.6,7464.5,70,0,0,0,0,0,0,0.555,13e-6,0,,
bad_focal,7016137,0,0,0,-1046.6,7464.5,0,0,0,0,0,0,0,0,13e-6,0,,
garbled,7016137,0,0,0,-1046.6,7464.5,x,0,0,0,0,0,0,0.555,13e-6,0,,
";

    /// The output of `eval` on `cases`, read back.
    fn out(model: Model, backend: &str, cases: &str) -> Table {
        Table::parse(&eval_csv(model, backend, cases).unwrap()).unwrap()
    }

    #[test]
    fn one_row_per_input_row_with_typed_errors() {
        for backend in ["reference", "f64", "f32", "fixed"] {
            let out = out(Model::Sphere, backend, CASES);
            assert_eq!(out.rows.len(), 5);
            assert!(out
                .header
                .join(",")
                .ends_with("v1_mps,v2_mps,v_mps,line_period_s,error"));
            assert_eq!(out.field(0, "case"), "nadir", "extra columns are kept");
            assert_eq!(out.field(0, "error"), "");
            assert_eq!(out.field(2, "error"), "line_of_sight_misses_earth");
            assert_eq!(out.field(2, "v1_mps"), "");
            assert_eq!(out.field(3, "error"), "non_positive_focal_length");
            assert_eq!(out.field(4, "error"), "unparsable_input");
        }
        assert!(eval_csv(Model::Sphere, "f16", CASES).is_err());
    }

    #[test]
    fn backends_agree_and_period_is_pixel_over_speed() {
        let r = out(Model::Sphere, "reference", CASES);
        let f = out(Model::Sphere, "f32", CASES);
        let x = out(Model::Sphere, "fixed", CASES);
        for row in 0..2 {
            let (vr, vf, vx) = (
                r.num(row, "v_mps"),
                f.num(row, "v_mps"),
                x.num(row, "v_mps"),
            );
            assert!((vf - vr).abs() / vr < 1e-6, "{vf} vs {vr}");
            assert!((vx - vr).abs() / vr < 2e-6, "fixed {vx} vs {vr}");
            let t = r.num(row, "line_period_s");
            assert!((t - 13e-6 / vr).abs() < 1e-15 * t);
        }
    }

    #[test]
    fn earth_one_row_per_input_row_with_typed_errors() {
        for backend in ["reference", "f64", "f32", "fixed"] {
            let out = out(Model::Earth, backend, EARTH_CASES);
            assert_eq!(out.rows.len(), 6);
            assert!(out
                .header
                .join(",")
                .ends_with("v1_mps,v2_mps,v_mps,line_period_s,drift_rad,error"));
            assert_eq!(out.field(0, "case"), "nadir", "extra columns are kept");
            for row in 0..3 {
                assert_eq!(out.field(row, "error"), "", "row {row}");
            }
            assert_eq!(out.field(3, "error"), "line_of_sight_misses_earth");
            assert_eq!(out.field(3, "v1_mps"), "");
            assert_eq!(out.field(4, "error"), "invalid_input");
            assert_eq!(out.field(5, "error"), "unparsable_input");
        }
        assert!(eval_csv(Model::Earth, "f16", EARTH_CASES).is_err());
    }

    /// A DEM ground has no fixed-point path: refused with the reason, not evaluated.
    #[test]
    fn earth_fixed_on_a_dem_is_refused() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../core-math/tests/data/dem_tile.csv"
        );
        let (grid, heights) = parse_dem(&std::fs::read_to_string(path).unwrap()).unwrap();
        let tile = DemTile::new(grid, &heights).unwrap();
        let err = eval_earth("fixed", BUS_CASES, Some(&tile)).unwrap_err();
        assert!(err.to_string().contains("no DEM ground"), "{err}");
        assert!(eval_earth("f64", BUS_CASES, Some(&tile)).is_ok());
    }

    /// The derived outputs follow the definition from v1 and v2, and the backends agree.
    #[test]
    fn earth_derived_outputs_and_agreement() {
        let r = out(Model::Earth, "reference", EARTH_CASES);
        let f = out(Model::Earth, "f32", EARTH_CASES);
        let x = out(Model::Earth, "fixed", EARTH_CASES);
        for row in 0..3 {
            let d = (x.num(row, "v1_mps") - r.num(row, "v1_mps"))
                .hypot(x.num(row, "v2_mps") - r.num(row, "v2_mps"));
            let v = r.num(row, "v_mps");
            assert!(d / v < 2e-6, "fixed, row {row}: {}", d / v);
            let t = x.num(row, "line_period_s");
            assert!((t - 13e-6 / x.num(row, "v1_mps").abs()).abs() <= 1e-15 * t);
            let (v1, v2) = (r.num(row, "v1_mps"), r.num(row, "v2_mps"));
            assert!((r.num(row, "v_mps") - v1.hypot(v2)).abs() <= 1e-16);
            let t = r.num(row, "line_period_s");
            assert!((t - 13e-6 / v1.abs()).abs() <= 1e-15 * t);
            assert!((r.num(row, "drift_rad") - (v2 / v1).atan()).abs() <= 1e-15);
            let d = (f.num(row, "v1_mps") - v1).hypot(f.num(row, "v2_mps") - v2);
            assert!(d / v1.hypot(v2) < 2e-6, "row {row}");
        }
    }

    /// Part II rows (shared/EARTH-MODEL.md, "Eval CSV, Part II"), 2024-01-01 or so: Part
    /// I's angles with the state in the ITRF and the GCRF; a quaternion relative to the
    /// ITRF and to the GCRF (boresight to nadir, gyro rates, a camera mounting); a bad
    /// quaternion; a GCRF state and a GCRF quaternion without `gps_s`; an unknown frame.
    const BUS_CASES: &str = "case,frame,gps_s,dut1_s,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps,\
roll_deg,pitch_deg,yaw_deg,roll_rate_dps,pitch_rate_dps,yaw_rate_dps,\
qw,qx,qy,qz,attitude_frame,wx_dps,wy_dps,wz_dps,cam_qw,cam_qx,cam_qy,cam_qz,\
ground_h_m,f_m,pixel_m,n_px
itrf_angles,itrf,1388000000,,7016137,0,0,0,-1558.2,7464.5,5,-3,2,0.1,0,0,,,,,,,,,,,,,300,0.555,13e-6,1000
gcrf_angles,gcrf,1388000000,0.2,7016137,0,0,0,-1046.6,7464.5,5,-3,2,0.1,0,0,,,,,,,,,,,,,300,0.555,13e-6,1000
itrf_q,itrf,1388000000,,7016137,0,0,0,-1558.2,7464.5,,,,,,,0.70710678,0,0.70710678,0,itrf,0.01,-0.06,0.02,0.9998477,0.0174524,0,0,100,0.555,13e-6,-2000
gcrf_q,gcrf,1388000000,0.2,7016137,0,0,0,-1046.6,7464.5,,,,,,,0.70710678,0,0.70710678,0,,0.01,-0.06,0.02,,,,,100,0.555,13e-6,-2000
bad_q,gcrf,1388000000,,7016137,0,0,0,-1046.6,7464.5,,,,,,,0.8,0,0.8,0,gcrf,,,,,,,,0,0.555,13e-6,0
bad_cam_q,itrf,1388000000,,7016137,0,0,0,-1046.6,7464.5,,,,,,,1,0,0,0,itrf,,,,0.5,0,0,0,0,0.555,13e-6,0
gcrf_no_time,gcrf,,,7016137,0,0,0,-1046.6,7464.5,0,0,0,0,0,0,,,,,,,,,,,,,0,0.555,13e-6,0
q_no_time,inertial,,,7016137,0,0,0,-1046.6,7464.5,,,,,,,0.70710678,0,0.70710678,0,gcrf,,,,,,,,0,0.555,13e-6,0
itrf_no_time,itrf,,,7016137,0,0,0,-1046.6,7464.5,0,0,0,0,0,0,,,,,,,,,,,,,0,0.555,13e-6,0
bad_frame,ecef,1388000000,,7016137,0,0,0,-1046.6,7464.5,0,0,0,0,0,0,,,,,,,,,,,,,0,0.555,13e-6,0
partial_q,itrf,1388000000,,7016137,0,0,0,-1046.6,7464.5,,,,,,,1,0,,0,itrf,,,,,,,,0,0.555,13e-6,0
one_rate,itrf,1388000000,,7016137,0,0,0,-1558.2,7464.5,,,,,,,0.70710678,0,0.70710678,0,itrf,,-0.06,,,,,,0,0.555,13e-6,0
";

    #[test]
    fn bus_rows_typed_errors() {
        for backend in ["reference", "f64", "f32", "fixed"] {
            let out = out(Model::Earth, backend, BUS_CASES);
            assert_eq!(out.rows.len(), 12);
            for row in (0..4).chain([11]) {
                assert_eq!(out.field(row, "error"), "", "{backend} row {row}");
            }
            assert_eq!(out.field(4, "error"), "invalid_quaternion");
            assert_eq!(out.field(5, "error"), "invalid_quaternion");
            assert_eq!(out.field(6, "error"), "invalid_input", "gcrf without gps_s");
            assert_eq!(
                out.field(7, "error"),
                "invalid_input",
                "gcrf q without gps_s"
            );
            assert_eq!(out.field(8, "error"), "invalid_input", "itrf without gps_s");
            assert_eq!(out.field(9, "error"), "invalid_input", "unknown frame");
            assert_eq!(
                out.field(10, "error"),
                "invalid_input",
                "partial quaternion"
            );
            for row in 4..11 {
                assert_eq!(out.field(row, "v1_mps"), "");
                assert_eq!(out.field(row, "ground_lat_deg"), "");
            }
        }
    }

    /// The ground columns come with a `frame` column only: not with Part I's columns,
    /// nor with a quaternion alone.
    #[test]
    fn ground_columns_only_with_frame() {
        let ground = "error,ground_lat_deg,ground_lon_deg,ground_height_m";
        let q_only = "qw,qx,qy,qz,attitude_frame,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps,\
ground_h_m,f_m,pixel_m,n_px
0.70710678,0,0.70710678,0,itrf,7016137,0,0,0,-1558.2,7464.5,0,0.555,13e-6,0
";
        for backend in ["reference", "f64", "f32"] {
            assert!(out(Model::Earth, backend, BUS_CASES)
                .header
                .join(",")
                .ends_with(ground));
            let part1 = out(Model::Earth, backend, EARTH_CASES);
            assert!(part1.header.join(",").ends_with("drift_rad,error"));
            let q = out(Model::Earth, backend, q_only);
            assert!(q.header.join(",").ends_with("drift_rad,error"));
            assert_eq!(q.field(0, "error"), "");
        }
    }

    /// Part I's rows keep their numbers and errors with a `frame` column (empty or
    /// `inertial`), and gain the ground columns.
    #[test]
    fn part1_rows_unchanged_under_frame_column() {
        let with_frame: String = EARTH_CASES
            .lines()
            .enumerate()
            .map(|(i, line)| match i {
                0 => format!("frame,{line}\n"),
                i if i % 2 == 0 => format!("inertial,{line}\n"),
                _ => format!(",{line}\n"),
            })
            .collect();
        for backend in ["reference", "f64", "f32"] {
            let old = out(Model::Earth, backend, EARTH_CASES);
            let new = out(Model::Earth, backend, &with_frame);
            assert_eq!(new.rows.len(), old.rows.len());
            for row in 0..old.rows.len() {
                for name in EARTH_OUTPUTS.iter().chain(&["case"]) {
                    assert_eq!(new.field(row, name), old.field(row, name), "{row} {name}");
                }
                let lat = new.field(row, "ground_lat_deg");
                assert_eq!(lat.is_empty(), !old.field(row, "error").is_empty());
            }
            // The nadir row looks straight down on the equator at longitude 0.
            assert!(new.num(0, "ground_lat_deg").abs() < 1e-9);
            assert!(new.num(0, "ground_lon_deg").abs() < 1e-9);
            assert!(new.num(0, "ground_height_m").abs() < 1e-6);
        }
    }
    /// A row's numbers are read before any of core-math's checks (`unparsable_input`
    /// first), and Part I's rows in a `frame` file keep Part I's first error: for a
    /// state that is not finite with a zero focal length, the camera's (`invalid_input`,
    /// as `bad_focal` above).
    #[test]
    fn row_checks_in_the_documented_order() {
        let head = "frame,gps_s,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps,roll_deg,pitch_deg,yaw_deg,\
roll_rate_dps,pitch_rate_dps,yaw_rate_dps,ground_h_m,f_m,pixel_m,n_px\n";
        for frame in ["", "inertial", "itrf"] {
            let rows = format!(
                "{head}{frame},1388000000,inf,0,0,0,7500,0,x,0,0,0,0,0,0,0.555,13e-6,0\n\
                 {frame},1388000000,inf,0,0,0,7500,0,10,0,0,0,0,0,0,0,13e-6,0\n"
            );
            let out = out(Model::Earth, "f64", &rows);
            assert_eq!(out.field(0, "error"), "unparsable_input", "{frame}");
            if frame != "itrf" {
                assert_eq!(out.field(1, "error"), "invalid_input", "{frame}");
            }
        }
    }
}
