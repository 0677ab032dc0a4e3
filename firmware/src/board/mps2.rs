//! Boards `mps2-an386` (the default) and `mps2-an385`: QEMU's `-machine mps2-an386`, a
//! Cortex-M4 with FPU, and `-machine mps2-an385`, a Cortex-M3 without one. Both FPGA
//! images put the Cortex-M System Design Kit's APB peripherals at the same fixed
//! addresses, on the same interrupt lines and APB clock (QEMU hw/arm/mps2.c, which
//! builds both from one code path; ARM AN385 and AN386), so only the core and the
//! board's name differ. No HAL or
//! peripheral access crate exists for it: the peripherals are driven through the
//! register blocks and drivers of [`cmsdk`](super::cmsdk). UART0 is the telemetry link;
//! TIMER0 stands in for segment 0's line clock; TIMER1, free-running, is the
//! [`Monotonic`](super::Monotonic) clock. This module holds only what is the board's
//! own: the addresses, the interrupt line, the APB clock and the wiring (QEMU
//! hw/arm/mps2.c).

use core::sync::atomic::{AtomicBool, Ordering};

use super::cmsdk::{self, start_uart, FreeRunning, Timer, UartRx, UartTx};
use super::{BoardError, Parts, LINK_BAUD, WATCHDOG_TIMEOUT_MS};
use crate::link::QueuedLink;
use crate::platform;
use crate::retained::{self, ResetCause};
use crate::{rx, tx};

/// The board's name (the cargo feature).
#[cfg(feature = "mps2-an386")]
pub const NAME: &str = "mps2-an386";
/// The board's name (the cargo feature).
#[cfg(feature = "mps2-an385")]
pub const NAME: &str = "mps2-an385";
/// The telemetry link's peripheral.
pub const LINK: &str = "UART0";
/// The board's telemetry link, segment 0's line clock and clock.
pub type Link = QueuedLink<Uart0Rx, Uart0Tx>;
pub type LineClock = Timer<TIMER0_BASE>;
pub type Clock = FreeRunning<TIMER1_BASE, PCLK_HZ>;
pub type Watchdog = cmsdk::Watchdog<WATCHDOG_BASE>;

/// UART0's base address: a CMSDK APB UART.
const UART0_BASE: usize = 0x4000_4000;
/// TIMER0's base address: a CMSDK APB timer.
const TIMER0_BASE: usize = 0x4000_0000;
/// TIMER1's base address: a CMSDK APB timer.
const TIMER1_BASE: usize = 0x4000_1000;
/// The watchdog's base address: a CMSDK APB watchdog, its interrupt wired to the NMI.
const WATCHDOG_BASE: usize = 0x4000_8000;
/// The APB clock of the UARTs, timers and watchdog, and the core's clock (Hz). TIMER1 at this rate wraps every
/// 2^32 / 25 MHz = 172 s.
const PCLK_HZ: u32 = 25_000_000;

/// Brings the board up: UART0 at 115 200 Bd, its receive interrupt feeding the receive
/// queue and its transmit interrupt draining the transmit queue, TIMER0 stopped until
/// its first period, TIMER1 running, the watchdog started. Call once.
pub fn take() -> Result<Parts<Link, LineClock, Clock, Watchdog>, BoardError> {
    // The same guard as a HAL's `Peripherals::take`: a second call gets nothing.
    static TAKEN: AtomicBool = AtomicBool::new(false);
    if TAKEN.swap(true, Ordering::Relaxed) {
        return Err(BoardError::Taken);
    }
    // Half the time-out to the early warning (the NMI, which resets at once), the other
    // half to the watchdog's own reset if the NMI handler cannot run.
    let half_timeout_ticks = PCLK_HZ / 1000 * (WATCHDOG_TIMEOUT_MS / 2);
    // SAFETY: the addresses are those of a CMSDK APB UART, two CMSDK APB timers and the
    // CMSDK APB watchdog on this machine, and the guard above lets this run once, so
    // nothing else owns them; the watchdog's NMI handler is below.
    let (link, line_clock, clock, watchdog) = unsafe {
        (
            start_uart::<UART0_BASE, _, _>(PCLK_HZ, LINK_BAUD, (&RX, Uart0Rx), (&TX, Uart0Tx))
                .ok_or(BoardError::Taken)?,
            LineClock::stopped(),
            Clock::start(),
            Watchdog::start(half_timeout_ticks),
        )
    };
    Ok(Parts {
        link,
        line_clock,
        clock,
        watchdog,
        // The MPS2's system control keeps no reset flags that QEMU models: the record in
        // retained RAM tells.
        reset_cause: None,
        core_clock_hz: PCLK_HZ,
        timer_clock_hz: PCLK_HZ,
    })
}

/// UART0's receive interrupt on the MPS2 (NVIC line 0; QEMU hw/arm/mps2.c).
#[derive(Clone, Copy)]
pub struct Uart0Rx;

const UART0_RX_IRQ: u16 = 0;

// SAFETY: 0 is the NVIC line QEMU's mps2-an385 and mps2-an386 wire UART0's RX interrupt to.
unsafe impl cortex_m::interrupt::InterruptNumber for Uart0Rx {
    fn number(self) -> u16 {
        UART0_RX_IRQ
    }
}

/// UART0's transmit interrupt on the MPS2 (NVIC line 1: each UART's TX line is
/// its RX line + 1; QEMU hw/arm/mps2.c).
#[derive(Clone, Copy)]
pub struct Uart0Tx;

const UART0_TX_IRQ: u16 = 1;

// SAFETY: 1 is the NVIC line QEMU's mps2-an385 and mps2-an386 wire UART0's TX interrupt to.
unsafe impl cortex_m::interrupt::InterruptNumber for Uart0Tx {
    fn number(self) -> u16 {
        UART0_TX_IRQ
    }
}

/// The receive interrupt's state: UART0's receiver and the queue's producer.
static RX: rx::Handler<UartRx<UART0_BASE>, Uart0Rx> = rx::Handler::new();
/// The transmit interrupt's state: UART0's transmitter and the queue's consumer.
static TX: tx::Handler<UartTx<UART0_BASE>> = tx::Handler::new();

/// The watchdog's early warning: the loop has not fed it for half the time-out. The
/// core is reset now rather than at the watchdog's second time-out, the cause noted for
/// the next boot (`crate::retained`). (`unsafe` because cortex-m-rt asks it of an NMI
/// handler, which nothing can mask; this one touches only the retained record.)
#[cortex_m_rt::exception]
unsafe fn NonMaskableInt() {
    retained::note_cause(ResetCause::Watchdog);
    cortex_m::peripheral::SCB::sys_reset()
}

/// The number of device interrupt lines of the board's NVIC (QEMU 7.2: `info qtree`
/// gives the `armv7m_nvic` of both machines `num-irq = 48`).
const NVIC_LINES: usize = 48;

extern "C" {
    /// cortex-m-rt's name for the handler below.
    fn DefaultHandler();
}

/// The device part of the vector table, one entry per NVIC line, all to
/// [`DefaultHandler`] (cortex-m-rt's feature `device`, which the board features enable,
/// takes it from here): without it cortex-m-rt puts 240, 768 bytes of flash more for
/// lines this board does not have (docs/target.md, flash).
#[link_section = ".vector_table.interrupts"]
#[no_mangle]
#[used]
static __INTERRUPTS: [unsafe extern "C" fn(); NVIC_LINES] = [DefaultHandler; NVIC_LINES];

/// Every device interrupt. The MPS2 has no peripheral access crate to name its
/// vectors, so the vector table above sends them all here with their number; only
/// UART0's receive and transmit interrupts are ever unmasked. (`unsafe` because
/// cortex-m-rt asks it of a `DefaultHandler`; nothing in it is.)
#[cortex_m_rt::exception]
unsafe fn DefaultHandler(irqn: i16) {
    if irqn == UART0_RX_IRQ as i16 {
        RX.run();
    } else if irqn == UART0_TX_IRQ as i16 {
        TX.run();
    } else {
        defmt::error!("unexpected interrupt {=i16}", irqn);
        platform::exit(platform::EXIT_UNEXPECTED_INTERRUPT)
    }
}
