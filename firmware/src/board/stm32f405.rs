//! Board `stm32f405`: an STM32F405RG (Cortex-M4F) through `stm32f4xx-hal`. Runs on
//! QEMU's `netduinoplus2` (an STM32F405RG) and is the route to a real board through
//! probe-rs (docs/target.md, "Boards" and "A real board").
//!
//! - Clock: the internal 16 MHz HSI as reset leaves it (`RCC.constrain()`). QEMU models
//!   no HSE or PLL (asking for them waits forever for a ready bit); a flight build would
//!   run the PLL from a crystal so that a timer counts the scene's 10 MHz line clock
//!   exactly.
//! - Link: USART1 on PA9 (TX) and PA10 (RX), 115 200 Bd 8N1, through the HAL's
//!   `embedded-hal-nb` serial port, split: USART1's interrupt reads the receiver (RXNE)
//!   into the queue of [`crate::rx`] and writes the transmitter (TXE, enabled only while
//!   bytes wait) from the queue of [`crate::tx`]; the loop takes received bytes from the
//!   one and puts whole frames in the other.
//! - Line clock: TIM2 (32-bit) counting the timer clock (PSC 0), segment 0's period in
//!   its auto-reload register with preload (ARPE), so a new period starts at the end of
//!   the current line, never in the middle of one.
//! - Clock: TIM5 (32-bit) as the HAL's 1 MHz counter, free-running.
//! - Watchdog: the IWDG on the 32 kHz LSI, through the HAL; the reset cause from
//!   RCC_CSR's flags (cleared at each boot). QEMU 7.2 models neither (the IWDG and RCC
//!   are unimplemented devices there: writes ignored, reads 0, so no reset and no
//!   flags); on the mps2 QEMU models the watchdog (docs/target.md, "Faults and resets").
//!
//! Under QEMU the USART is flow-controlled like the mps2's UART (the host's next byte
//! waits until DR has been read) but drops bytes that arrive before it is enabled, which
//! is why the firmware announces that the link is ready and the pass player waits for
//! that line. QEMU's timers count a nominal 1 GHz divided by PSC + 1 whatever the clock
//! tree: ARR and PSC write and read back (the register path), the rates do not match
//! the HSI's (the TIM5 "microseconds" run 62.5 times fast).

use embedded_hal_nb::serial::{Error as _, ErrorType, Write};
use stm32f4xx_hal::pac::{self, interrupt, Interrupt};
use stm32f4xx_hal::prelude::*;
use stm32f4xx_hal::serial::{Event, Rx, Serial, Tx, TxListen};
use stm32f4xx_hal::timer::{CounterUs, Timer};
use stm32f4xx_hal::watchdog::IndependentWatchdog;
use stm32f4xx_hal::Listen;

use super::{BoardError, Extended, Monotonic, Parts, LINK_BAUD, WATCHDOG_TIMEOUT_MS};
use crate::line_clock::ReloadRegister;
use crate::link::{LinkError, QueuedLink};
use crate::retained::ResetCause;
use crate::rx;
use crate::tx::{self, TxPort};

/// The board's name (the cargo feature).
pub const NAME: &str = "stm32f405";
/// The telemetry link's peripheral.
pub const LINK: &str = "USART1";
/// The board's telemetry link, segment 0's line clock and clock.
pub type Link = Usart1;
pub type LineClock = Tim2Reload;
pub type Clock = Tim5Clock;
pub type Watchdog = Iwdg;

/// The receive interrupt's state: USART1's receiver and the queue's producer.
static RX: rx::Handler<Rx<pac::USART1, u8>, Interrupt> = rx::Handler::new();
/// The transmit interrupt's state: USART1's transmitter and the queue's consumer.
static TX: tx::Handler<Usart1Tx> = tx::Handler::new();

/// USART1's one interrupt, for both directions. The receive side masks the line while its
/// queue is full (`rx`), which holds the transmitter back too until the loop takes the
/// next byte (`tx::TxQueue::wait_for_room`).
#[interrupt]
fn USART1() {
    RX.run();
    TX.run();
}

/// Brings the board up: HSI clocks, USART1 at 115 200 Bd, its interrupt feeding the
/// receive queue and draining the transmit queue, TIM2 stopped until its first period,
/// TIM5 counting, the IWDG started. Call once.
pub fn take() -> Result<Parts<Link, LineClock, Clock, Watchdog>, BoardError> {
    let dp = pac::Peripherals::take().ok_or(BoardError::Taken)?;
    let reset_cause = reset_cause(&dp.RCC);
    // The clocks as reset leaves them: HSI 16 MHz, every bus undivided (`freeze` would
    // compute the same from `Config::hsi()`, through PLL set-up code that can panic).
    let mut rcc = dp.RCC.constrain();
    let gpioa = dp.GPIOA.split(&mut rcc);
    let mut serial: Serial<pac::USART1, u8> = dp
        .USART1
        .serial(
            (gpioa.pa9, gpioa.pa10),
            stm32f4xx_hal::serial::Config::default().baudrate(LINK_BAUD.bps()),
            &mut rcc,
        )
        .map_err(|_| BoardError::SerialConfig)?;
    serial.listen(Event::RxNotEmpty);
    let (transmitter, receiver) = serial.split();
    let rx = rx::start(&RX, receiver, Interrupt::USART1).ok_or(BoardError::Taken)?;
    let tx = tx::start(&TX, Usart1Tx(transmitter), Interrupt::USART1).ok_or(BoardError::Taken)?;

    let timer_clock_hz = rcc.clocks.timclk1().raw();
    let tim2 = Timer::new(dp.TIM2, &mut rcc).release();
    // Prescaler 0: count every timer clock tick.
    tim2.psc().write(|w| w.psc().set(0));
    tim2.cr1().modify(|_, w| w.arpe().set_bit());

    let mut tim5 = dp.TIM5.counter_us(&mut rcc);
    // The longest period the HAL allows, 2^32 - 1 ticks: the counter wraps after that.
    tim5.start(u32::MAX.micros())
        .map_err(|_| BoardError::TimerConfig)?;
    let ticks = Extended::new(u64::from(u32::MAX), tim5.now().ticks());
    let core_clock_hz = rcc.clocks.sysclk().raw();

    let mut iwdg = IndependentWatchdog::new(dp.IWDG);
    iwdg.start(WATCHDOG_TIMEOUT_MS.millis());

    Ok(Parts {
        link: QueuedLink::new(rx, tx),
        line_clock: Tim2Reload { tim: tim2 },
        clock: Tim5Clock {
            counter: tim5,
            ticks,
        },
        watchdog: Iwdg(iwdg),
        reset_cause,
        core_clock_hz,
        timer_clock_hz,
    })
}

/// The last reset's cause from RCC_CSR's flags, which are then cleared so that the next
/// reset's stand alone. None if no flag is set (QEMU, which does not model them).
fn reset_cause(rcc: &pac::RCC) -> Option<ResetCause> {
    let csr = rcc.csr().read();
    let cause = if csr.porrstf().bit_is_set() || csr.borrstf().bit_is_set() {
        Some(ResetCause::PowerOn)
    } else if csr.wdgrstf().bit_is_set() || csr.wwdgrstf().bit_is_set() {
        Some(ResetCause::Watchdog)
    } else if csr.sftrstf().bit_is_set() {
        Some(ResetCause::Software)
    } else if csr.padrstf().bit_is_set() || csr.lpwrrstf().bit_is_set() {
        Some(ResetCause::Unknown)
    } else {
        None
    };
    rcc.csr().modify(|_, w| w.rmvf().set_bit());
    cause
}

/// The IWDG, started by [`take`].
pub struct Iwdg(IndependentWatchdog);

impl super::Watchdog for Iwdg {
    fn feed(&mut self) {
        self.0.feed();
    }
}

/// USART1, the loop's side: the receive queue the interrupt fills and the transmit queue
/// it drains.
pub type Usart1 = QueuedLink<Interrupt, Interrupt>;

/// USART1's transmitter, the HAL's, written by the interrupt only.
pub struct Usart1Tx(Tx<pac::USART1, u8>);

impl ErrorType for Usart1Tx {
    type Error = LinkError;
}

impl Write<u8> for Usart1Tx {
    fn write(&mut self, byte: u8) -> nb::Result<(), LinkError> {
        self.0
            .write(byte)
            .map_err(|e| e.map(|e| LinkError::from_kind(e.kind())))
    }
    /// Done when the last byte has left the shift register (TC).
    fn flush(&mut self) -> nb::Result<(), LinkError> {
        self.0
            .flush()
            .map_err(|e| e.map(|e| LinkError::from_kind(e.kind())))
    }
}

impl TxPort for Usart1Tx {
    /// TXE is a level (the data register is empty), so its interrupt is enabled only
    /// while bytes wait or the last one is still leaving (one character time).
    fn interrupt(&mut self, on: bool) {
        if on {
            TxListen::listen(&mut self.0);
        } else {
            TxListen::unlisten(&mut self.0);
        }
    }
}

/// TIM2's auto-reload register: segment 0's line period.
pub struct Tim2Reload {
    tim: pac::TIM2,
}

impl ReloadRegister for Tim2Reload {
    /// Sets the period; the first one also loads it at once (update event) and starts
    /// the counter. Later ones wait in the preload register for the current period's end.
    fn set_reload(&mut self, value: u32) {
        // TIM2's ARR field is 32 bits wide: it takes any value.
        self.tim.arr().write(|w| w.arr().set(value));
        if self.tim.cr1().read().cen().bit_is_clear() {
            self.tim.egr().write(|w| w.ug().set_bit());
            self.tim.cr1().modify(|_, w| w.cen().set_bit());
        }
    }
    fn reload(&self) -> u32 {
        self.tim.arr().read().arr().bits()
    }
}

/// TIM5 counting microseconds (the HAL's 1 MHz counter), as a [`Monotonic`]. It wraps
/// every 71.6 minutes.
pub struct Tim5Clock {
    counter: CounterUs<pac::TIM5>,
    ticks: Extended,
}

impl Monotonic for Tim5Clock {
    // Out of line: the loop reads the clock in several places, and inlined each was a
    // copy of the 64-bit extension (docs/target.md, flash).
    #[inline(never)]
    fn now_us(&mut self) -> u64 {
        self.ticks.update(self.counter.now().ticks())
    }
}
