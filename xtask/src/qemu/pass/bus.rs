//! The bus's frames of a built-in pass (protocol version 4): GNSS fixes in the ITRF,
//! star-tracker quaternions relative to the GCRF with gyro rates, and the Earth
//! orientation that relates them to the truth orbit, from ERFA (pyerfa's
//! `c2t06a`, IAU 2006/2000A), not from the firmware's IAU 2000B series.
//!
//! The truth orbit lives in I0, the ITRF frozen at the orbit's t = 0 (Part I's I then),
//! so x_GCRF = C2T(0)^T x_I0 and x_ITRF(t) = C2T(t) C2T(0)^T x_I0.

use anyhow::{anyhow, bail, Context, Result};
use controller::bus::{Gnss, StarAttitude};
use core_math::earth::dem::DemTile;
pub use core_math::earth::frames::mat_mul;
use core_math::earth::frames::{geodetic_from_itrf, Mat3, TimeScales};
use core_math::earth::EarthGeometry;
use core_math::EARTH_RATE_RAD_S;
use std::process::Command;

use super::scenario::AgileTruth;

/// The time scales the passes fly with (sent in TIME_SCALES at their start): the leap
/// seconds since 2017, and an assumed UT1 - UTC.
pub const SCALES: TimeScales = TimeScales {
    gps_utc_s: 18.0,
    dut1_s: 0.0625,
};
/// dERA/dt (rad/s of UT1): 2 pi 1.00273781191135448 per day.
pub const ERA_RATE_RAD_S: f64 = std::f64::consts::TAU * 1.002_737_811_911_354_5 / 86_400.0;
/// The camera's mounting on the body: turned 20 mrad about (0.3, 0.9, 0.1).
pub fn mounting_q() -> [f64; 4] {
    let (s, c) = 0.01f64.sin_cos();
    let n = (0.91f64).sqrt();
    [c, s * 0.3 / n, s * 0.9 / n, s * 0.1 / n]
}
/// One-sigma noise: GNSS position per axis (m) and velocity per axis (m/s), the star
/// tracker's attitude per axis (rad, 4 arcsec), the gyros' rates per axis (rad/s,
/// 0.01 deg/h).
pub const SIGMA_POSITION_M: f64 = 2.0;
pub const SIGMA_VELOCITY_MPS: f64 = 0.03;
pub const SIGMA_ATTITUDE_RAD: f64 = 2e-5;
pub const SIGMA_RATE_RAD_S: f64 = 5e-8;

/// C2T of IAU 2006/2000A (polar motion zero) from ERFA once a second over a pass, and
/// between: C2T(t) = R3(ERA(t) - ERA(t_k)) C2T(t_k) (the CIO-based C2I moves by about
/// 1e-11 rad in a second).
#[derive(Clone, Debug)]
pub struct EarthOrientation {
    /// GPS seconds of the grid's first point (whole).
    gps0_s: i64,
    grid: Vec<Mat3>,
}

impl EarthOrientation {
    /// From pyerfa at every whole GPS second of `gps0_s ..= gps0_s + seconds` (installs
    /// tools/goldens/requirements.txt when `erfa` does not import).
    pub fn new(gps0_s: i64, seconds: usize) -> Result<EarthOrientation> {
        let script = r#"
import sys, numpy as np, erfa
g0, n, leap, dut1 = int(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4])
ms = np.arange(g0, g0 + n + 1, dtype=np.int64) * 1000
def jd(ms, extra_s):
    d = np.floor_divide(ms, 86400000)
    return 2444244.5 + d, ((ms - d * 86400000) / 1000.0 + extra_s) / 86400.0
tt1, tt2 = jd(ms + 51184, 0.0)
ut1, ut2 = jd(ms - leap * 1000, dut1)
for m in erfa.c2t06a(tt1, tt2, ut1, ut2, 0.0, 0.0):
    print(" ".join(repr(float(x)) for x in m.ravel()))
"#;
        let run = || {
            Command::new("python3")
                .args(["-c", script])
                .args([
                    gps0_s.to_string(),
                    seconds.to_string(),
                    format!("{}", SCALES.gps_utc_s as i64),
                    format!("{:?}", SCALES.dut1_s),
                ])
                .output()
                .context("running python3 for ERFA's C2T")
        };
        let mut out = run()?;
        if String::from_utf8_lossy(&out.stderr).contains("No module named") {
            let req = super::super::workspace_root().join("tools/goldens/requirements.txt");
            Command::new("python3")
                .args(["-m", "pip", "install", "--quiet", "-r"])
                .arg(&req)
                .status()
                .with_context(|| format!("installing {}", req.display()))?;
            out = run()?;
        }
        if !out.status.success() {
            bail!("ERFA's C2T: {}", String::from_utf8_lossy(&out.stderr));
        }
        let grid = String::from_utf8_lossy(&out.stdout)
            .lines()
            .map(|l| {
                let v: Vec<f64> = l.split(' ').filter_map(|x| x.parse().ok()).collect();
                match v.as_slice() {
                    &[a, b, c, d, e, f, g, h, i] => Ok([[a, b, c], [d, e, f], [g, h, i]]),
                    _ => Err(anyhow!("ERFA's C2T: `{l}` is not a matrix")),
                }
            })
            .collect::<Result<Vec<_>>>()?;
        if grid.len() != seconds + 1 {
            bail!(
                "ERFA's C2T: {} matrices for {} seconds",
                grid.len(),
                seconds + 1
            );
        }
        Ok(EarthOrientation { gps0_s, grid })
    }

    /// C2T at `gps_s` (within the grid).
    pub fn c2t(&self, gps_s: f64) -> Mat3 {
        let dt = gps_s - self.gps0_s as f64;
        let k = (dt.floor().max(0.0) as usize).min(self.grid.len() - 1);
        let (s, c) = (ERA_RATE_RAD_S * (dt - k as f64)).sin_cos();
        let m = &self.grid[k];
        [
            std::array::from_fn(|j| c * m[0][j] + s * m[1][j]),
            std::array::from_fn(|j| c * m[1][j] - s * m[0][j]),
            m[2],
        ]
    }
}

pub fn mat_vec(m: &Mat3, x: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| m[i][0] * x[0] + m[i][1] * x[1] + m[i][2] * x[2])
}

pub fn transpose(a: &Mat3) -> Mat3 {
    std::array::from_fn(|i| std::array::from_fn(|j| a[j][i]))
}

pub fn q_mul(q: [f64; 4], e: [f64; 4]) -> [f64; 4] {
    [
        q[0] * e[0] - q[1] * e[1] - q[2] * e[2] - q[3] * e[3],
        q[0] * e[1] + q[1] * e[0] + q[2] * e[3] - q[3] * e[2],
        q[0] * e[2] - q[1] * e[3] + q[2] * e[0] + q[3] * e[1],
        q[0] * e[3] + q[1] * e[2] - q[2] * e[1] + q[3] * e[0],
    ]
}

/// Deterministic Gaussian noise (splitmix64, Box-Muller).
pub struct Noise(u64);

impl Noise {
    pub fn new(seed: u64) -> Noise {
        Noise(seed)
    }
    fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn gauss(&mut self, sigma: f64) -> f64 {
        let (u, v) = (self.uniform().max(1e-300), self.uniform());
        sigma * (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }
    pub fn vec3(&mut self, sigma: f64) -> [f64; 3] {
        [self.gauss(sigma), self.gauss(sigma), self.gauss(sigma)]
    }
}

impl AgileTruth {
    /// GPS seconds of pass time `t_s`.
    pub fn gps_s(&self, t_s: f64) -> f64 {
        self.epoch_us as f64 * 1e-6 + t_s
    }

    /// I0 to the ITRF at pass time `t_s`.
    pub fn i0_to_itrf(&self, t_s: f64) -> Mat3 {
        mat_mul(&self.earth.c2t(self.gps_s(t_s)), &transpose(&self.c2t0))
    }

    /// The GNSS fix at pass time `t_s`, exact, then with `noise`.
    pub fn gnss(&self, t_s: f64, noise: Option<&mut Noise>) -> Gnss {
        let s = self.orbit.state(t_s);
        let m = self.i0_to_itrf(t_s);
        let r = mat_vec(&m, s.position_m);
        let v = mat_vec(&m, s.velocity_mps);
        // Relative to the ITRF: minus w x r, w the Earth's rotation along the CIP.
        let w = ERA_RATE_RAD_S;
        let mut g = Gnss {
            fix_us: self.epoch_us + super::scenario::us(t_s),
            position_m: r,
            velocity_mps: [v[0] + w * r[1], v[1] - w * r[0], v[2]],
        };
        if let Some(n) = noise {
            let (dr, dv) = (n.vec3(SIGMA_POSITION_M), n.vec3(SIGMA_VELOCITY_MPS));
            g.position_m = std::array::from_fn(|i| r[i] + dr[i]);
            g.velocity_mps = std::array::from_fn(|i| g.velocity_mps[i] + dv[i]);
        }
        g
    }

    /// The camera's axes in I0 and its angular velocity (camera axes, rad/s) at `t_s`.
    pub fn camera(&self, t_s: f64) -> Result<(Mat3, [f64; 3])> {
        let g = EarthGeometry {
            state: self.orbit.state(t_s),
            attitude: self.attitude(t_s),
            ground_h_m: 0.0,
            ellipsoid: controller::EARTH,
            earth_rate_rad_s: EARTH_RATE_RAD_S,
        }
        .to_inertial()
        .map_err(|e| anyhow!("the truth's attitude at {t_s} s: {}", e.name()))?;
        Ok((g.attitude.camera_to_inertial, g.attitude.omega_rad_s))
    }

    /// The star tracker's quaternion and the gyros' rates at pass time `t_s`, exact,
    /// then with `noise`.
    pub fn star(&self, t_s: f64, noise: Option<&mut Noise>) -> Result<StarAttitude> {
        let (b, omega) = self.camera(t_s)?;
        let cam = quaternion_matrix(mounting_q())?;
        // x_GCRF = C2T(0)^T B R(cam)^T x_body.
        let body = mat_mul(&mat_mul(&transpose(&self.c2t0), &b), &transpose(&cam));
        let mut q = core_math::earth::bus::matrix_quaternion(&body);
        let mut w = mat_vec(&cam, omega);
        if let Some(n) = noise {
            let e = n.vec3(SIGMA_ATTITUDE_RAD);
            q = q_mul(q, [1.0, e[0] / 2.0, e[1] / 2.0, e[2] / 2.0]);
            let dw = n.vec3(SIGMA_RATE_RAD_S);
            w = std::array::from_fn(|i| w[i] + dw[i]);
        }
        let norm = q.iter().map(|x| x * x).sum::<f64>().sqrt();
        Ok(StarAttitude {
            valid_us: self.epoch_us + super::scenario::us(t_s),
            q: q.map(|x| (x / norm) as f32),
            body_rate_rad_s: w.map(|x| x as f32),
        })
    }
}

impl AgileTruth {
    /// The ground height under each segment's centre at `t_s`: the DEM's where its line
    /// of sight meets the tile, the terrain profile's elsewhere (m).
    pub fn ground_m(&self, t_s: f64, tile: Option<&DemTile<'_, i16>>) -> Result<Vec<f32>> {
        let mut heights = self.heights_m(t_s);
        let Some(tile) = tile else {
            return Ok(heights);
        };
        let scene = super::scenario::pass_scene(true);
        let m = self.i0_to_itrf(t_s);
        let (b, _) = self.camera(t_s)?;
        let r = mat_vec(&m, self.orbit.state(t_s).position_m);
        for (h, spec) in heights.iter_mut().zip(&scene.segments) {
            let Ok((p1, p2)) = scene.earth_camera(spec).focal_plane_m(spec.centre_px()) else {
                continue;
            };
            let d = mat_vec(&m, mat_vec(&b, [p1, p2, -scene.camera.focal_m]));
            let Ok(s) = tile.first_crossing(&controller::EARTH, r, d) else {
                continue;
            };
            let x: [f64; 3] = std::array::from_fn(|i| r[i] + s * d[i]);
            if let Ok((_, _, h_m)) = geodetic_from_itrf(x, &controller::EARTH) {
                *h = h_m as f32;
            }
        }
        Ok(heights)
    }
}

pub fn quaternion_matrix(q: [f64; 4]) -> Result<Mat3> {
    core_math::earth::bus::quaternion_matrix(q, core_math::Param::Quaternion)
        .map_err(|e| anyhow!("quaternion: {}", e.name()))
}
