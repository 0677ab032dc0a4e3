//! What each simplification of the paper's model costs in the line period: the truth is
//! `core_math::EarthReference` (the definition of `shared/EARTH-MODEL.md` on dual
//! numbers, the golden source, itself checked against an independent numerical model by
//! core-math's test `two_routes`), the simplified model either the paper's round Earth
//! (`core_math::sphere::Reference` on a `core_math::sphere::Geometry` from the state vector, as the
//! firmware does today) or the truth with one input dropped. One simplification at a
//! time, at the default scene over one orbit and over a seeded sample of the envelope.
//!
//! The error is that of the line period, T_model / T_truth - 1, T = pixel / |v1| (the
//! contract's period) for both, except for Eq. 16, where T_model = pixel / |v_P| of the
//! truth's own motion: > 0 when the simplified model clocks too slowly.

use core_math::earth::kepler::Kepler;
use core_math::earth::{limb_margin_rad, Attitude};
use core_math::sample::{eccentric_state, EarthCase, SplitMix64};
use core_math::sphere::Reference;
use core_math::vector::{dot, norm, scale};
use core_math::{
    Backend, Camera, EarthCamera, EarthGeometry, EarthReference, Ellipsoid, ImageMotion,
    StateVector, EARTH_RATE_RAD_S, GM_M3_S2,
};

use crate::markdown::signed;

use super::{orbit_state, round_geometry, ALTITUDE_M, INCLINATION_DEG, RAAN_RAD, R_PAPER_M};

const FOCAL_M: f64 = 0.555;
const PIXEL_M: f64 = 13e-6;
/// Terrain height of row (b) (m), eccentricity of row (c), stereo pitches of row (d).
const TERRAIN_M: f64 = 9_000.0;
const ECCENTRICITY: f64 = 0.05;
const PITCHES_DEG: [f64; 2] = [20.0, 45.0];
/// Cases within this of the limb (rad) are skipped: there the period is as
/// ill-conditioned as the ray is close to tangent, and no simplification is the issue.
const LIMB_BAND_RAD: f64 = 0.5 * std::f64::consts::PI / 180.0;
const ENVELOPE_SEED: u64 = 0x11_C057;

/// The default scene's grid: argument of latitude, roll, pixel.
#[derive(Clone, Copy, Debug)]
pub struct Grid {
    pub u_step_deg: f64,
    pub roll_step_deg: f64,
    pub n_step_px: f64,
    pub envelope_draws: usize,
}

impl Grid {
    /// `cargo xtask ellipsoid`: 1 deg of orbit, 5 deg of roll (-25 to 25), every 5000th
    /// pixel from -30 000 to +30 000, 20 000 envelope draws.
    pub const FULL: Grid = Grid {
        u_step_deg: 1.0,
        roll_step_deg: 5.0,
        n_step_px: 5_000.0,
        envelope_draws: 20_000,
    };
}

/// Worst and RMS of a row's error, with where the worst is.
pub type Stat = super::Stat<String>;

/// One row of the table.
#[derive(Clone, Debug)]
pub struct Row {
    pub label: &'static str,
    pub truth: &'static str,
    pub model: &'static str,
    pub default: Option<Stat>,
    pub envelope: Option<Stat>,
    /// What the envelope column covers for this row.
    pub envelope_note: &'static str,
}

#[derive(Clone, Debug)]
pub struct Costs {
    pub rows: Vec<Row>,
    pub grid: Grid,
    pub default_cases: usize,
}

fn wgs(state: StateVector, attitude: Attitude<f64>, ground_h_m: f64) -> EarthGeometry<f64> {
    EarthGeometry {
        state,
        attitude,
        ground_h_m,
        ellipsoid: Ellipsoid::WGS84,
        earth_rate_rad_s: EARTH_RATE_RAD_S,
    }
}

fn roll_only(roll_rad: f64) -> Attitude<f64> {
    Attitude {
        roll_rad,
        ..Attitude::default()
    }
}

/// The truth's image motion; None for a miss or a ray within 0.5 deg of the limb.
fn truth(g: &EarthGeometry<f64>, cam: &EarthCamera, n: f64) -> Option<ImageMotion<f64>> {
    let margin = limb_margin_rad(g, cam, n).ok()?;
    if margin < LIMB_BAND_RAD || margin.is_nan() {
        return None;
    }
    EarthReference.evaluate(cam, g, n).ok()
}

/// The paper's round Earth fed the state vector as the firmware does
/// (`OrbitState::from_state`, R = 6371 km, H = |r| - R), the camera rolled; None for a
/// miss or a ray within 0.5 deg of its limb.
fn paper(
    state: &StateVector,
    roll_rad: f64,
    cam: &EarthCamera,
    n: f64,
) -> Option<ImageMotion<f64>> {
    let g = round_geometry(state, roll_rad, R_PAPER_M).ok()?;
    let camera = Camera {
        focal_m: cam.focal_m,
        pixel_m: cam.pixel_m,
    };
    // Nadir angle |roll + alpha| against the limb asin(R / (R + H)).
    let alpha = (n * cam.pixel_m / cam.focal_m).atan();
    let limb = (R_PAPER_M / (R_PAPER_M + g.altitude_m)).asin();
    let margin = limb - (roll_rad + alpha).abs();
    if margin < LIMB_BAND_RAD || margin.is_nan() {
        return None;
    }
    Reference.evaluate(&camera, &g, n).ok()
}

/// T_model / T_truth - 1 with T = pixel / |v1|.
fn period_err(truth: &ImageMotion<f64>, model: &ImageMotion<f64>) -> f64 {
    truth.v1_mps.abs() / model.v1_mps.abs() - 1.0
}

/// The period error of a simplification that drops what `drop` changes: the truth at
/// `g` against the truth at `g` so changed.
fn dropped(
    g: &EarthGeometry<f64>,
    cam: &EarthCamera,
    n: f64,
    drop: impl FnOnce(&mut EarthGeometry<f64>),
) -> Option<f64> {
    let t = truth(g, cam, n)?;
    let mut m = *g;
    drop(&mut m);
    Some(period_err(&t, &truth(&m, cam, n)?))
}

/// How a row compares the model's motion with the truth's.
type ErrFn = fn(&ImageMotion<f64>, &ImageMotion<f64>) -> f64;

/// T_model / T_truth - 1 with Eq. 16's period T = pixel / |v_P|.
fn speed_err(truth: &ImageMotion<f64>, model: &ImageMotion<f64>) -> f64 {
    truth.speed_mps() / model.speed_mps() - 1.0
}

/// Eq. 16's period pixel / |v_P| against the contract's pixel / |v1|, same motion.
fn eq16_err(m: &ImageMotion<f64>) -> f64 {
    m.v1_mps.abs() / m.speed_mps() - 1.0
}

/// The yaw that steers the centre pixel's drift away: v2 = 0 on the boresight, where a
/// yaw turns the image motion by -yaw (a rotation about the boresight).
fn steering_yaw(g: &EarthGeometry<f64>, cam: &EarthCamera) -> Option<f64> {
    let m = EarthReference
        .evaluate(&EarthCamera { p1_m: 0.0, ..*cam }, g, 0.0)
        .ok()?;
    Some((m.v2_mps / m.v1_mps).atan())
}

/// The state vector with the same position and the circular velocity in the same
/// direction of flight (sqrt(GM / |r|), the radial part removed).
fn circularise(s: &StateVector) -> StateVector {
    let (r, v) = (s.position_m, s.velocity_mps);
    let rn = norm(r);
    let vr = dot(r, v) / rn;
    let t: [f64; 3] = std::array::from_fn(|k| v[k] - vr * r[k] / rn);
    let k = (GM_M3_S2 / rn).sqrt() / norm(t);
    StateVector {
        position_m: r,
        velocity_mps: scale(k, t),
    }
}

fn lat_deg(s: &StateVector) -> f64 {
    (s.position_m[2] / norm(s.position_m)).asin().to_degrees()
}

/// One default-scene case: the orbit's argument of latitude, the roll and the pixel.
#[derive(Clone, Copy, Debug)]
struct Case {
    u_rad: f64,
    roll_rad: f64,
    n: f64,
}

impl Case {
    fn at(&self, state: &StateVector) -> String {
        format!(
            "u {:.0}, lat {:+.1}, roll {:+.0}, n {:+.0}",
            self.u_rad.to_degrees(),
            lat_deg(state),
            self.roll_rad.to_degrees(),
            self.n
        )
    }
}

fn default_cases(grid: &Grid) -> Vec<Case> {
    let mut out = Vec::new();
    let steps = |lo: f64, hi: f64, step: f64| {
        let k = ((hi - lo) / step).round() as usize;
        (0..=k).map(move |i| lo + step * i as f64)
    };
    for u in steps(0.0, 360.0 - grid.u_step_deg, grid.u_step_deg) {
        for roll in steps(-25.0, 25.0, grid.roll_step_deg) {
            for n in steps(-30_000.0, 30_000.0, grid.n_step_px) {
                out.push(Case {
                    u_rad: u.to_radians(),
                    roll_rad: roll.to_radians(),
                    n,
                });
            }
        }
    }
    out
}

/// The default scene: one error per case (None: skipped).
fn over_default(
    cases: &[Case],
    f: impl Fn(&Case, &StateVector) -> Option<f64>,
    state: impl Fn(&Case) -> StateVector,
) -> Stat {
    let mut st = Stat::default();
    for c in cases {
        let s = state(c);
        match f(c, &s) {
            Some(e) => st.push(e, || c.at(&s)),
            None => st.skipped += 1,
        }
    }
    st
}

/// The envelope: `draws` seeded draws (`SplitMix64::envelope_case`), each adjusted by the
/// row and then measured (None: skipped).
fn over_envelope(
    draws: usize,
    f: impl Fn(&mut EarthGeometry<f64>, &mut EarthCamera, f64) -> Option<f64>,
) -> Stat {
    let mut rng = SplitMix64(ENVELOPE_SEED);
    let mut st = Stat::default();
    for _ in 0..draws {
        let EarthCase {
            camera: mut cam,
            geometry: mut g,
            n_px: n,
        } = rng.envelope_case();
        match f(&mut g, &mut cam, n) {
            Some(e) => st.push(e, || envelope_at(&g, &cam, n)),
            None => st.skipped += 1,
        }
    }
    st
}

fn envelope_at(g: &EarthGeometry<f64>, cam: &EarthCamera, n: f64) -> String {
    let s = &g.state;
    let lat = lat_deg(s);
    let alt = norm(s.position_m) - Ellipsoid::WGS84.geocentric_radius_m(lat.to_radians());
    let e =
        Kepler::new(s.position_m, s.velocity_mps, GM_M3_S2).map_or(f64::NAN, |k| k.eccentricity());
    let a = &g.attitude;
    let d = f64::to_degrees;
    let mut o = format!(
        "alt {:.0} km, e {e:.3}, lat {lat:+.1}, roll {:+.1}, pitch {:+.1}, yaw {:+.1}",
        alt / 1e3,
        d(a.roll_rad),
        d(a.pitch_rad),
        d(a.yaw_rad),
    );
    let rates = [a.roll_rate_rad_s, a.pitch_rate_rad_s, a.yaw_rate_rad_s];
    if rates.iter().any(|&x| x != 0.0) {
        o += &format!(
            ", rates {:+.2} {:+.2} {:+.2} deg/s",
            d(rates[0]),
            d(rates[1]),
            d(rates[2])
        );
    }
    o += &format!(
        ", field {:+.1}, h {:.0} m, margin {:.1}",
        d((n * cam.pixel_m / cam.focal_m).atan()),
        g.ground_h_m,
        limb_margin_rad(g, cam, n).map_or(f64::NAN, d),
    );
    o
}

/// The attitude held still: the rates 0 (with rates the along-track motion v1 can
/// vanish, and then every relative error of the period is unbounded; row (f)).
fn still(g: &mut EarthGeometry<f64>) {
    g.attitude.roll_rate_rad_s = 0.0;
    g.attitude.pitch_rate_rad_s = 0.0;
    g.attitude.yaw_rate_rad_s = 0.0;
}

/// The paper's error of the line period at the truth's geometry `g`: its round Earth
/// from the same state vector and roll against the truth, compared by `err`.
fn vs_paper(g: &EarthGeometry<f64>, cam: &EarthCamera, n: f64, err: ErrFn) -> Option<f64> {
    let t = truth(g, cam, n)?;
    Some(err(&t, &paper(&g.state, g.attitude.roll_rad, cam, n)?))
}

/// Attitude, camera and ground of the paper: roll only, the detector line through the
/// optical axis, ground height 0.
fn paper_case(g: &mut EarthGeometry<f64>, cam: &mut EarthCamera) {
    g.attitude = roll_only(g.attitude.roll_rad);
    g.ground_h_m = 0.0;
    cam.p1_m = 0.0;
}

/// A row's measure over the default scene's cases, at the case and its state vector.
type OnCase<'a> = &'a dyn Fn(&Case, &StateVector) -> Option<f64>;
/// A row's measure over the envelope's draws, each adjusted by the row first.
type OnDraw<'a> = &'a dyn Fn(&mut EarthGeometry<f64>, &mut EarthCamera, f64) -> Option<f64>;

pub fn costs(grid: Grid) -> Costs {
    let cam = EarthCamera {
        focal_m: FOCAL_M,
        pixel_m: PIXEL_M,
        p1_m: 0.0,
    };
    let cases = default_cases(&grid);
    // A row's two columns: the default scene on the orbit `state` gives, the envelope.
    let default = |state: fn(&Case) -> StateVector, f: OnCase| Some(over_default(&cases, f, state));
    let envelope = |f: OnDraw| Some(over_envelope(grid.envelope_draws, f));
    let circ: fn(&Case) -> StateVector = |c| orbit_state(c.u_rad);
    // The truth of the default scene: WGS 84, the roll alone.
    let wgs_roll = |c: &Case, s: &StateVector| wgs(*s, roll_only(c.roll_rad), 0.0);
    let mut rows = Vec::new();

    // (a) The ellipsoid against the round Earth.
    rows.push(Row {
        label: "(a) WGS 84 -> sphere R = 6371 km, H = |r| - R",
        truth: "WGS 84, h = 0, circular orbit, roll only",
        model: "paper's round Earth from the state vector (`Reference`)",
        default: default(circ, &|c, s| {
            vs_paper(&wgs_roll(c, s), &cam, c.n, period_err)
        }),
        envelope: envelope(&|g, cam, n| {
            paper_case(g, cam);
            g.state = circularise(&g.state);
            vs_paper(g, cam, n, period_err)
        }),
        envelope_note: "circular, roll only, p1 = 0, h = 0",
    });

    // (b) Terrain.
    rows.push(Row {
        label: "(b) terrain 9 km -> ground height 0",
        truth: "WGS 84, h = 9 km",
        model: "the same with h = 0",
        default: default(circ, &|c, s| {
            let g = wgs(*s, roll_only(c.roll_rad), TERRAIN_M);
            dropped(&g, &cam, c.n, |m| m.ground_h_m = 0.0)
        }),
        envelope: envelope(&|g, cam, n| {
            still(g);
            g.attitude.yaw_rad = 0.0;
            g.ground_h_m = TERRAIN_M;
            dropped(g, cam, n, |m| m.ground_h_m = 0.0)
        }),
        envelope_note: "rates 0, yaw 0, h = 9 km, the rest of the envelope",
    });

    // (c) Eccentricity: truth on the paper's sphere, so that only the orbit differs.
    let sphere = Ellipsoid {
        a_m: R_PAPER_M,
        flattening: 0.0,
    };
    let ecc: fn(&Case) -> StateVector = |c| {
        eccentric_state(
            R_PAPER_M + ALTITUDE_M,
            ECCENTRICITY,
            c.u_rad,
            INCLINATION_DEG.to_radians(),
            RAAN_RAD,
            c.u_rad,
        )
    };
    let variants: [(&str, &str, &str, &str, ErrFn); 2] = [
        (
            "(c) e = 0.05 -> the circular model of the same instant",
            "sphere R = 6371 km, e = 0.05 (645 km at the instant, perigee at the node), roll only",
            "paper's round Earth from the state vector (`OrbitState::from_state`)",
            "sphere, roll only, p1 = 0, h = 0, e 0-0.05 as drawn",
            period_err,
        ),
        (
            "(c) the same, in the Eq. 16 period pixel / |v_P| of both",
            "as above",
            "as above",
            "as above",
            speed_err,
        ),
    ];
    for (label, truth_text, model_text, envelope_note, err) in variants {
        rows.push(Row {
            label,
            truth: truth_text,
            model: model_text,
            default: default(ecc, &|c, s| {
                let g = wgs_roll(c, s);
                vs_paper(
                    &EarthGeometry {
                        ellipsoid: sphere,
                        ..g
                    },
                    &cam,
                    c.n,
                    err,
                )
            }),
            envelope: envelope(&|g, cam, n| {
                paper_case(g, cam);
                g.ellipsoid = sphere;
                vs_paper(g, cam, n, err)
            }),
            envelope_note,
        });
    }

    // (d) Pitch and yaw ignored.
    for (k, &pitch_deg) in PITCHES_DEG.iter().enumerate() {
        let pitch = pitch_deg.to_radians();
        rows.push(Row {
            label: [
                "(d) stereo pitch 20 deg -> pitch 0",
                "(d) stereo pitch 45 deg -> pitch 0",
            ][k],
            truth: [
                "WGS 84, roll and pitch 20 deg",
                "WGS 84, roll and pitch 45 deg",
            ][k],
            model: "the same with pitch 0",
            default: default(circ, &|c, s| {
                let mut g = wgs_roll(c, s);
                g.attitude.pitch_rad = pitch;
                dropped(&g, &cam, c.n, |m| m.attitude.pitch_rad = 0.0)
            }),
            envelope: (k == 0).then(|| {
                over_envelope(grid.envelope_draws, |g, cam, n| {
                    still(g);
                    g.attitude.yaw_rad = 0.0;
                    dropped(g, cam, n, |m| m.attitude.pitch_rad = 0.0)
                })
            }),
            envelope_note:
                "rates 0, yaw 0, pitch within +-45 deg as drawn, the rest of the envelope",
        });
    }
    rows.push(Row {
        label: "(d) steering yaw -> yaw 0",
        truth: "WGS 84, roll, yaw steered (v2 = 0 on the boresight)",
        model: "the same with yaw 0",
        default: default(circ, &|c, s| {
            let mut g = wgs_roll(c, s);
            g.attitude.yaw_rad = steering_yaw(&g, &cam)?;
            dropped(&g, &cam, c.n, |m| m.attitude.yaw_rad = 0.0)
        }),
        envelope: envelope(&|g, cam, n| {
            still(g);
            g.attitude.yaw_rad /= 18.0;
            dropped(g, cam, n, |m| m.attitude.yaw_rad = 0.0)
        }),
        envelope_note: "rates 0, yaw within +-10 deg (at any yaw unbounded: v1 -> 0 as the \
                        yaw nears 90 deg), the rest of the envelope",
    });

    // (e) Eq. 16 against the contract's period, the yaw unsteered and steered.
    let eq16 = [
        (
            "(e) pixel / |v_P| (Eq. 16) -> pixel / |v1|, yaw unsteered",
            "WGS 84, roll, yaw 0: pixel / |v1|",
            "rates 0, yaw 0, the rest of the envelope",
            false,
        ),
        (
            "(e) pixel / |v_P| (Eq. 16) -> pixel / |v1|, yaw steered",
            "WGS 84, roll, steering yaw: pixel / |v1|",
            "rates 0, the steering yaw, the rest of the envelope",
            true,
        ),
    ];
    for (label, truth_text, envelope_note, steered) in eq16 {
        // The truth at `g` with yaw 0 (or the steering yaw), in both periods.
        let err = |g: &mut EarthGeometry<f64>, cam: &EarthCamera, n: f64| {
            if steered {
                g.attitude.yaw_rad = steering_yaw(g, cam)?;
            }
            Some(eq16_err(&truth(g, cam, n)?))
        };
        rows.push(Row {
            label,
            truth: truth_text,
            model: "the same motion: pixel / |v_P|",
            default: default(circ, &|c, s| err(&mut wgs_roll(c, s), &cam, c.n)),
            envelope: envelope(&|g, cam, n| {
                still(g);
                g.attitude.yaw_rad = 0.0;
                err(g, cam, n)
            }),
            envelope_note,
        });
    }

    // Angle rates ignored (the paper has none): the envelope only.
    rows.push(Row {
        label: "(f) angle rates (+-2 deg/s) -> 0",
        truth: "WGS 84, the attitude with its rates",
        model: "the same with the rates 0",
        default: None,
        envelope: envelope(&|g, cam, n| dropped(g, cam, n, still)),
        envelope_note: "the whole envelope (unbounded where the rates cancel v1)",
    });

    Costs {
        rows,
        grid,
        default_cases: cases.len(),
    }
}

/// The markdown block between `begin` and `end`.
pub fn render(c: &Costs, begin: &str, end: &str, cmd: &str) -> String {
    let g = &c.grid;
    let mut o = format!(
        "{begin}\n\nEvery figure in this block is printed by {cmd}. Error = T_model / T_truth - 1 \
         of the line period, T = pixel / |v1| (the contract's) for both, except in the two \
         Eq. 16 rows (T_model = pixel / |v_P| of the truth's own motion): > 0 when the \
         simplified model clocks too slowly. Truth: `core_math::EarthReference`. One \
         simplification per row, everything else as the truth. Default scene: circular \
         orbit of radius 6371 + 645 km, i0 = {INCLINATION_DEG} deg, f = {FOCAL_M} m, pixel \
         {:.0} um, {} cases (argument of latitude u = 0-359 deg in {} deg steps, roll -25 to \
         +25 deg in {} deg steps, n = -30000 to +30000 in steps of {}). Envelope: {} seeded \
         draws (`SplitMix64::envelope_case`: altitude 200-2000 km, e 0-0.05, any inclination, \
         roll and pitch +-45 deg, any yaw, rates +-2 deg/s, h -500 to 9000 m, field +-40 \
         deg, p1 +-0.05 m), adjusted as the row says. Cases that miss the Earth or lie \
         within 0.5 deg of the limb (truth or simplified model) are skipped and counted. \
         Where: u, latitude (geocentric, of the satellite), roll in deg and the pixel; \
         in the envelope the altitude above the ellipsoid, eccentricity, angles in deg, \
         field angle, ground height and limb margin.\n\n\
         | simplification | truth | simplified model | default scene: worst | where | RMS | \
         skipped | envelope: worst | where (envelope: what is drawn) | skipped | command |\n\
         |---|---|---|---|---|---|---|---|---|---|---|\n",
        PIXEL_M * 1e6,
        c.default_cases,
        g.u_step_deg,
        g.roll_step_deg,
        g.n_step_px,
        g.envelope_draws,
    );
    for r in &c.rows {
        let (dw, dat, drms, dsk) = match &r.default {
            Some(s) => (
                signed(s.worst),
                s.at.clone(),
                format!("{:.2e}", s.rms()),
                s.skipped.to_string(),
            ),
            None => (
                "n/a".into(),
                "no rates in the default scene".into(),
                "".into(),
                "".into(),
            ),
        };
        let (ew, eat, esk) = match &r.envelope {
            Some(s) => (
                signed(s.worst),
                format!("{} ({})", s.at, r.envelope_note),
                s.skipped.to_string(),
            ),
            None => ("".into(), "as the row above".into(), "".into()),
        };
        // A bar inside a cell would end it.
        let cell = |x: &str| x.replace('|', "\\|");
        o += &format!(
            "| {} | {} | {} | {dw} | {dat} | {drms} | {dsk} | {ew} | {} | {esk} | {cmd} |\n",
            cell(r.label),
            cell(r.truth),
            cell(r.model),
            cell(&eat),
        );
    }
    o += &format!(
        "\nThe truth's check against an independent numerical model (Kepler propagation \
         and a finite difference), on these default-scene cases among others: \
         `cargo test -p core-math --test two_routes -- --nocapture`.\n\n{end}"
    );
    o
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A coarse grid of the table: every row measured, the signs and sizes of what
    /// each simplification does as the physics says.
    #[test]
    fn costs_are_plausible() {
        let c = costs(Grid {
            u_step_deg: 30.0,
            roll_step_deg: 25.0,
            n_step_px: 30_000.0,
            envelope_draws: 400,
        });
        let row = |p: &str| c.rows.iter().find(|r| r.label.starts_with(p)).unwrap();
        let d = |p: &str| row(p).default.clone().unwrap();
        // (a) a few per cent (docs/earth-model.md, the round Earth's error).
        assert!((0.01..0.06).contains(&d("(a)").worst.abs()));
        // (b) 9 km of terrain: the range shrinks by at least 9/645 at nadir, the
        // image is faster, the model's period too long.
        assert!(d("(b)").worst > 0.013 && d("(b)").worst < 0.05);
        // (c) roll only and p1 = 0: the radial velocity moves the image along P2 and
        // scales it about the principal point, so v1 (P1 = 0) is untouched and only
        // |v_P| sees it.
        assert!(d("(c) e").worst.abs() < 1e-12);
        assert!(d("(c) the same").worst.abs() > 1e-4);
        // (e) Eq. 16's period is shorter: cos(drift) - 1 < 0; steered, near 0.
        assert!(d("(e) pixel / |v_P| (Eq. 16) -> pixel / |v1|, yaw unsteered").worst < -1e-4);
        let steered = d("(e) pixel / |v_P| (Eq. 16) -> pixel / |v1|, yaw steered");
        assert!(
            steered.worst.abs()
                < d("(e) pixel / |v_P| (Eq. 16) -> pixel / |v1|, yaw unsteered")
                    .worst
                    .abs()
        );
        let block = render(&c, "<b>", "<e>", "`x`");
        assert!(block.starts_with("<b>") && block.ends_with("<e>"));
        assert_eq!(block.matches("\n| (").count(), c.rows.len());
    }
}
