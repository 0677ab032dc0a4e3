//! What survives a reset: a record in the RAM region `RETAINED` of the board's memory
//! layout (`firmware/memory/`), which neither the startup code nor QEMU's image loader
//! writes, so its contents outlive a watchdog or software reset (not a power cycle).
//!
//! Today the record holds why the core was last reset and how many resets there have
//! been since power-on (docs/target.md, "Faults and resets"). It is trusted only when
//! its magic, version and CRC check out: after power-on the RAM holds noise, which
//! this reads as a power-on reset and starts the count afresh.
//!
//! A handler that is about to reset the core (the watchdog's early warning on the
//! mps2, the HardFault handler) notes the cause first ([`note_cause`]); the next boot reads it ([`boot`]). A
//! board whose reset controller keeps its own flags (the STM32F405's RCC_CSR) hands
//! them to [`boot`], and they win over a noted cause.

use controller::crc;

/// Why the core last started.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ResetCause {
    /// Power-on (or a record that did not check out: RAM contents not to be trusted).
    PowerOn,
    /// The watchdog: the main loop stopped making progress.
    Watchdog,
    /// The firmware asked for it (SYSRESETREQ) for a reason it did not note.
    Software,
    /// The stack ran into its guard (crate::stack).
    StackOverflow,
    /// Any other HardFault.
    Fault,
    /// A reset the firmware did not see coming and the board cannot name (the reset
    /// pin, a debugger).
    Unknown,
}

impl ResetCause {
    pub fn name(self) -> &'static str {
        match self {
            ResetCause::PowerOn => "power-on",
            ResetCause::Watchdog => "watchdog",
            ResetCause::Software => "software",
            ResetCause::StackOverflow => "stack overflow",
            ResetCause::Fault => "hard fault",
            ResetCause::Unknown => "unknown",
        }
    }

    fn code(self) -> u32 {
        match self {
            ResetCause::PowerOn => 1,
            ResetCause::Watchdog => 2,
            ResetCause::Software => 3,
            ResetCause::Unknown => 4,
            ResetCause::StackOverflow => 5,
            ResetCause::Fault => 6,
        }
    }

    fn from_code(code: u32) -> Option<ResetCause> {
        [
            ResetCause::PowerOn,
            ResetCause::Watchdog,
            ResetCause::Software,
            ResetCause::Unknown,
            ResetCause::StackOverflow,
            ResetCause::Fault,
        ]
        .into_iter()
        .find(|c| c.code() == code)
    }
}

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
const VERSION: u32 = 1;

impl Record {
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

    fn checks_out(&self) -> bool {
        self.magic == MAGIC && self.version == VERSION && self.crc == self.crc()
    }

    fn sealed(mut self) -> Record {
        self.crc = self.crc();
        self
    }
}

extern "C" {
    /// The start of the board's `RETAINED` region (its memory layout defines it).
    static mut __sretained: Record;
    static __eretained: u8;
}

const _: () = assert!(core::mem::size_of::<Record>() <= 4096);

fn read() -> Record {
    // SAFETY: `__sretained` is the start of RAM that the memory layout reserves for this
    // module alone (4 KiB, aligned: checked above and by the layout), always mapped; any
    // bit pattern is a valid `Record` of `u32`s. Volatile: the contents come from before
    // the reset, which the compiler cannot know.
    unsafe { core::ptr::read_volatile(&raw const __sretained) }
}

fn write(record: Record) {
    // SAFETY: as in `read`; only this module writes the region, and the firmware is
    // single-threaded apart from handlers that end in a reset (`note_cause`).
    unsafe { core::ptr::write_volatile(&raw mut __sretained, record) }
}

/// Reads (and then renews) the record at boot. `hardware` is the cause the board's
/// reset controller reports, if it keeps one.
pub fn boot(hardware: Option<ResetCause>) -> Boot {
    let old = read();
    let (cause, resets) = if old.checks_out() {
        let noted = ResetCause::from_code(old.noted_cause);
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
    Boot { cause, resets }
}

/// Notes why the core is about to be reset, for the next [`boot`]. Called by a handler
/// that resets the core next; leaves a record that does not check out alone.
pub fn note_cause(cause: ResetCause) {
    let mut record = read();
    if record.checks_out() {
        record.noted_cause = cause.code();
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
