//! The Cortex-M System Design Kit's APB UART and APB timer, as typed register blocks and
//! as the board layer's link, line clock and clock: the code every board built on the
//! CMSDK shares (QEMU's MPS2 images; a board module adds only its addresses, interrupt
//! lines, APB clock and wiring).
//!
//! Register maps from the Cortex-M System Design Kit TRM (ARM DDI0479C) as QEMU models
//! them (hw/char/cmsdk-apb-uart.c, hw/timer/cmsdk-apb-timer.c). Each peripheral is a
//! `#[repr(C)]` block of `volatile_register::RW<u32>`, its field offsets checked against
//! the TRM at compile time, reached through a zero-sized [`Peripheral`] handle that
//! dereferences to the block at the instance's fixed address: the shape of `cortex-m`'s
//! `peripheral` modules. No address arithmetic: the compiler lays the registers out.
//!
//! UART, as modelled by QEMU: a one-byte receive buffer (STATE.RXFULL set on arrival,
//! cleared by reading DATA) and QEMU offers the next byte only once it is empty, so the
//! host side is flow-controlled; a one-byte transmit buffer (STATE.TXFULL) that stays
//! full while the host end of the chardev does not accept the byte. On silicon the
//! receive side overruns instead (STATE.RXOVERRUN) if a byte is not read within one
//! character time: so the receive interrupt reads every byte into the queue of
//! [`crate::rx`], and the loop takes them from there. The transmit interrupt (raised when
//! TXFULL goes from set to clear with CTRL.TXINTEN, latched in INTSTATUS.TX) writes the
//! bytes the loop queued ([`crate::tx`]).

use core::marker::PhantomData;
use core::ops::Deref;

use cortex_m::interrupt::InterruptNumber;
use embedded_hal_nb::serial::{ErrorKind, ErrorType, Read, Write};

use super::{Extended, Monotonic};
use crate::line_clock::ReloadRegister;
use crate::link::QueuedLink;
use crate::rx;
use crate::tx::{self, TxPort};

/// The APB UART's registers (TRM, "APB UART"; QEMU hw/char/cmsdk-apb-uart.c).
pub mod uart {
    use core::mem::{offset_of, size_of};
    use volatile_register::RW;

    /// The UART's register block.
    #[repr(C)]
    pub struct RegisterBlock {
        /// 0x00 DATA: read, the received byte (clears STATE.RXFULL); write, the byte to
        /// send.
        pub data: RW<u32>,
        /// 0x04 STATE: buffer full and overrun flags; the overrun flags are write 1 to
        /// clear.
        pub state: RW<u32>,
        /// 0x08 CTRL: enables (transmitter, receiver, their interrupts).
        pub ctrl: RW<u32>,
        /// 0x0C INTSTATUS on read, INTCLEAR on write (write 1 to clear).
        pub intstatus: RW<u32>,
        /// 0x10 BAUDDIV: the APB clock cycles per bit (at least 16).
        pub bauddiv: RW<u32>,
    }

    const _: () = {
        assert!(offset_of!(RegisterBlock, data) == 0x00);
        assert!(offset_of!(RegisterBlock, state) == 0x04);
        assert!(offset_of!(RegisterBlock, ctrl) == 0x08);
        assert!(offset_of!(RegisterBlock, intstatus) == 0x0C);
        assert!(offset_of!(RegisterBlock, bauddiv) == 0x10);
        assert!(size_of::<RegisterBlock>() == 0x14);
    };

    /// STATE: transmit buffer full.
    pub const STATE_TX_FULL: u32 = 1 << 0;
    /// STATE: receive buffer full.
    pub const STATE_RX_FULL: u32 = 1 << 1;
    /// STATE: receive overrun (write 1 to clear).
    pub const STATE_RX_OVERRUN: u32 = 1 << 3;
    /// CTRL: transmitter enable.
    pub const CTRL_TX_EN: u32 = 1 << 0;
    /// CTRL: receiver enable.
    pub const CTRL_RX_EN: u32 = 1 << 1;
    /// CTRL: transmit interrupt enable.
    pub const CTRL_TX_INTEN: u32 = 1 << 2;
    /// CTRL: receive interrupt enable.
    pub const CTRL_RX_INTEN: u32 = 1 << 3;
    /// INTSTATUS / INTCLEAR: transmit interrupt.
    pub const INT_TX: u32 = 1 << 0;
    /// INTSTATUS / INTCLEAR: receive interrupt.
    pub const INT_RX: u32 = 1 << 1;
    /// The smallest BAUDDIV the UART accepts (QEMU ignores smaller values).
    pub const BAUDDIV_MIN: u32 = 16;
}

/// The APB timer's registers (TRM, "APB timer"; QEMU hw/timer/cmsdk-apb-timer.c).
pub mod timer {
    use core::mem::{offset_of, size_of};
    use volatile_register::RW;

    /// The timer's register block.
    #[repr(C)]
    pub struct RegisterBlock {
        /// 0x0 CTRL: enable, external input as enable or clock, interrupt enable.
        pub ctrl: RW<u32>,
        /// 0x4 VALUE: the down-counter.
        pub value: RW<u32>,
        /// 0x8 RELOAD: loaded into VALUE when it reaches zero.
        pub reload: RW<u32>,
        /// 0xC INTSTATUS on read, INTCLEAR on write (write 1 to clear).
        pub intstatus: RW<u32>,
    }

    const _: () = {
        assert!(offset_of!(RegisterBlock, ctrl) == 0x0);
        assert!(offset_of!(RegisterBlock, value) == 0x4);
        assert!(offset_of!(RegisterBlock, reload) == 0x8);
        assert!(offset_of!(RegisterBlock, intstatus) == 0xC);
        assert!(size_of::<RegisterBlock>() == 0x10);
    };

    /// CTRL: counter enable.
    pub const CTRL_EN: u32 = 1 << 0;
}

/// The APB watchdog's registers (TRM, "APB watchdog"; QEMU
/// hw/watchdog/cmsdk-apb-watchdog.c).
pub mod watchdog {
    use core::mem::{offset_of, size_of};
    use volatile_register::RW;

    /// The watchdog's register block, up to LOCK (the integration-test and ID registers
    /// above it are not used).
    #[repr(C)]
    pub struct RegisterBlock {
        /// 0x000 LOAD: the count the counter restarts from.
        pub load: RW<u32>,
        /// 0x004 VALUE: the down-counter (read only).
        pub value: RW<u32>,
        /// 0x008 CONTROL: INTEN (also runs the counter), RESEN.
        pub control: RW<u32>,
        /// 0x00C INTCLR: any write clears the interrupt and reloads the counter.
        pub intclr: RW<u32>,
        /// 0x010 RIS: raw interrupt status.
        pub ris: RW<u32>,
        /// 0x014 MIS: masked interrupt status.
        pub mis: RW<u32>,
        _reserved: [u32; 762],
        /// 0xC00 LOCK: writing [`UNLOCK`] allows writes to the others, any other value
        /// stops them.
        pub lock: RW<u32>,
    }

    const _: () = {
        assert!(offset_of!(RegisterBlock, load) == 0x000);
        assert!(offset_of!(RegisterBlock, value) == 0x004);
        assert!(offset_of!(RegisterBlock, control) == 0x008);
        assert!(offset_of!(RegisterBlock, intclr) == 0x00C);
        assert!(offset_of!(RegisterBlock, ris) == 0x010);
        assert!(offset_of!(RegisterBlock, mis) == 0x014);
        assert!(offset_of!(RegisterBlock, lock) == 0xC00);
        assert!(size_of::<RegisterBlock>() == 0xC04);
    };

    /// CONTROL: interrupt enable; the counter runs only while it is set.
    pub const CONTROL_INTEN: u32 = 1 << 0;
    /// CONTROL: reset enable: a second time-out with the interrupt still raised resets.
    pub const CONTROL_RESEN: u32 = 1 << 1;
    /// LOCK: the key that allows writes.
    pub const UNLOCK: u32 = 0x1ACC_E551;
}

/// The register block `B` of the peripheral instance at `ADDR`: a zero-sized handle that
/// dereferences to the block, as `cortex-m`'s `SYST` or `NVIC` do. Only its constructor is
/// `unsafe`; reads through it are safe, writes are `volatile_register`'s `unsafe` ones.
pub struct Peripheral<B, const ADDR: usize> {
    // `B` holds `UnsafeCell`s: the handle is `Send` (a driver can move into the
    // receive interrupt's static) but not `Sync`.
    _block: PhantomData<B>,
}

impl<B, const ADDR: usize> Peripheral<B, ADDR> {
    /// The block's address.
    const PTR: *const B = {
        assert!(ADDR != 0 && ADDR.is_multiple_of(core::mem::align_of::<B>()));
        ADDR as *const B
    };

    /// The handle.
    ///
    /// # Safety
    /// A `B` must be mapped at `ADDR` for the whole program (a device's registers, not
    /// memory Rust owns), and the caller must own the registers it uses through the
    /// handle: no other code writes them meanwhile (two handles to one block may split
    /// its registers between them, as the UART's transmitter and receiver do).
    pub const unsafe fn new() -> Self {
        // Evaluated here, so that a misaligned or null address fails the build.
        let _ = Self::PTR;
        Peripheral {
            _block: PhantomData,
        }
    }
}

impl<B, const ADDR: usize> Deref for Peripheral<B, ADDR> {
    type Target = B;

    fn deref(&self) -> &B {
        // SAFETY: `new`'s contract: a `B` is mapped at `ADDR` (aligned and non-null,
        // checked at compile time) for the program's life. Its registers are volatile
        // cells, so a shared reference allows exactly the volatile accesses the drivers
        // make.
        unsafe { &*Self::PTR }
    }
}

/// The registers of the CMSDK APB UART at `ADDR`.
pub type UartRegisters<const ADDR: usize> = Peripheral<uart::RegisterBlock, ADDR>;
/// The registers of the CMSDK APB timer at `ADDR`.
pub type TimerRegisters<const ADDR: usize> = Peripheral<timer::RegisterBlock, ADDR>;

/// The registers of the CMSDK APB watchdog at `ADDR`.
pub type WatchdogRegisters<const ADDR: usize> = Peripheral<watchdog::RegisterBlock, ADDR>;

/// The CMSDK APB watchdog at `ADDR`, counting down from LOAD on its clock: at zero it
/// raises its interrupt (the board wires it to the NMI: the early warning) and starts
/// again; at zero with the interrupt still raised it resets the system. Feeding clears
/// the interrupt and restarts the count.
pub struct Watchdog<const ADDR: usize> {
    regs: WatchdogRegisters<ADDR>,
}

impl<const ADDR: usize> Watchdog<ADDR> {
    /// The watchdog, started: the interrupt after `ticks` of its clock without a feed,
    /// the reset `ticks` later.
    ///
    /// # Safety
    /// A CMSDK APB watchdog must be mapped at `ADDR`, and the caller must be its only
    /// owner; its interrupt's handler must be installed.
    pub unsafe fn start(ticks: u32) -> Self {
        // SAFETY: the caller's contract.
        let regs = unsafe { WatchdogRegisters::new() };
        // SAFETY: unlocked, the count set and the counter started with its interrupt
        // and reset, locked again so that a stray write cannot stop it.
        unsafe {
            regs.lock.write(watchdog::UNLOCK);
            regs.load.write(ticks.max(1));
            regs.intclr.write(1);
            regs.control
                .write(watchdog::CONTROL_INTEN | watchdog::CONTROL_RESEN);
            regs.lock.write(0);
        }
        Watchdog { regs }
    }
}

impl<const ADDR: usize> super::Watchdog for Watchdog<ADDR> {
    fn feed(&mut self) {
        // SAFETY: unlocked, INTCLR written (clears the interrupt, reloads the counter),
        // locked again.
        unsafe {
            self.regs.lock.write(watchdog::UNLOCK);
            self.regs.intclr.write(1);
            self.regs.lock.write(0);
        }
    }
}

/// The receiver of the UART at `ADDR`, read by the receive interrupt only: DATA reads,
/// STATE's receive bits, INTSTATUS.RX (the transmitter's DATA writes, STATE.TXFULL and
/// INTSTATUS.TX are the transmit interrupt's; the status bits are write-1-to-clear, so
/// the two sides never undo each other's writes).
pub struct UartRx<const ADDR: usize> {
    regs: UartRegisters<ADDR>,
}

/// The transmitter of the UART at `ADDR`, written by the transmit interrupt only: DATA
/// writes, STATE.TXFULL, INTSTATUS.TX.
pub struct UartTx<const ADDR: usize> {
    regs: UartRegisters<ADDR>,
}

/// The CMSDK APB UART at `ADDR` as the loop's link ([`QueuedLink`]): the UART, enabled for transmit and receive at `baud` (8N1) from the APB clock
/// `pclk_hz`, its receive interrupt `rx_line` feeding the receive queue through
/// `rx_handler`, its transmit interrupt `tx_line` draining the transmit queue through
/// `tx_handler` (each line's interrupt handler must call its handler's `run()`).
/// None if a queue was taken before.
///
/// # Safety
/// A CMSDK APB UART must be mapped at `ADDR`, and the caller must be its only owner.
pub unsafe fn start_uart<const ADDR: usize, R: InterruptNumber, T: InterruptNumber>(
    pclk_hz: u32,
    baud: u32,
    (rx_handler, rx_line): (&'static rx::Handler<UartRx<ADDR>, R>, R),
    (tx_handler, tx_line): (&'static tx::Handler<UartTx<ADDR>>, T),
) -> Option<QueuedLink<R, T>> {
    // SAFETY: the caller's contract; the three handles split the UART's registers as
    // their types document (set-up here, then the receiver's and the transmitter's).
    let (regs, rx_regs, tx_regs): (UartRegisters<ADDR>, _, _) = unsafe {
        (
            UartRegisters::new(),
            UartRegisters::new(),
            UartRegisters::new(),
        )
    };
    let div = (pclk_hz / baud.max(1)).max(uart::BAUDDIV_MIN);
    // SAFETY: a divider of at least the minimum sets the bit rate, nothing else; the
    // enables start the transmitter and the receiver with their interrupts, whose
    // handlers are installed, before their lines are unmasked, by `rx::start` and
    // `tx::start`.
    unsafe {
        regs.bauddiv.write(div);
        regs.ctrl
            .write(uart::CTRL_TX_EN | uart::CTRL_RX_EN | uart::CTRL_TX_INTEN | uart::CTRL_RX_INTEN);
    }
    let rx = rx::start(rx_handler, UartRx { regs: rx_regs }, rx_line)?;
    let tx = tx::start(tx_handler, UartTx { regs: tx_regs }, tx_line)?;
    Some(QueuedLink::new(rx, tx))
}

impl<const ADDR: usize> ErrorType for UartTx<ADDR> {
    type Error = ErrorKind;
}

impl<const ADDR: usize> Write<u8> for UartTx<ADDR> {
    /// Writes the byte if the one-byte transmit buffer is empty. The transmit
    /// interrupt's status is cleared first, so the byte's leaving raises it again.
    fn write(&mut self, byte: u8) -> nb::Result<(), ErrorKind> {
        // SAFETY: writing 1 clears the transmit interrupt's status bit, the other bits
        // written 0 are left alone.
        unsafe { self.regs.intstatus.write(uart::INT_TX) };
        self.flush()?;
        // SAFETY: the transmit buffer is empty (`flush`): DATA takes the byte to send.
        unsafe { self.regs.data.write(u32::from(byte)) };
        Ok(())
    }

    /// Done when the one-byte transmit buffer is empty.
    fn flush(&mut self) -> nb::Result<(), ErrorKind> {
        if self.regs.state.read() & uart::STATE_TX_FULL == 0 {
            Ok(())
        } else {
            Err(nb::Error::WouldBlock)
        }
    }
}

impl<const ADDR: usize> TxPort for UartTx<ADDR> {
    /// CTRL.TXINTEN stays set: the UART raises its transmit interrupt when a byte leaves
    /// the buffer, an event latched in INTSTATUS.TX until cleared. Every `write` clears
    /// it before it looks at the buffer, so a byte that leaves later raises it anew: to
    /// be interrupted again nothing is to be done (clearing it here could lose that
    /// byte's event). Not to be: the buffer is empty, so the status is cleared.
    fn interrupt(&mut self, on: bool) {
        if !on {
            // SAFETY: writing 1 clears the transmit interrupt's status bit, the other
            // bits written 0 are left alone.
            unsafe { self.regs.intstatus.write(uart::INT_TX) };
        }
    }
}

impl<const ADDR: usize> ErrorType for UartRx<ADDR> {
    type Error = ErrorKind;
}

impl<const ADDR: usize> Read<u8> for UartRx<ADDR> {
    /// The received byte; an overrun (a byte lost because the previous one was not read
    /// in time: never under QEMU, whose UART is flow-controlled) is reported once, then
    /// the byte that is there is read. The receive interrupt's status is cleared first,
    /// so a byte that arrives after this read raises it again.
    fn read(&mut self) -> nb::Result<u8, ErrorKind> {
        // SAFETY: writing 1 clears the receive interrupt's status bit, the other bits
        // written 0 are left alone.
        unsafe { self.regs.intstatus.write(uart::INT_RX) };
        let state = self.regs.state.read();
        if state & uart::STATE_RX_OVERRUN != 0 {
            // SAFETY: writing 1 clears the receive overrun flag, the other bits written
            // 0 (the transmitter's included) are left alone.
            unsafe { self.regs.state.write(uart::STATE_RX_OVERRUN) };
            return Err(nb::Error::Other(ErrorKind::Overrun));
        }
        if state & uart::STATE_RX_FULL == 0 {
            return Err(nb::Error::WouldBlock);
        }
        Ok(self.regs.data.read() as u8)
    }
}

/// A CMSDK APB timer at `ADDR` as a line clock: a 32-bit down-counter on the APB clock
/// that reloads from RELOAD when it reaches zero (one period = RELOAD + 1 clock cycles).
pub struct Timer<const ADDR: usize> {
    regs: TimerRegisters<ADDR>,
}

impl<const ADDR: usize> Timer<ADDR> {
    /// The timer, stopped until its first period is set.
    ///
    /// # Safety
    /// A CMSDK APB timer must be mapped at `ADDR`, and the caller must be its only owner.
    pub unsafe fn stopped() -> Self {
        // SAFETY: the caller's contract.
        let regs = unsafe { TimerRegisters::new() };
        // SAFETY: CTRL 0 stops the counter, with its interrupt disabled.
        unsafe { regs.ctrl.write(0) };
        Timer { regs }
    }
}

impl<const ADDR: usize> ReloadRegister for Timer<ADDR> {
    /// Sets the period; the first one also starts the counter (a running counter with
    /// RELOAD 0 would have no period).
    fn set_reload(&mut self, value: u32) {
        // SAFETY: RELOAD takes any 32-bit value; CTRL_EN alone starts the counter on the
        // APB clock with its interrupt disabled.
        unsafe {
            self.regs.reload.write(value);
            if self.regs.ctrl.read() & timer::CTRL_EN == 0 {
                self.regs.ctrl.write(timer::CTRL_EN);
            }
        }
    }
    fn reload(&self) -> u32 {
        self.regs.reload.read()
    }
}

/// A CMSDK APB timer at `ADDR` counting down from 2^32 - 1 on the APB clock of
/// `PCLK_HZ`, round and round (it wraps every 2^32 ticks), as a [`Monotonic`]. Under
/// QEMU it runs on the virtual clock, which without `-icount` follows the host's.
pub struct FreeRunning<const ADDR: usize, const PCLK_HZ: u32> {
    regs: TimerRegisters<ADDR>,
    ticks: Extended,
}

impl<const ADDR: usize, const PCLK_HZ: u32> FreeRunning<ADDR, PCLK_HZ> {
    /// APB clock ticks per microsecond (a whole number, at least 1: checked when built).
    const TICKS_PER_US: u64 = {
        assert!(PCLK_HZ >= 1_000_000 && PCLK_HZ.is_multiple_of(1_000_000));
        PCLK_HZ as u64 / 1_000_000
    };

    /// The timer, started.
    ///
    /// # Safety
    /// A CMSDK APB timer must be mapped at `ADDR`, and the caller must be its only owner.
    pub unsafe fn start() -> Self {
        // SAFETY: the caller's contract.
        let regs = unsafe { TimerRegisters::new() };
        // SAFETY: stopped, then the full 32-bit range loaded into RELOAD and VALUE, then
        // started on the APB clock with its interrupt disabled.
        unsafe {
            regs.ctrl.write(0);
            regs.reload.write(u32::MAX);
            regs.value.write(u32::MAX);
            regs.ctrl.write(timer::CTRL_EN);
        }
        let ticks = Extended::new(1 << 32, Self::elapsed(&regs));
        FreeRunning { regs, ticks }
    }

    /// Ticks since the count started, modulo 2^32 (the counter counts down).
    fn elapsed(regs: &timer::RegisterBlock) -> u32 {
        !regs.value.read()
    }
}

impl<const ADDR: usize, const PCLK_HZ: u32> Monotonic for FreeRunning<ADDR, PCLK_HZ> {
    // Out of line: the loop reads the clock in several places, and inlined each was a
    // copy of the 64-bit extension (docs/target.md, flash).
    #[inline(never)]
    fn now_us(&mut self) -> u64 {
        let ticks = self.ticks.update(Self::elapsed(&self.regs));
        ticks / Self::TICKS_PER_US
    }
}
