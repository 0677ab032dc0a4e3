//! The f32 (and f64) closed form against the f64 reference over a dense grid of the
//! envelope, bucketed by how far the line of sight is from the Earth's limb.

use core_math::{Backend, Camera, Geometry, Reference, CLOSED_F32, CLOSED_F64};

/// Unit roundoff of f32.
const U32: f64 = f32::EPSILON as f64 / 2.0;

/// Limb-margin buckets (deg): a case falls in the first bucket whose lower bound it meets.
const BUCKETS_DEG: [(f64, &str); 6] = [
    (1.0, ">= 1 deg"),
    (0.1, "0.1 - 1 deg"),
    (0.01, "0.01 - 0.1 deg"),
    (1e-3, "1e-3 - 0.01 deg"),
    (1e-4, "1e-4 - 1e-3 deg"),
    (0.0, "< 1e-4 deg"),
];

#[derive(Clone, Copy, Default)]
struct Stat {
    n: u64,
    max_speed: f64,
    max_v1: f64,
    max_v2_over_speed: f64,
    /// max of err * q^2 / u: the constant in err <= C u / q^2.
    max_c: f64,
    max_speed_f64: f64,
    errors: u64,
}

pub fn run(args: &[String]) -> Result<(), String> {
    let quick = args.iter().any(|a| a == "--quick");
    let stats = sweep(quick);
    print_table(&stats, quick);
    Ok(())
}

fn bucket(margin_deg: f64) -> usize {
    BUCKETS_DEG
        .iter()
        .position(|(lo, _)| margin_deg >= *lo)
        .unwrap_or(BUCKETS_DEG.len() - 1)
}

fn sweep(quick: bool) -> Vec<Stat> {
    let camera = Camera {
        focal_m: 0.555,
        pixel_m: 13e-6,
    };
    let mut stats = vec![Stat::default(); BUCKETS_DEG.len()];
    let alts_km: &[f64] = if quick {
        &[200.0, 645.0, 2000.0]
    } else {
        &[200.0, 400.0, 645.0, 1000.0, 1500.0, 2000.0]
    };
    let step = if quick { 4 } else { 1 };
    for &alt_km in alts_km {
        for i in (0..=180).step_by(15 * step) {
            for gq in (0..360).step_by(15 * step) {
                let g64 = Geometry::circular(
                    0.0,
                    (i as f64).to_radians(),
                    (gq as f64).to_radians(),
                    alt_km * 1e3,
                    6_371e3,
                );
                for roll_half_deg in (-90..=90).step_by(3 * step) {
                    let roll = (roll_half_deg as f64 * 0.5).to_radians();
                    let g = Geometry {
                        roll_rad: roll,
                        ..g64
                    };
                    // f32 inputs, and the reference at exactly those inputs.
                    let g32 = g.to::<f32>();
                    let gref = g32.to_f64();
                    let u32c = match CLOSED_F32.update(&g32) {
                        Ok(u) => u,
                        Err(_) => continue,
                    };
                    let u64c = CLOSED_F64.update(&gref).expect("valid");
                    let k = 1.0 + gref.altitude_m / gref.earth_radius_m;
                    let limb = libm::asin(1.0 / k);
                    // Field angles up to 40 deg, then extra points approaching the limb.
                    let mut fields: Vec<f64> = (-40..=40)
                        .step_by(step)
                        .map(|d| (d as f64).to_radians())
                        .collect();
                    for m in [3.0, 1.0, 0.3, 0.1, 0.03, 0.01, 3e-3, 1e-3, 3e-4, 1e-4, 1e-5] {
                        let m: f64 = m;
                        for side in [1.0, -1.0] {
                            let a = side * (limb - m.to_radians()) - gref.roll_rad;
                            if a.abs() <= 40f64.to_radians() {
                                fields.push(a);
                            }
                        }
                    }
                    for alpha in fields {
                        let n_px = libm::tan(alpha) * camera.focal_m / camera.pixel_m;
                        let eta =
                            gref.roll_rad + libm::atan(n_px * camera.pixel_m / camera.focal_m);
                        let margin_deg = (limb - eta.abs()).to_degrees();
                        if margin_deg <= 0.0 {
                            continue;
                        }
                        let Ok(r) = Reference.evaluate(&camera, &gref, n_px) else {
                            continue;
                        };
                        let b = bucket(margin_deg);
                        let s = &mut stats[b];
                        s.n += 1;
                        let p32 = CLOSED_F32.pixel(&camera, n_px).expect("pixel");
                        let p64 = CLOSED_F64.pixel(&camera, n_px).expect("pixel");
                        let (m32, m64) = match (
                            CLOSED_F32.motion(&u32c, &p32),
                            CLOSED_F64.motion(&u64c, &p64),
                        ) {
                            (Ok(a), Ok(b)) => (a, b),
                            _ => {
                                s.errors += 1;
                                continue;
                            }
                        };
                        let sp = r.speed_mps();
                        let e_sp = ((m32.speed_mps() as f64) - sp).abs() / sp;
                        let e_v1 = ((m32.v1_mps as f64) - r.v1_mps).abs() / r.v1_mps.abs();
                        let e_v2 = ((m32.v2_mps as f64) - r.v2_mps).abs() / sp;
                        let e64 = (m64.speed_mps() - sp).abs() / sp;
                        let s_eta = libm::sin(eta.abs());
                        let q2 = (1.0 - k * s_eta) * (1.0 + k * s_eta);
                        if b == 0 && e_sp > s.max_speed && std::env::var("ACC_DEBUG").is_ok() {
                            eprintln!("worst so far: e {e_sp:.2e} alt {alt_km} i {i} g {gq} roll {:.1} alpha {:.2} eta {:.3} margin {margin_deg:.3} q2 {q2:.4} v1 {:.4e} v2 {:.4e}", gref.roll_rad.to_degrees(), alpha.to_degrees(), eta.to_degrees(), r.v1_mps, r.v2_mps);
                        }
                        s.max_speed = s.max_speed.max(e_sp);
                        s.max_v1 = s.max_v1.max(e_v1);
                        s.max_v2_over_speed = s.max_v2_over_speed.max(e_v2);
                        s.max_c = s.max_c.max(e_sp.max(e_v1) * q2 / U32);
                        s.max_speed_f64 = s.max_speed_f64.max(e64);
                    }
                }
            }
        }
    }
    stats
}

fn print_table(stats: &[Stat], quick: bool) {
    println!(
        "# f32 closed form vs f64 reference ({} sweep)",
        if quick { "quick" } else { "full" }
    );
    println!();
    println!("| limb margin | cases | max rel err |v| | max rel err v1 | max err v2 / |v| | max err*q^2/u | f64 closed form max rel err |v| | refused |");
    println!("|---|---|---|---|---|---|---|---|");
    for ((_, name), s) in BUCKETS_DEG.iter().zip(stats) {
        println!(
            "| {name} | {} | {:.2e} | {:.2e} | {:.2e} | {:.2} | {:.2e} | {} |",
            s.n, s.max_speed, s.max_v1, s.max_v2_over_speed, s.max_c, s.max_speed_f64, s.errors
        );
    }
}
