//! Host tasks, run as `cargo xtask <command>`.
//!
//! Each command is one module. A command with options declares them as a clap `Args`
//! struct next to its `run` (one field per option, its doc comment the `--help` text);
//! `main` only parses and dispatches. A new option is a new field there.
//!
//! The firmware flies core-math's real-Earth general form (`GENERAL_F32`; on the
//! Cortex-M3, `EARTH_FIXED`'s fixed-point pixels). `eval` and `accuracy` take it with
//! `--model earth` (their default, `sphere`, is the paper's round Earth); `stability`
//! maps both; `ellipsoid` measures the round Earth against it. Start reading at the
//! command you run: `cargo xtask run` is `qemu::run` (`qemu/pass.rs`), `cargo xtask
//! test` is `test_cmd::run`.

mod accuracy;
mod csv;
mod ellipsoid;
mod eval;
mod footprint;
mod markdown;
mod no_panic;
mod paper;
mod plot;
mod qemu;
mod report;
mod stability;
mod test_cmd;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Host tasks of the TDI line-rate controller: evaluation, sweeps, figures, the
/// firmware under QEMU, and every check CI runs.
#[derive(Parser)]
#[command(bin_name = "cargo xtask", arg_required_else_help = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Evaluate a model on cases from a CSV file; CSV to stdout
    Eval(eval::Args),
    /// f32/f64 error sweep against the reference (docs/accuracy.md)
    Accuracy(accuracy::Args),
    /// Regenerate docs/paper/ (Figs. 5-8; docs/paper-reproduction.md)
    Paper(paper::Args),
    /// Every check CI runs
    Test,
    /// A pass through the firmware under QEMU (docs/telemetry.md), or the demo
    Run(qemu::RunArgs),
    /// Guest instructions per evaluation, from a QEMU plugin (docs/bench.md)
    Bench(qemu::BenchArgs),
    /// Flash and static RAM of the release flight binary, per board (docs/target.md)
    Size(qemu::SizeArgs),
    /// The firmware on a real board through probe-rs (docs/target.md)
    Flash(qemu::FlashArgs),
    /// Error against run time per backend; runs the bench (docs/error-vs-runtime.md)
    Report(report::Args),
    /// Regenerate docs/stability.md and its maps
    Stability(stability::Args),
    /// Round-Earth model error against WGS 84, cost of each simplification (docs/earth-model.md)
    Ellipsoid(ellipsoid::Args),
    /// Cargo runner for thumbv7em-none-eabihf: an ELF under QEMU, its defmt log decoded
    Qemu {
        /// The ELF, then any arguments cargo passes on (ignored: the firmware takes none)
        #[arg(
            value_name = "ELF",
            required = true,
            num_args = 1..,
            trailing_var_arg = true,
            allow_hyphen_values = true
        )]
        args: Vec<String>,
    },
}

fn main() -> ExitCode {
    let result = match Cli::parse().command {
        Command::Eval(args) => eval::run(&args),
        Command::Accuracy(args) => accuracy::run(&args),
        Command::Paper(args) => paper::run(&args),
        Command::Test => test_cmd::run(),
        Command::Run(args) => qemu::run(&args),
        Command::Bench(args) => qemu::bench(&args),
        Command::Size(args) => qemu::size(&args),
        Command::Flash(args) => qemu::flash(&args),
        Command::Report(args) => report::run(&args),
        Command::Stability(args) => stability::run(&args),
        Command::Ellipsoid(args) => ellipsoid::run(&args),
        Command::Qemu { args } => qemu::qemu(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("xtask: {e:#}");
            ExitCode::FAILURE
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn the_command_line_is_consistent() {
        Cli::command().debug_assert();
    }

    /// The spellings the docs use parse, and misspelt or out-of-range ones are refused.
    #[test]
    fn documented_command_lines_parse() {
        for (line, ok) in [
            ("eval --model earth --backend f32 --input -", true),
            ("accuracy --model earth --quick", true),
            ("paper --out /tmp/paper", true),
            ("run --every 1 --segments all --plot x.png --debug", true),
            ("run --segments 0,5,9 --telemetry t.csv --short", true),
            ("run --short --release --board stm32f405", true),
            ("run --demo --board mps2-an386", true),
            ("report --csv --cases 2000 --seed 0x5EED --no-bench", true),
            ("stability --quick", true),
            ("ellipsoid --print", true),
            ("qemu firmware.elf --quiet --test-threads 1", true),
            ("test", true),
            ("bench", true),
            ("bench --board stm32f405", true),
            ("size", true),
            ("size --board mps2-an386", true),
            ("flash", true),
            ("flash --board stm32f405 --bin demo --print-command", true),
            ("run --board stm32f407", false),
            ("flash --bin bench", false),
            ("run --segment all", false),
            ("run --every 0", false),
            ("run --segments 1,x", false),
            ("report --seed x", false),
            ("eval --backend f16 --input -", false),
            ("frobnicate", false),
        ] {
            let args = std::iter::once("xtask").chain(line.split(' '));
            assert_eq!(Cli::try_parse_from(args).is_ok(), ok, "{line}");
        }
    }
}
