//! Host tasks, run as `cargo xtask <command>`.
//!
//! Each command is one module; `main` only dispatches.

mod accuracy;
mod csv;
mod ellipsoid;
mod eval;
mod footprint;
mod no_panic;
mod paper;
mod plot;
mod report;
mod stability;
mod target;
mod test_cmd;

use std::process::ExitCode;

const USAGE: &str = "usage: cargo xtask <command>

commands:
  eval [--model sphere|earth] --backend <reference|f64|f32|fixed> --input CASES.csv
                                                         evaluate cases, CSV to stdout (earth: no fixed)
  accuracy [--quick] [--model sphere|earth]              f32/f64 error sweep against the reference
  paper                                                  regenerate docs/paper/ (Figs. 5-8)
  test                                                   every check CI runs
  run [--short] [--telemetry FILE.csv] [--debug]         a pass through the firmware under QEMU (docs/telemetry.md)
      [--plot PNG] [--every S] [--segments 0,5,9|all]
      [--export-telemetry FILE.csv] [--demo]             (--demo: the default-scene demo)
      [--board mps2-an386|stm32f405]                     (the board and its QEMU machine: docs/target.md)
  bench [--board mps2-an386|stm32f405]                   guest instructions per evaluation (QEMU plugin)
  size [--board mps2-an386|stm32f405]                    flash and static RAM of the flight binary, per board
  flash [--board stm32f405] [--bin firmware|demo]        a real board through probe-rs (docs/target.md)
        [--debug] [--print-command]
  report [--csv] [--cases N] [--seed S] [--no-bench]     error against run time per backend (runs the bench)
  stability [--quick]                                    regenerate docs/stability.md and its maps
  ellipsoid [--print]                                    round-Earth model error against WGS 84, cost of each
                                                         simplification against the real-Earth model
  qemu ELF                                               cargo runner: ELF under QEMU, defmt decoded
";

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(cmd) = args.first() else {
        eprint!("{USAGE}");
        return ExitCode::from(2);
    };
    let rest = &args[1..];
    let result = match cmd.as_str() {
        "eval" => eval::run(rest),
        "accuracy" => accuracy::run(rest),
        "paper" => paper::run(rest),
        "test" => test_cmd::run(rest),
        "run" => target::run(rest),
        "bench" => target::bench(rest),
        "size" => target::size(rest),
        "flash" => target::flash(rest),
        "report" => report::run(rest),
        "qemu" => target::qemu(rest),
        "stability" => stability::run(rest),
        "ellipsoid" => ellipsoid::run(rest),
        "help" | "--help" | "-h" => {
            print!("{USAGE}");
            Ok(())
        }
        other => Err(format!("unknown command `{other}`\n{USAGE}")),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("xtask: {e}");
            ExitCode::FAILURE
        }
    }
}
