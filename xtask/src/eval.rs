//! `cargo xtask eval [--model <sphere|earth>] --backend <...> --input CASES.csv`: a model
//! on user-supplied cases, CSV out, so the firmware's numbers can be checked on the
//! ground. `sphere` (the default) is the paper's round Earth; `earth` the real-Earth
//! model of `shared/EARTH-MODEL.md` (`eval/earth.rs`).

mod earth;

use anyhow::{bail, Context, Result};
use core_math::fixed_point::{geometry_from_f64, motion_to_f64};
use core_math::{
    line_period_s, Backend, Camera, Geometry, ModelError, Real, Reference, CLOSED_F32, CLOSED_F64,
    FIXED,
};

use crate::csv::{Table, Writer};

/// Input columns, in the order the model takes them.
pub const INPUT_COLUMNS: [&str; 8] = [
    "n_px",
    "phi_deg",
    "i0_deg",
    "gamma0_deg",
    "h_m",
    "f_m",
    "pixel_m",
    "r_m",
];
pub const OUTPUT_COLUMNS: [&str; 5] = ["v1_mps", "v2_mps", "v_mps", "line_period_s", "error"];

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
    /// The implementation to run (earth: no fixed)
    #[arg(long, value_parser = ["reference", "f64", "f32", "fixed"])]
    backend: String,
    /// The cases: a CSV file whose header names the model's input columns (`-`: stdin)
    #[arg(long, value_name = "CASES.csv")]
    input: String,
}

pub fn run(args: &Args) -> Result<()> {
    let (backend, input) = (&args.backend, &args.input);
    let text = if input == "-" {
        std::io::read_to_string(std::io::stdin()).context("reading stdin")?
    } else {
        std::fs::read_to_string(input).with_context(|| format!("reading {input}"))?
    };
    let out = match args.model {
        Model::Earth => earth::eval_csv(backend, &text)?,
        Model::Sphere => eval_csv(backend, &text)?,
    };
    print!("{out}");
    Ok(())
}

/// The whole command on a CSV text: one output row per input row, always.
pub fn eval_csv(backend: &str, text: &str) -> Result<String> {
    let table = Table::parse(text)?;
    let cols = table.columns(&INPUT_COLUMNS)?;
    write_rows(&table, &OUTPUT_COLUMNS, |row| {
        parse_case(row, &cols).and_then(|case| match backend {
            "reference" => evaluate(&Reference, &case, |g| g),
            "f64" => evaluate(&CLOSED_F64, &case, |g| g),
            "f32" => evaluate(&CLOSED_F32, &case, |g| g.to::<f32>()),
            "fixed" => evaluate_fixed(&case),
            other => Err(EvalError::Usage(format!(
                "unknown backend `{other}` (reference|f64|f32|fixed)"
            ))),
        })
    })
}

/// The output text: the input header and `outputs` (the last of which is `error`), then
/// each input row as given followed by its numbers and an empty error, or by empty
/// numbers and the error's name. Stops at the first usage error.
fn write_rows<const N: usize>(
    table: &Table,
    outputs: &[&str],
    mut eval_row: impl FnMut(&[String]) -> Result<[String; N], EvalError>,
) -> Result<String> {
    let header: Vec<&str> = table
        .header
        .iter()
        .map(String::as_str)
        .chain(outputs.iter().copied())
        .collect();
    let mut out = Writer::new("", &header)?;
    for row in &table.rows {
        let (nums, error) = match eval_row(row) {
            Ok(nums) => (nums, ""),
            Err(EvalError::Model(e)) => (std::array::from_fn(|_| String::new()), e.name()),
            Err(EvalError::Unparsable) => {
                (std::array::from_fn(|_| String::new()), "unparsable_input")
            }
            Err(EvalError::Usage(msg)) => bail!(msg),
        };
        let fields: Vec<&str> = row
            .iter()
            .chain(&nums)
            .map(String::as_str)
            .chain([error])
            .collect();
        out.row(&fields)?;
    }
    out.into_string()
}

enum EvalError {
    Model(ModelError),
    Unparsable,
    Usage(String),
}

impl From<ModelError> for EvalError {
    fn from(e: ModelError) -> Self {
        EvalError::Model(e)
    }
}

/// One case in SI units: optics, geometry (f64, to be rounded by the backend), pixel.
pub struct Case {
    pub camera: Camera,
    pub geometry: Geometry<f64>,
    pub n_px: f64,
}

fn parse_case(row: &[String], cols: &[usize]) -> Result<Case, EvalError> {
    let mut v = [0.0f64; 8];
    for (slot, &c) in v.iter_mut().zip(cols) {
        *slot = row
            .get(c)
            .and_then(|s| s.parse::<f64>().ok())
            .ok_or(EvalError::Unparsable)?;
    }
    let [n_px, phi_deg, i0_deg, gamma0_deg, h_m, f_m, pixel_m, r_m] = v;
    Ok(Case {
        camera: Camera {
            focal_m: f_m,
            pixel_m,
        },
        geometry: Geometry::circular(
            phi_deg.to_radians(),
            i0_deg.to_radians(),
            gamma0_deg.to_radians(),
            h_m,
            r_m,
        ),
        n_px,
    })
}

/// v1, v2, |v| and the line period, formatted in the backend's own precision
/// (shortest text that reads back to the same value).
fn evaluate<B: Backend>(
    backend: &B,
    case: &Case,
    to_real: impl Fn(Geometry<f64>) -> Geometry<B::Real>,
) -> Result<[String; 4], EvalError>
where
    B::Real: Real + std::fmt::Display,
{
    let m = backend.evaluate(&case.camera, &to_real(case.geometry), case.n_px)?;
    let speed = m.speed_mps();
    let period = line_period_s(B::Real::from_f64(case.camera.pixel_m), speed)?;
    Ok([
        m.v1_mps.to_string(),
        m.v2_mps.to_string(),
        speed.to_string(),
        period.to_string(),
    ])
}

/// The fixed-point backend: the geometry rounded to I24F40, the results widened to f64
/// (exact) and printed as f64; |v| and the line period in f64 from them.
fn evaluate_fixed(case: &Case) -> Result<[String; 4], EvalError> {
    let g = geometry_from_f64(&case.geometry)?;
    let m = motion_to_f64(&FIXED.evaluate(&case.camera, &g, case.n_px)?);
    let speed = m.speed_mps();
    let period = line_period_s(case.camera.pixel_m, speed)?;
    Ok([
        m.v1_mps.to_string(),
        m.v2_mps.to_string(),
        speed.to_string(),
        period.to_string(),
    ])
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

    /// An output (header and rows), read back by column name.
    pub(super) struct Out(Table);

    impl Out {
        pub(super) fn of(text: &str) -> Out {
            Out(Table::parse(text).unwrap())
        }

        pub(super) fn rows(&self) -> usize {
            self.0.rows.len()
        }

        /// Field `name` of row `row` (0: the first after the header).
        pub(super) fn field(&self, row: usize, name: &str) -> &str {
            &self.0.rows[row][self.0.columns(&[name]).unwrap()[0]]
        }

        pub(super) fn num(&self, row: usize, name: &str) -> f64 {
            self.field(row, name).parse().unwrap()
        }

        pub(super) fn header(&self) -> String {
            self.0.header.join(",")
        }
    }

    #[test]
    fn one_row_per_input_row_with_typed_errors() {
        for backend in ["reference", "f64", "f32", "fixed"] {
            let out = Out::of(&eval_csv(backend, CASES).unwrap());
            assert_eq!(out.rows(), 5);
            assert!(out
                .header()
                .ends_with("v1_mps,v2_mps,v_mps,line_period_s,error"));
            assert_eq!(out.field(0, "case"), "nadir", "extra columns are kept");
            assert_eq!(out.field(0, "error"), "");
            assert_eq!(out.field(2, "error"), "line_of_sight_misses_earth");
            assert_eq!(out.field(2, "v1_mps"), "");
            assert_eq!(out.field(3, "error"), "non_positive_focal_length");
            assert_eq!(out.field(4, "error"), "unparsable_input");
        }
        assert!(eval_csv("f16", CASES).is_err());
    }

    #[test]
    fn backends_agree_and_period_is_pixel_over_speed() {
        let r = Out::of(&eval_csv("reference", CASES).unwrap());
        let f = Out::of(&eval_csv("f32", CASES).unwrap());
        let x = Out::of(&eval_csv("fixed", CASES).unwrap());
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
}
