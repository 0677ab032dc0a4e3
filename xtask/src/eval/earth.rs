//! `cargo xtask eval --model earth --backend <reference|f64|f32>`: the real-Earth model
//! on user-supplied cases, exactly as `shared/EARTH-MODEL.md` ("Eval CSV") specifies.

use anyhow::{anyhow, Result};
use core_math::earth::{line_period_s, Attitude, EarthCamera, EarthGeometry};
use core_math::{
    Backend, Earth, EarthReference, Ellipsoid, ModelError, Real, StateVector, EARTH_RATE_RAD_S,
    GENERAL_F32, GENERAL_F64,
};

use crate::csv::Table;

use super::EvalError;

/// Required input columns, in the order the case is built from them.
pub const INPUT_COLUMNS: [&str; 16] = [
    "x_m",
    "y_m",
    "z_m",
    "vx_mps",
    "vy_mps",
    "vz_mps",
    "roll_deg",
    "pitch_deg",
    "yaw_deg",
    "roll_rate_dps",
    "pitch_rate_dps",
    "yaw_rate_dps",
    "ground_h_m",
    "f_m",
    "pixel_m",
    "n_px",
];
/// Optional input columns and their defaults (a missing column or an empty cell).
pub const OPTIONAL_COLUMNS: [(&str, f64); 4] = [
    ("p1_m", 0.0),
    ("a_m", Ellipsoid::WGS84.a_m),
    ("flattening", Ellipsoid::WGS84.flattening),
    ("earth_rate_rad_s", EARTH_RATE_RAD_S),
];
pub const OUTPUT_COLUMNS: [&str; 6] = [
    "v1_mps",
    "v2_mps",
    "v_mps",
    "line_period_s",
    "drift_rad",
    "error",
];
pub const BACKENDS: &str = "reference|f64|f32";

/// One case in SI units: optics, geometry (f64; the backend rounds the attitude), pixel.
#[derive(Clone, Copy, Debug)]
pub struct Case {
    pub camera: EarthCamera,
    pub geometry: EarthGeometry<f64>,
    pub n_px: f64,
}

/// The whole command on a CSV text: one output row per input row, always.
pub fn eval_csv(backend: &str, text: &str) -> Result<String> {
    if !["reference", "f64", "f32"].contains(&backend) {
        return Err(if backend == "fixed" {
            anyhow!(
                "eval: the earth model has no fixed-point backend (use reference|f64|f32, or \
                 --model sphere for fixed)"
            )
        } else {
            anyhow!("eval: unknown backend `{backend}` for the earth model ({BACKENDS})")
        });
    }
    let table = Table::parse(text)?;
    let required = table.columns(&INPUT_COLUMNS)?;
    let optional: Vec<Option<usize>> = OPTIONAL_COLUMNS
        .iter()
        .map(|(name, _)| table.header.iter().position(|h| h == name))
        .collect();
    super::write_rows(&table, &OUTPUT_COLUMNS, |row| {
        parse_case(row, &required, &optional).and_then(|case| match backend {
            "reference" => evaluate(&EarthReference, &case, |g| g),
            "f64" => evaluate(&GENERAL_F64, &case, |g| g),
            _ => evaluate(&GENERAL_F32, &case, |g| g.to::<f32>()),
        })
    })
}

fn parse_case(
    row: &[String],
    required: &[usize],
    optional: &[Option<usize>],
) -> Result<Case, EvalError> {
    let cell = |c: usize| row.get(c).map(String::as_str).unwrap_or("");
    let mut v = [0.0f64; 16];
    for (slot, &c) in v.iter_mut().zip(required) {
        *slot = cell(c).parse::<f64>().map_err(|_| EvalError::Unparsable)?;
    }
    let mut o = [0.0f64; 4];
    for ((slot, col), (_, default)) in o.iter_mut().zip(optional).zip(OPTIONAL_COLUMNS) {
        *slot = match col.map(&cell) {
            None | Some("") => default,
            Some(text) => text.parse::<f64>().map_err(|_| EvalError::Unparsable)?,
        };
    }
    let [x, y, z, vx, vy, vz, roll, pitch, yaw, roll_rate, pitch_rate, yaw_rate, ground_h_m, f_m, pixel_m, n_px] =
        v;
    let [p1_m, a_m, flattening, earth_rate_rad_s] = o;
    let rad = f64::to_radians;
    Ok(Case {
        camera: EarthCamera {
            focal_m: f_m,
            pixel_m,
            p1_m,
        },
        geometry: EarthGeometry {
            state: StateVector {
                position_m: [x, y, z],
                velocity_mps: [vx, vy, vz],
            },
            attitude: Attitude {
                roll_rad: rad(roll),
                pitch_rad: rad(pitch),
                yaw_rad: rad(yaw),
                roll_rate_rad_s: rad(roll_rate),
                pitch_rate_rad_s: rad(pitch_rate),
                yaw_rate_rad_s: rad(yaw_rate),
            },
            ground_h_m,
            ellipsoid: Ellipsoid { a_m, flattening },
            earth_rate_rad_s,
        },
        n_px,
    })
}

/// v1, v2, |v|, the line period pixel/|v1| and the drift atan(v2/v1), in the backend's
/// own precision, printed as the shortest text that reads back to the same value.
fn evaluate<B: Backend<Earth>>(
    backend: &B,
    case: &Case,
    to_real: impl Fn(EarthGeometry<f64>) -> EarthGeometry<B::Real>,
) -> Result<[String; 5], EvalError>
where
    B::Real: Real + std::fmt::Display,
{
    let m = backend.evaluate(&case.camera, &to_real(case.geometry), case.n_px)?;
    let period = line_period_s(B::Real::from_f64(case.camera.pixel_m), &m);
    if !period.is_finite() {
        return Err(EvalError::Model(ModelError::NoAlongTrackMotion));
    }
    Ok([
        m.v1_mps.to_string(),
        m.v2_mps.to_string(),
        m.speed_mps().to_string(),
        period.to_string(),
        m.drift_rad().to_string(),
    ])
}

#[cfg(test)]
mod tests {
    use super::super::tests::Out;
    use super::*;

    /// A 645 km sun-synchronous state (circular: 7 016 137 m, 7 537.5 m/s), then the same
    /// agile, eccentric and mountainous; a case with the optional columns given, one
    /// beyond the limb, one with a bad focal length, one garbled.
    const CASES: &str = "case,x_m,y_m,z_m,vx_mps,vy_mps,vz_mps,roll_deg,pitch_deg,yaw_deg,\
roll_rate_dps,pitch_rate_dps,yaw_rate_dps,ground_h_m,f_m,pixel_m,n_px,p1_m,a_m
nadir,7016137,0,0,0,-1046.6,7464.5,0,0,0,0,0,0,0,0.555,13e-6,0,,
agile,7016137,0,0,150,-1046.6,7464.5,20,-25,7,0.3,-1,0.5,4000,0.555,13e-6,20000,0.01,
sphere,7016137,0,0,0,-1046.6,7464.5,0,0,0,0,0,0,0,0.555,13e-6,0,,6371000
beyond_limb,7016137,0,0,0,-1046.6,7464.5,70,0,0,0,0,0,0,0.555,13e-6,0,,
bad_focal,7016137,0,0,0,-1046.6,7464.5,0,0,0,0,0,0,0,0,13e-6,0,,
garbled,7016137,0,0,0,-1046.6,7464.5,x,0,0,0,0,0,0,0.555,13e-6,0,,
";

    #[test]
    fn one_row_per_input_row_with_typed_errors() {
        for backend in ["reference", "f64", "f32"] {
            let out = Out::of(&eval_csv(backend, CASES).unwrap());
            assert_eq!(out.rows(), 6);
            assert!(out
                .header()
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
        assert!(eval_csv("fixed", CASES)
            .unwrap_err()
            .to_string()
            .contains("no fixed-point"));
        assert!(eval_csv("f16", CASES).is_err());
    }

    /// The derived outputs follow the definition from v1 and v2, and the backends agree.
    #[test]
    fn derived_outputs_and_agreement() {
        let r = Out::of(&eval_csv("reference", CASES).unwrap());
        let f = Out::of(&eval_csv("f32", CASES).unwrap());
        for row in 0..3 {
            let (v1, v2) = (r.num(row, "v1_mps"), r.num(row, "v2_mps"));
            assert!((r.num(row, "v_mps") - v1.hypot(v2)).abs() <= 1e-16);
            let t = r.num(row, "line_period_s");
            assert!((t - 13e-6 / v1.abs()).abs() <= 1e-15 * t);
            assert!((r.num(row, "drift_rad") - (v2 / v1).atan()).abs() <= 1e-15);
            let d = (f.num(row, "v1_mps") - v1).hypot(f.num(row, "v2_mps") - v2);
            assert!(d / v1.hypot(v2) < 2e-6, "row {row}");
        }
    }
}
