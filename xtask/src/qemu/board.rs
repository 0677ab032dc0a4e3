//! The boards the firmware builds for (`firmware/src/board/`), as the xtask sees them:
//! the cargo feature that selects one, the QEMU machine that emulates it, the probe-rs
//! chip of the real part; which board an ELF was linked for; and `cargo xtask size`.

use anyhow::{anyhow, Context, Result};
use std::path::Path;

use object::{Object, ObjectSection, ObjectSymbol};

/// A board of the firmware (and of the hil-tests, which take the same features); the
/// value of `--board` (its name, which is also the cargo feature).
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Board {
    /// QEMU's mps2-an386 (CMSDK UART and timers): the default
    #[value(name = "mps2-an386")]
    Mps2An386,
    /// QEMU's mps2-an385: the same peripherals on a Cortex-M3 without FPU
    #[value(name = "mps2-an385")]
    Mps2An385,
    /// An STM32F405RG through stm32f4xx-hal: QEMU's netduinoplus2, or a real board
    #[value(name = "stm32f405")]
    Stm32f405,
}

/// `--board NAME` of `run` and `bench` (the default board when absent).
#[derive(clap::Args)]
pub struct BoardArg {
    /// The board to build for, and its QEMU machine (docs/target.md)
    #[arg(long, value_enum, default_value_t = Board::DEFAULT)]
    pub board: Board,
}

impl Board {
    pub const ALL: [Board; 3] = [Board::Mps2An386, Board::Mps2An385, Board::Stm32f405];
    /// The firmware crate's default feature.
    pub const DEFAULT: Board = Board::Mps2An386;

    /// The name, which is also the cargo feature.
    pub fn name(self) -> &'static str {
        match self {
            Board::Mps2An386 => "mps2-an386",
            Board::Mps2An385 => "mps2-an385",
            Board::Stm32f405 => "stm32f405",
        }
    }

    /// The flight binary's flash budget (bytes): 80 KiB on the Cortex-M4F boards (issue
    /// 23, with the DEM route), 96 KiB on the Cortex-M3 (issue 24), docs/target.md.
    pub fn flash_budget_bytes(self) -> u64 {
        match self {
            Board::Mps2An386 | Board::Stm32f405 => 80 * 1024,
            Board::Mps2An385 => 96 * 1024,
        }
    }

    /// The Rust target: hard-float Cortex-M4F, or the Cortex-M3's soft float.
    pub fn target(self) -> &'static str {
        match self {
            Board::Mps2An386 | Board::Stm32f405 => super::TARGET,
            Board::Mps2An385 => super::NO_FPU_TARGET,
        }
    }

    /// The controller's configuration in this board's firmware
    /// (`firmware::board::controller_config`), for the host twin: the sample pixels in
    /// fixed point on the core without an FPU.
    pub fn controller_config(self) -> controller::Config {
        controller::Config {
            fixed_point_pixels: self == Board::Mps2An385,
            ..controller::Config::default()
        }
    }

    /// QEMU's `-cpu`.
    pub fn qemu_cpu(self) -> &'static str {
        match self {
            Board::Mps2An386 | Board::Stm32f405 => "cortex-m4",
            Board::Mps2An385 => "cortex-m3",
        }
    }

    /// QEMU's `-machine`.
    pub fn qemu_machine(self) -> &'static str {
        match self {
            Board::Mps2An386 => "mps2-an386",
            Board::Mps2An385 => "mps2-an385",
            Board::Stm32f405 => "netduinoplus2",
        }
    }

    /// probe-rs's `--chip` for the real part; None for a board that exists only in QEMU.
    pub fn probe_rs_chip(self) -> Option<&'static str> {
        match self {
            Board::Mps2An386 | Board::Mps2An385 => None,
            Board::Stm32f405 => Some("STM32F405RGTx"),
        }
    }

    /// The symbol the board's memory layout (`firmware/memory/<board>.x`) defines, so
    /// that an ELF says which board it was linked for.
    fn symbol(self) -> String {
        format!("__tdi_board_{}", self.name().replace('-', "_"))
    }

    /// The cargo arguments that build for this board with `extra` features besides:
    /// `--no-default-features --features <board>[,extra...]`.
    pub fn cargo_features(self, extra: &[&str]) -> [String; 3] {
        let mut features = vec![self.name()];
        features.extend_from_slice(extra);
        [
            "--no-default-features".into(),
            "--features".into(),
            features.join(","),
        ]
    }

    /// The board `elf` was linked for, from its symbol table.
    pub fn of_elf(elf: &[u8]) -> Result<Board> {
        let file = object::File::parse(elf).context("not an ELF file")?;
        let found: Vec<Board> = Board::ALL
            .into_iter()
            .filter(|b| {
                let symbol = b.symbol();
                file.symbols().any(|s| s.name() == Ok(symbol.as_str()))
            })
            .collect();
        match found.as_slice() {
            [board] => Ok(*board),
            [] => Err(anyhow!(
                "the ELF names no board (no symbol __tdi_board_*; boards: {})",
                names()
            )),
            _ => Err(anyhow!("the ELF names several boards")),
        }
    }
}

/// Every board's name, for messages.
pub fn names() -> String {
    Board::ALL.map(Board::name).join(", ")
}

/// The sections that take RAM before the stack: initialised data, zeroed data and
/// cortex-m-rt's uninitialised statics.
const RAM_SECTIONS: [&str; 3] = [".data", ".bss", ".uninit"];

/// `cargo xtask size`'s options.
#[derive(clap::Args)]
pub struct SizeArgs {
    /// Only this board [default: every board]
    #[arg(long, value_enum)]
    board: Option<Board>,
}

/// `cargo xtask size`: the release flight binary of each board (or of the one named):
/// flash (every section loaded from flash: vector table, code, constants, `.data`'s
/// initial image) and static RAM.
pub fn size(args: &SizeArgs) -> Result<()> {
    let boards = match args.board {
        Some(board) => vec![board],
        None => Board::ALL.to_vec(),
    };
    super::ensure_target_tools()?;
    let mut lines = Vec::new();
    for board in boards {
        let elf = super::build_firmware(board, "firmware", true, &[], &[])?;
        lines.push(size_line(board, &elf)?);
    }
    println!("\nrelease flight binary (opt-level 3, fat LTO), bytes:");
    for line in lines {
        println!("{line}");
    }
    println!("(stack: the firmware's last log line of `cargo xtask run --board NAME`)");
    Ok(())
}

/// Each board's release flight binary within its flash budget, or an error naming the
/// excess (`cargo xtask test`).
pub fn check_flash_budgets() -> Result<()> {
    for board in Board::ALL {
        let elf = super::build_firmware(board, "firmware", true, &[], &[])?;
        let (flash, budget) = (
            crate::footprint::flash_bytes(&elf)?,
            board.flash_budget_bytes(),
        );
        anyhow::ensure!(
            flash <= budget,
            "{}: the flight binary is {flash} bytes of flash, over its budget of {budget} by {} \
             (docs/target.md, flash)",
            board.name(),
            flash - budget
        );
        eprintln!(
            "xtask: {} flash {flash} bytes, budget {budget}",
            board.name()
        );
    }
    Ok(())
}

fn size_line(board: Board, elf: &Path) -> Result<String> {
    let flash = crate::footprint::flash_bytes(elf)?;
    let bytes = std::fs::read(elf).with_context(|| format!("reading {}", elf.display()))?;
    let file = object::File::parse(&*bytes).with_context(|| format!("{}", elf.display()))?;
    let ram: Vec<String> = RAM_SECTIONS
        .iter()
        .map(|name| {
            let size = file.section_by_name(name).map_or(0, |s| s.size());
            format!("{name} {size}")
        })
        .collect();
    let sections: u64 = RAM_SECTIONS
        .iter()
        .map(|name| file.section_by_name(name).map_or(0, |s| s.size()))
        .sum();
    // The retained regions hold no section: their size is their symbols' distance.
    use object::{Object as _, ObjectSymbol as _};
    let symbol = |name: &str| {
        file.symbols()
            .find(|s| s.name() == Ok(name))
            .map(|s| s.address())
    };
    let region = |start: &str, end: &str| match (symbol(start), symbol(end)) {
        (Some(a), Some(b)) => b.saturating_sub(a),
        _ => 0,
    };
    let retained = region("__sretained", "__eretained");
    let dem = region("__sretained_dem", "__eretained_dem");
    Ok(format!(
        "{:<11} flash {flash} (budget {}), static RAM: {}, retained {retained} + DEM tile memory {dem}, total {}",
        board.name(),
        board.flash_budget_bytes(),
        ram.join(", "),
        sections + retained + dem
    ))
}
