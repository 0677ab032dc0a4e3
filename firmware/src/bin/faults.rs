//! A build that fails on purpose, twice, to show that the firmware comes back (docs/
//! target.md, "Faults and resets"; `cargo xtask test` runs it on the mps2-an386, whose
//! watchdog, MPU and system reset QEMU models).
//!
//! Each boot brings the board up as the flight binary does (watchdog started, stack
//! guard and heartbeat set up), reads the reset record and goes on by its cause:
//! 1. after power-on it runs the controller once (the default scene, a synthetic NAV
//!    frame at 20 deg of roll and 10 of pitch), uploads a small DEM tile into the tile
//!    memory in retained RAM (`RETAINED_DEM`), keeps its snapshot in retained RAM as
//!    the flight loop does, then stops feeding the watchdog (the heartbeat still wakes
//!    the core): the watchdog's early warning notes the cause and resets the core;
//! 2. after the watchdog's reset it restores the kept snapshot into a fresh controller
//!    and checks that every period comes back, held, equal to a recomputation, and that
//!    the DEM tile comes back in force with the bounds of its heights; then it
//!    recurses until the stack runs into its guard: the HardFault handler notes a stack
//!    overflow and resets the core;
//! 3. after that reset it exits with status 0.
//!
//! Any other cause, or a step that does not end in the reset it should, exits with 1
//! (or hangs until the runner's time limit, if no watchdog fires).
#![no_std]
#![no_main]

use controller::dem::{encode_begin, encode_chunk, heights_crc32, DEM_CHUNK_NODES};
use controller::frame::{kind, Frame, MAX_PAYLOAD};
use controller::{Controller, LinePeriodSink};
use core_math::earth::dem::{DemGrid, DemTile};
use cortex_m_rt::entry;
use firmware::board::{self, Monotonic, Parts, WATCHDOG_TIMEOUT_MS};
use firmware::retained::{self, ResetCause};
use firmware::synthetic::{controller_with_nav, NoRegisters};
use firmware::{heartbeat, platform, stack};

/// The controller of step 1, after its one update (None if it refused).
fn flown() -> Option<Controller> {
    let attitude = controller::nav::Attitude {
        roll_rad: 20f32.to_radians(),
        pitch_rad: 10f32.to_radians(),
        ..Default::default()
    };
    let mut c = controller_with_nav(controller::Scene::paper_default(), false, attitude).ok()?;
    c.advance(1_000_000, &mut NoRegisters).then_some(c)
}

/// The tile step 1 uploads: 16 x 20 nodes (two chunks), 100 m to 8 000 m.
const DEM_ID: u32 = 0x2300;
const DEM_ROWS: usize = 16;
const DEM_COLS: usize = 20;

fn dem_grid() -> DemGrid {
    DemGrid {
        lat0_deg: 46.0,
        lon0_deg: 7.5,
        dlat_deg: 0.01,
        dlon_deg: 0.01,
        nrows: DEM_ROWS,
        ncols: DEM_COLS,
    }
}

fn dem_heights() -> [i16; DEM_ROWS * DEM_COLS] {
    core::array::from_fn(|k| 100 + ((k * 397) % 7_901) as i16)
}

/// Step 1's upload through the controller's frame intake; true if the tile is in force.
fn upload_tile(c: &mut Controller, boot: &retained::Boot) -> bool {
    let Some(store) = retained::dem_store(boot) else {
        return false;
    };
    c.attach_dem(store);
    let h = dem_heights();
    let mut t_us = c.now_us();
    let mut send = |c: &mut Controller, kind: u8, payload: &[u8]| {
        t_us += 1_000;
        let before = c.frames_accepted;
        c.on_frame(&Frame {
            kind,
            sequence: 0,
            time_us: t_us,
            payload,
        });
        c.frames_accepted == before + 1
    };
    let mut ok = send(
        c,
        kind::DEM_BEGIN,
        &encode_begin(DEM_ID, &dem_grid(), heights_crc32(&h)),
    );
    let mut buf = [0u8; MAX_PAYLOAD];
    for k in 0..(h.len().div_ceil(DEM_CHUNK_NODES) as u16) {
        let Some(n) = encode_chunk(DEM_ID, k, &h, &mut buf) else {
            return false;
        };
        ok &= send(c, kind::DEM_CHUNK, buf.get(..n).unwrap_or(&[]));
    }
    ok && c.dem_status().in_force_id == DEM_ID
}

/// Step 2's check of the tile: a fresh controller lent the tile memory puts the tile
/// back in force, with the bounds core-math finds in the same heights.
fn tile_as_kept(boot: &retained::Boot) -> bool {
    let Some(store) = retained::dem_store(boot) else {
        return false;
    };
    let mut c = Controller::blank(board::controller_config());
    c.attach_dem(store);
    let restored = c.restore_dem();
    let h = dem_heights();
    let same = match (c.dem_tile(), DemTile::new(dem_grid(), &h)) {
        (Some(got), Ok(want)) => got.bounds() == want.bounds() && *got.grid() == dem_grid(),
        _ => false,
    };
    defmt::info!(
        "DEM tile from retained RAM: id {=u32}, bounds as uploaded: {=bool}",
        restored.unwrap_or(0),
        same
    );
    restored == Ok(DEM_ID) && same
}

/// Period registers that remember what was written.
struct Recorded {
    ticks: [u32; controller::scene::MAX_SEGMENTS],
}

impl LinePeriodSink for Recorded {
    type Error = core::convert::Infallible;
    fn write_period(&mut self, index: u8, ticks: u32) -> Result<(), Self::Error> {
        if let Some(t) = self.ticks.get_mut(usize::from(index)) {
            *t = ticks;
        }
        Ok(())
    }
}

/// Step 2's check: the kept snapshot restored into a fresh controller gives back every
/// period of step 1 (recomputed: the controller is deterministic), each flagged held.
fn restored_as_kept(boot: &retained::Boot) -> bool {
    let (Some(snapshot), Some(expected)) = (retained::snapshot(boot), flown()) else {
        return false;
    };
    let mut c = Controller::blank(board::controller_config());
    let mut regs = Recorded {
        ticks: [0; controller::scene::MAX_SEGMENTS],
    };
    let Ok(restored) = c.restore(snapshot, &mut regs) else {
        return false;
    };
    let all_back = expected.outputs().all(|o| {
        regs.ticks.get(usize::from(o.index)) == Some(&o.ticks)
            && c.outputs()
                .any(|r| r.index == o.index && r.held && r.ticks == o.ticks)
    });
    defmt::info!(
        "restored {=usize} of {=usize} periods from retained RAM, held: {=bool}",
        restored.periods,
        expected.outputs().count(),
        all_back
    );
    all_back && restored.periods == expected.outputs().count()
}

#[entry]
fn main() -> ! {
    let Parts {
        mut clock,
        reset_cause,
        core_clock_hz,
        ..
    } = match board::take() {
        Ok(parts) => parts,
        Err(e) => {
            defmt::error!("board {=str}: {}", board::NAME, e);
            platform::exit(3)
        }
    };
    let boot = retained::boot(reset_cause);
    defmt::info!(
        "boot: reset cause {=str}, {=u32} resets since power-on",
        boot.cause.name(),
        boot.resets
    );
    let Some(mut core) = cortex_m::Peripherals::take() else {
        platform::exit(3)
    };
    let Some(guard) = stack::guard(&mut core.MPU) else {
        platform::exit(3)
    };
    let Some(_syst) = heartbeat::start(core.SYST, core_clock_hz) else {
        platform::exit(3)
    };
    match (boot.resets, boot.cause) {
        (0, ResetCause::PowerOn) => {
            let Some(mut c) = flown() else {
                platform::exit(1)
            };
            if !upload_tile(&mut c, &boot) {
                defmt::error!("the DEM tile was not taken");
                platform::exit(1)
            }
            defmt::info!("DEM tile {=u32} in force", DEM_ID);
            retained::keep(&c, &mut retained::Kept::default());
            defmt::info!(
                "kept a snapshot: {=usize} periods, segment 0 at {=u32} ticks",
                c.outputs().count(),
                c.outputs().next().map_or(0, |o| o.ticks)
            );
            defmt::info!(
                "hanging on purpose at t = {=u64} us: nothing feeds the watchdog (time-out {=u32} ms)",
                clock.now_us(),
                WATCHDOG_TIMEOUT_MS
            );
            loop {
                // The heartbeat wakes the core; nothing feeds the watchdog.
                cortex_m::asm::wfi();
            }
        }
        (1, ResetCause::Watchdog) => {
            if !restored_as_kept(&boot) {
                defmt::error!("the snapshot did not come back as kept");
                platform::exit(1)
            }
            if !tile_as_kept(&boot) {
                defmt::error!("the DEM tile did not come back as kept");
                platform::exit(1)
            }
            defmt::info!(
                "overflowing the stack on purpose: guard at {=usize:#010x}..{=usize:#010x}",
                guard.start,
                guard.end
            );
            let depth = recurse(u32::MAX);
            defmt::error!("the recursion returned ({=u32}): no overflow", depth);
            platform::exit(1)
        }
        (2, ResetCause::StackOverflow) => {
            defmt::info!("recovered: running again after a watchdog reset and a stack overflow");
            platform::exit(0)
        }
        (resets, cause) => {
            defmt::error!(
                "unexpected: reset cause {=str} after {=u32} resets",
                cause.name(),
                resets
            );
            platform::exit(1)
        }
    }
}

/// Recursion `n` deep, each frame holding 64 bytes the optimiser cannot drop.
#[inline(never)]
fn recurse(n: u32) -> u32 {
    let frame = core::hint::black_box([n; 16]);
    if n == 0 {
        return 0;
    }
    let below = recurse(core::hint::black_box(n - 1));
    below.wrapping_add(frame.iter().fold(0, |a, b| a ^ b))
}
