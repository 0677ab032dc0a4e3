//! What survives a reset: a record in the RAM region `RETAINED` of the board's memory
//! layout (`firmware/memory/`), which neither the startup code nor QEMU's image loader
//! writes, so its contents outlive a watchdog or software reset (not a power cycle).
//!
//! The record holds why the core was last reset and how many resets there have been
//! since power-on, and the controller's [`Snapshot`] (the scene, its heights and the
//! last periods, in the telemetry's encodings: `controller::restart`), kept up to date
//! by the loop ([`keep`]) and handed back after a reset ([`snapshot`]) (docs/target.md,
//! "Faults and resets"). Each part is trusted only when its magic, version and CRC
//! check out: after power-on the RAM holds noise, which this reads as a power-on reset
//! with nothing kept.
//!
//! A handler that is about to reset the core (the watchdog's early warning on the
//! mps2, the HardFault handler) notes the cause first ([`note_cause`]); the next boot reads it ([`boot`]). A
//! board whose reset controller keeps its own flags (the STM32F405's RCC_CSR) hands
//! them to [`boot`], and they win over a noted cause.

use controller::crc;
use controller::dem::DemStore;
pub use controller::fault::ResetCause;
use controller::restart::{Payload, Snapshot};
use controller::Controller;

/// What [`boot`] found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Boot {
    pub cause: ResetCause,
    /// Resets since power-on, this one included (0 after power-on).
    pub resets: u32,
}

/// The record's layout. `repr(C)` and only `u32`s, so that a build with a different
/// layout is caught by `VERSION`, not misread.
#[repr(C)]
#[derive(Clone, Copy)]
struct Record {
    magic: u32,
    version: u32,
    resets: u32,
    /// The cause a handler noted just before it reset the core (0: none noted).
    noted_cause: u32,
    /// CRC-16/CCITT-FALSE of the fields above, in the low half.
    crc: u32,
}

const MAGIC: u32 = 0x5444_4952; // "TDIR"
const VERSION: u32 = 4;

impl Record {
    // Out of line: the boot, the HardFault handler and the cause's note all seal or
    // check the record.
    #[inline(never)]
    fn crc(&self) -> u32 {
        let mut bytes = [0u8; 16];
        for (chunk, word) in
            bytes
                .chunks_exact_mut(4)
                .zip([self.magic, self.version, self.resets, self.noted_cause])
        {
            chunk.copy_from_slice(&word.to_le_bytes());
        }
        u32::from(crc::crc16(&bytes))
    }

    // Out of line, as `crc`: three callers.
    #[inline(never)]
    fn checks_out(&self) -> bool {
        self.magic == MAGIC && self.version == VERSION && self.crc == self.crc()
    }

    fn sealed(mut self) -> Record {
        self.crc = self.crc();
        self
    }
}

/// The region's contents: the record, then the snapshot with its two CRCs (one for the
/// scene and heights, written when they change; one for the periods and the attitude
/// estimate, written after every update), each over the payloads' lengths and bytes. `repr(C)`; the snapshot's
/// fields are `u16`s and bytes, so any contents are a valid value, checked before use.
#[repr(C)]
struct Region {
    record: Record,
    inputs_crc: u32,
    periods_crc: u32,
    snapshot: Snapshot,
}

extern "C" {
    /// The start of the board's `RETAINED` region (its memory layout defines it).
    static mut __sretained: Region;
    static __eretained: u8;
    /// The board's `RETAINED_DEM` region: the DEM tile memory.
    static mut __sretained_dem: DemStore;
    static __eretained_dem: u8;
}

const _: () = assert!(core::mem::size_of::<Region>() <= 4096);

fn read() -> Record {
    // SAFETY: `__sretained` is the start of RAM that the memory layout reserves for this
    // module alone (4 KiB, aligned: checked above and by the layout), always mapped; any
    // bit pattern is a valid `Record` of `u32`s. Volatile: the contents come from before
    // the reset, which the compiler cannot know.
    unsafe { core::ptr::read_volatile(&raw const __sretained.record) }
}

fn write(record: Record) {
    // SAFETY: as in `read`; only this module writes the region, and the firmware is
    // single-threaded apart from handlers that end in a reset (`note_cause`).
    unsafe { core::ptr::write_volatile(&raw mut __sretained.record, record) }
}

/// The region, for the loop's snapshot (`keep`) and the boot's (`snapshot`).
///
/// # Safety
/// No other reference to the region may be alive: callers are the loop and `main`
/// before it, one at a time, and the handlers that touch the record (`note_cause`)
/// reset the core before the interrupted code resumes.
unsafe fn region() -> &'static mut Region {
    // SAFETY: the caller's contract; the region is mapped RAM of the right size (checked
    // above) and any contents are a valid `Region`.
    unsafe { &mut *core::ptr::addr_of_mut!(__sretained) }
}

// Out of line: `keep` and the boot's restore both check it, and flash is scarcer than
// the cycles of a call.
#[inline(never)]
fn payload_crc(parts: &[&Payload]) -> u32 {
    let crc = parts.iter().fold(crc::INIT, |c, p| {
        let c = crc::update(c, &p.len.to_le_bytes());
        crc::update(c, p.as_slice())
    });
    u32::from(crc)
}

/// What the loop has last kept ([`keep`]): when to write again.
#[derive(Clone, Copy, Default)]
pub struct Kept {
    inputs_generation: Option<u32>,
    updates: Option<u32>,
    /// The attitude estimate's time of validity (an ATTITUDE frame changes it).
    attitude_us: Option<u64>,
}

/// Keeps the controller's snapshot up to date in retained RAM: the scene and heights
/// when they have changed, the periods and the attitude estimate after each update and
/// each new attitude.
pub fn keep(c: &Controller, kept: &mut Kept) {
    // SAFETY: the loop is the only user of the region while it runs (`region`).
    let region = unsafe { region() };
    if kept.inputs_generation != Some(c.inputs_generation()) {
        kept.inputs_generation = Some(c.inputs_generation());
        region.inputs_crc = if c.snapshot_inputs(&mut region.snapshot) {
            payload_crc(&[
                &region.snapshot.scene,
                &region.snapshot.terrain,
                &region.snapshot.time_scales,
            ])
        } else {
            // Never for a scene the controller took; a CRC that cannot match says "none".
            !payload_crc(&[
                &region.snapshot.scene,
                &region.snapshot.terrain,
                &region.snapshot.time_scales,
            ])
        };
    }
    let attitude_us = c.bus_attitude().map(|a| a.received.valid_us);
    if kept.updates != Some(c.updates) || kept.attitude_us != attitude_us {
        (kept.updates, kept.attitude_us) = (Some(c.updates), attitude_us);
        let s = &mut region.snapshot;
        let written = c.snapshot_periods(&mut s.periods) && c.snapshot_attitude(&mut s.attitude);
        let crc = payload_crc(&[&s.periods, &s.attitude]);
        region.periods_crc = if written { crc } else { !crc };
    }
}

/// The snapshot kept before the reset, if the record and both CRCs check out and the
/// core was not powered on (call after [`boot`], before the loop's first [`keep`]).
pub fn snapshot(boot: &Boot) -> Option<&'static Snapshot> {
    // SAFETY: called by `main` before the loop runs: no other user (`region`).
    let region = unsafe { region() };
    let ok = boot.cause != ResetCause::PowerOn
        && region.record.checks_out()
        && region.inputs_crc
            == payload_crc(&[
                &region.snapshot.scene,
                &region.snapshot.terrain,
                &region.snapshot.time_scales,
            ])
        && region.periods_crc
            == payload_crc(&[&region.snapshot.periods, &region.snapshot.attitude]);
    ok.then_some(&region.snapshot)
}

/// Reads (and then renews) the record at boot. `hardware` is the cause the board's
/// reset controller reports, if it keeps one.
pub fn boot(hardware: Option<ResetCause>) -> Boot {
    let old = read();
    let (cause, resets) = if old.checks_out() {
        let noted = u8::try_from(old.noted_cause)
            .ok()
            .and_then(ResetCause::from_u8);
        // The reset controller's flags win, except that a noted cause says more than
        // "software": the firmware's own reset after it noted why.
        let cause = match (hardware, noted) {
            (Some(ResetCause::Software), Some(n)) => n,
            (Some(h), _) => h,
            (None, n) => n.unwrap_or(ResetCause::Unknown),
        };
        if cause == ResetCause::PowerOn {
            (cause, 0)
        } else {
            (cause, old.resets.saturating_add(1))
        }
    } else {
        (ResetCause::PowerOn, 0)
    };
    write(
        Record {
            magic: MAGIC,
            version: VERSION,
            resets,
            noted_cause: 0,
            crc: 0,
        }
        .sealed(),
    );
    if cause == ResetCause::PowerOn {
        // Noise until the loop keeps a snapshot: make sure no CRC can match it.
        // SAFETY: called by `main` before the loop runs: no other user (`region`).
        let region = unsafe { region() };
        region.snapshot = Snapshot::EMPTY;
        region.inputs_crc = !payload_crc(&[
            &region.snapshot.scene,
            &region.snapshot.terrain,
            &region.snapshot.time_scales,
        ]);
        region.periods_crc = !payload_crc(&[&region.snapshot.periods]);
    }
    Boot { cause, resets }
}

/// Notes why the core is about to be reset, for the next [`boot`]. Called by a handler
/// that resets the core next; leaves a record that does not check out alone.
// Out of line: the fault handler and the watchdog's each inlined a copy.
#[inline(never)]
pub fn note_cause(cause: ResetCause) {
    let mut record = read();
    if record.checks_out() {
        record.noted_cause = u32::from(cause as u8);
        write(record.sealed());
    }
}

/// The size of the region the layout reserves (bytes).
pub fn capacity_bytes() -> usize {
    // Only the symbols' addresses are taken, which needs no `unsafe`.
    let (start, end) = (
        (&raw const __sretained) as usize,
        (&raw const __eretained) as usize,
    );
    end.saturating_sub(start)
}

/// Whether [`dem_store`] has lent the tile memory.
static DEM_LENT: core::sync::atomic::AtomicBool = core::sync::atomic::AtomicBool::new(false);

/// The DEM tile memory in the region `RETAINED_DEM`, once (`None` after, or if the
/// layout's region is too small for it). After power-on its record is forgotten (the
/// RAM holds noise); after a reset it is left for `Controller::restore_dem` to check.
pub fn dem_store(boot: &Boot) -> Option<&'static mut DemStore> {
    let (start, end) = (
        (&raw const __sretained_dem) as usize,
        (&raw const __eretained_dem) as usize,
    );
    let fits = end.saturating_sub(start) >= core::mem::size_of::<DemStore>()
        && start % core::mem::align_of::<DemStore>() == 0;
    if !fits || DEM_LENT.swap(true, core::sync::atomic::Ordering::Relaxed) {
        return None;
    }
    // SAFETY: the region is mapped RAM that the memory layout reserves for the store
    // alone, large and aligned enough (checked above); any contents are a valid
    // `DemStore` (integers only); `DEM_LENT` makes this the only reference ever made.
    let store = unsafe { &mut *core::ptr::addr_of_mut!(__sretained_dem) };
    if boot.cause == ResetCause::PowerOn {
        store.forget();
    }
    Some(store)
}
