//! The state an interrupt handler owns, in a static: empty until the loop installs it at
//! start-up, then serviced by the handler each time it runs. Behind a
//! `critical_section::Mutex`, so no `static mut`; the receive ([`crate::rx`]) and the
//! transmit ([`crate::tx`]) sides each keep one per board.

use core::cell::RefCell;

use critical_section::Mutex;

/// What an interrupt does each time it runs.
pub trait Service {
    fn service(&mut self);
}

/// A board's interrupt state, for a static.
pub struct Handler<S>(Mutex<RefCell<Option<S>>>);

impl<S: Service> Handler<S> {
    pub const fn new() -> Self {
        Handler(Mutex::new(RefCell::new(None)))
    }

    /// The interrupt handler's body: services the state, if installed.
    pub fn run(&self) {
        critical_section::with(|cs| {
            if let Ok(mut state) = self.0.borrow(cs).try_borrow_mut() {
                if let Some(state) = state.as_mut() {
                    state.service();
                }
            }
        });
    }

    /// Installs `state`; `None` if the handler is running (it cannot be: the line is
    /// unmasked after this).
    pub(crate) fn install(&self, state: S) -> Option<()> {
        critical_section::with(|cs| {
            *self.0.borrow(cs).try_borrow_mut().ok()? = Some(state);
            Some(())
        })
    }
}

impl<S: Service> Default for Handler<S> {
    fn default() -> Self {
        Self::new()
    }
}
