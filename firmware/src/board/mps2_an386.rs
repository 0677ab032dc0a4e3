//! Board `mps2-an386` (the default): QEMU's `-machine mps2-an386`, a Cortex-M4 with FPU
//! and the Cortex-M System Design Kit's APB peripherals at fixed addresses, driven
//! directly (there is no HAL for it): UART0, the telemetry link; TIMER0, standing in
//! for segment 0's line clock; TIMER1, free-running, the [`Monotonic`] clock. Register
//! maps from the Cortex-M System Design Kit TRM (ARM DDI0479C) as QEMU models them
//! (hw/char/cmsdk-apb-uart.c, hw/timer/cmsdk-apb-timer.c).
//!
//! UART, as modelled by QEMU: a one-byte receive buffer (STATE.RXFULL set on arrival,
//! cleared by reading DATA) and QEMU offers the next byte only once it is empty, so the
//! host side is flow-controlled; a one-byte transmit buffer (STATE.TXFULL) that stays
//! full while the host end of the chardev does not accept the byte. On silicon the
//! receive side overruns instead (STATE.RXOVERRUN) if a byte is not read within one
//! character time: so the receive interrupt reads every byte into the queue of
//! [`crate::rx`], and the loop takes them from there.

use core::sync::atomic::{AtomicBool, Ordering};

use embedded_hal_nb::serial::{ErrorKind, ErrorType, Read, Write};

use super::{BoardError, Extended, Monotonic, Parts, LINK_BAUD};
use crate::line_clock::ReloadRegister;
use crate::link::{LinkError, RxWait};
use crate::platform;
use crate::rx::{self, RxQueue};

/// The board's name (the cargo feature).
pub const NAME: &str = "mps2-an386";
/// The telemetry link's peripheral.
pub const LINK: &str = "UART0";
/// The board's telemetry link, segment 0's line clock and clock.
pub type Link = Uart;
pub type LineClock = Timer;
pub type Clock = FreeRunning;

/// mps2-an386 UART0 base address.
const UART0_BASE: usize = 0x4000_4000;
/// mps2-an386 TIMER0 base address.
const TIMER0_BASE: usize = 0x4000_0000;
/// mps2-an386 TIMER1 base address.
const TIMER1_BASE: usize = 0x4000_1000;
/// The APB clock of UARTs and timers on the mps2-an386 (Hz).
const PCLK_HZ: u32 = 25_000_000;

/// Brings the board up: UART0 at 115 200 Bd, its receive interrupt feeding the receive
/// queue, TIMER0 stopped until its first period, TIMER1 running. Call once.
pub fn take() -> Result<Parts<Link, LineClock, Clock>, BoardError> {
    // The same guard as a HAL's `Peripherals::take`: a second call gets nothing.
    static TAKEN: AtomicBool = AtomicBool::new(false);
    if TAKEN.swap(true, Ordering::Relaxed) {
        return Err(BoardError::Taken);
    }
    // SAFETY: the guard above lets this run once, so nothing else owns UART0, TIMER0
    // or TIMER1.
    let (link, line_clock, clock) = unsafe {
        (
            Uart::uart0(LINK_BAUD).ok_or(BoardError::Taken)?,
            Timer::timer0(),
            FreeRunning::timer1(),
        )
    };
    Ok(Parts {
        link,
        line_clock,
        clock,
        timer_clock_hz: PCLK_HZ,
    })
}

mod uart_reg {
    pub const DATA: usize = 0x00;
    pub const STATE: usize = 0x04;
    pub const CTRL: usize = 0x08;
    pub const INTSTATUS: usize = 0x0C;
    pub const BAUDDIV: usize = 0x10;
    /// STATE: transmit buffer full.
    pub const STATE_TX_FULL: u32 = 1 << 0;
    /// STATE: receive buffer full.
    pub const STATE_RX_FULL: u32 = 1 << 1;
    /// CTRL: transmitter and receiver enable, receive interrupt enable.
    pub const CTRL_TX_EN: u32 = 1 << 0;
    pub const CTRL_RX_EN: u32 = 1 << 1;
    pub const CTRL_RX_INTEN: u32 = 1 << 3;
    /// STATE: receive overrun (write 1 to clear).
    pub const STATE_RX_OVERRUN: u32 = 1 << 3;
    /// INTSTATUS: receive interrupt (write 1 to clear).
    pub const INT_RX: u32 = 1 << 1;
}

/// UART0's receive interrupt on the mps2-an386 (NVIC line 0; QEMU hw/arm/mps2.c).
#[derive(Clone, Copy)]
struct Uart0Rx;

const UART0_RX_IRQ: u16 = 0;

// SAFETY: 0 is the NVIC line QEMU's mps2-an386 wires UART0's RX interrupt to.
unsafe impl cortex_m::interrupt::InterruptNumber for Uart0Rx {
    fn number(self) -> u16 {
        UART0_RX_IRQ
    }
}

/// The receive interrupt's state: UART0's receiver and the queue's producer.
static RX: rx::Handler<UartRx, Uart0Rx> = rx::Handler::new();

/// Every device interrupt. The mps2-an386 has no peripheral access crate to name its
/// vectors, so cortex-m-rt's default vector table sends them all here with their
/// number; only UART0's receive interrupt is ever unmasked. (`unsafe` because
/// cortex-m-rt asks it of a `DefaultHandler`; nothing in it is.)
#[cortex_m_rt::exception]
unsafe fn DefaultHandler(irqn: i16) {
    if irqn == UART0_RX_IRQ as i16 {
        RX.run();
    } else {
        defmt::error!("unexpected interrupt {=i16}", irqn);
        platform::exit(platform::EXIT_UNEXPECTED_INTERRUPT)
    }
}

mod timer_reg {
    pub const CTRL: usize = 0x0;
    pub const VALUE: usize = 0x4;
    pub const RELOAD: usize = 0x8;
    /// CTRL: counter enable.
    pub const CTRL_EN: u32 = 1 << 0;
}

/// A 32-bit memory-mapped register block.
struct Registers {
    base: usize,
}

impl Registers {
    fn read(&self, offset: usize) -> u32 {
        // SAFETY: `base` is a peripheral this block owns (see the constructors), and
        // `offset` one of its word-aligned registers: a volatile word read is the
        // intended access.
        unsafe { core::ptr::read_volatile((self.base + offset) as *const u32) }
    }
    fn write(&mut self, offset: usize, value: u32) {
        // SAFETY: as in `read`.
        unsafe { core::ptr::write_volatile((self.base + offset) as *mut u32, value) }
    }
}

/// A CMSDK APB UART: the loop's side (the transmitter, and the receive queue the
/// interrupt fills).
pub struct Uart {
    /// Used for DATA writes and STATE.TXFULL only; the receive registers are the
    /// interrupt's ([`UartRx`]).
    tx: Registers,
    rx: RxQueue<Uart0Rx>,
}

/// UART0's receiver, read by the receive interrupt only: DATA reads, STATE's receive
/// bits, INTSTATUS (the transmitter's DATA writes and STATE.TXFULL are the loop's; the
/// status bits are write-1-to-clear, so the two sides never undo each other's writes).
struct UartRx {
    regs: Registers,
}

impl Uart {
    /// UART0 of the mps2-an386, enabled for transmit and receive at `baud` (8N1), its
    /// receive interrupt feeding the receive queue. None if the queue was taken before.
    ///
    /// # Safety
    /// The caller must be the only owner of UART0.
    unsafe fn uart0(baud: u32) -> Option<Uart> {
        let mut tx = Registers { base: UART0_BASE };
        // The divider must be at least 16 (QEMU ignores smaller values).
        let div = (PCLK_HZ / baud.max(1)).max(16);
        tx.write(uart_reg::BAUDDIV, div);
        tx.write(
            uart_reg::CTRL,
            uart_reg::CTRL_TX_EN | uart_reg::CTRL_RX_EN | uart_reg::CTRL_RX_INTEN,
        );
        let receiver = UartRx {
            regs: Registers { base: UART0_BASE },
        };
        let rx = rx::start(&RX, receiver, Uart0Rx)?;
        Some(Uart { tx, rx })
    }
}

impl ErrorType for Uart {
    type Error = LinkError;
}

impl Read<u8> for Uart {
    fn read(&mut self) -> nb::Result<u8, LinkError> {
        self.rx.read()
    }
}

impl Write<u8> for Uart {
    fn write(&mut self, byte: u8) -> nb::Result<(), LinkError> {
        self.flush()?;
        self.tx.write(uart_reg::DATA, u32::from(byte));
        Ok(())
    }

    /// Done when the one-byte transmit buffer is empty.
    fn flush(&mut self) -> nb::Result<(), LinkError> {
        if self.tx.read(uart_reg::STATE) & uart_reg::STATE_TX_FULL == 0 {
            Ok(())
        } else {
            Err(nb::Error::WouldBlock)
        }
    }
}

impl RxWait for Uart {
    fn wait_for_rx(&mut self) {
        self.rx.wait();
    }
}

impl ErrorType for UartRx {
    type Error = ErrorKind;
}

impl Read<u8> for UartRx {
    /// The received byte; an overrun (a byte lost because the previous one was not read
    /// in time: never under QEMU, whose UART is flow-controlled) is reported once, then
    /// the byte that is there is read. The receive interrupt's status is cleared first,
    /// so a byte that arrives after this read raises it again.
    fn read(&mut self) -> nb::Result<u8, ErrorKind> {
        self.regs.write(uart_reg::INTSTATUS, uart_reg::INT_RX);
        let state = self.regs.read(uart_reg::STATE);
        if state & uart_reg::STATE_RX_OVERRUN != 0 {
            self.regs.write(uart_reg::STATE, uart_reg::STATE_RX_OVERRUN);
            return Err(nb::Error::Other(ErrorKind::Overrun));
        }
        if state & uart_reg::STATE_RX_FULL == 0 {
            return Err(nb::Error::WouldBlock);
        }
        Ok(self.regs.read(uart_reg::DATA) as u8)
    }
}

/// A CMSDK APB timer: a 32-bit down-counter on the APB clock that reloads from RELOAD
/// when it reaches zero (one period = RELOAD + 1 clock cycles).
pub struct Timer {
    regs: Registers,
}

impl Timer {
    /// TIMER0 of the mps2-an386, stopped until its first period is set.
    ///
    /// # Safety
    /// The caller must be the only owner of TIMER0 (call this once).
    unsafe fn timer0() -> Timer {
        let mut timer = Timer {
            regs: Registers { base: TIMER0_BASE },
        };
        timer.regs.write(timer_reg::CTRL, 0);
        timer
    }
}

impl ReloadRegister for Timer {
    /// Sets the period; the first one also starts the counter (a running counter with
    /// RELOAD 0 would have no period).
    fn set_reload(&mut self, value: u32) {
        self.regs.write(timer_reg::RELOAD, value);
        if self.regs.read(timer_reg::CTRL) & timer_reg::CTRL_EN == 0 {
            self.regs.write(timer_reg::CTRL, timer_reg::CTRL_EN);
        }
    }
    fn reload(&self) -> u32 {
        self.regs.read(timer_reg::RELOAD)
    }
}

/// TIMER1 counting down from 2^32 - 1 on the 25 MHz APB clock, round and round (it wraps
/// every 172 s), as a [`Monotonic`]: QEMU runs it on its virtual clock, which without
/// `-icount` follows the host's.
pub struct FreeRunning {
    regs: Registers,
    ticks: Extended,
}

impl FreeRunning {
    /// TIMER1 of the mps2-an386, started.
    ///
    /// # Safety
    /// The caller must be the only owner of TIMER1 (call this once).
    unsafe fn timer1() -> FreeRunning {
        let mut regs = Registers { base: TIMER1_BASE };
        regs.write(timer_reg::CTRL, 0);
        regs.write(timer_reg::RELOAD, u32::MAX);
        regs.write(timer_reg::VALUE, u32::MAX);
        regs.write(timer_reg::CTRL, timer_reg::CTRL_EN);
        let ticks = Extended::new(1 << 32, Self::elapsed(&regs));
        FreeRunning { regs, ticks }
    }

    /// Ticks since the count started, modulo 2^32 (the counter counts down).
    fn elapsed(regs: &Registers) -> u32 {
        !regs.read(timer_reg::VALUE)
    }
}

impl Monotonic for FreeRunning {
    fn now_us(&mut self) -> u64 {
        let ticks = self.ticks.update(Self::elapsed(&self.regs));
        ticks / u64::from(PCLK_HZ / 1_000_000)
    }
}
