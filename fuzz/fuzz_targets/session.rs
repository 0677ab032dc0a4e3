//! `Session` against the reference model of the link's documented behaviour (the same
//! model as `controller/tests/session_model.rs`): every 25 bytes of input are one
//! action (a selector and three numbers: valid NAV, TIME, SCENE edits, ticks, time tags
//! backwards, too far ahead, past the largest tag, re-synchronisations, unknown kinds,
//! bit flips, cut frames, noise, bad versions and lengths, DEM uploads and their
//! faults), run through a real `Session` byte by byte; after each action the model's
//! invariants are asserted (a
//! refused input changes nothing and counts exactly its counter, an accepted frame
//! takes effect, the counters reconcile, every period written is inside the physical
//! bounds, every MTF in [0, 1]), and at the end an END frame's final STATUS must
//! reconcile with everything sent. Any divergence panics.
#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "../../controller/tests/model/mod.rs"]
mod model;

use model::{Action, Harness};

/// Bytes per action, and the most actions per input (longer inputs are cut).
const ACTION_LEN: usize = 25;
const MAX_ACTIONS: usize = 64;

fn u64_at(b: &[u8], at: usize) -> u64 {
    let mut a = [0u8; 8];
    a.copy_from_slice(&b[at..at + 8]);
    u64::from_le_bytes(a)
}

fuzz_target!(|data: &[u8]| {
    // A fresh controller per input (it is not `Clone`: it borrows its DEM tile memory,
    // which the harness lends from a pool).
    let mut h = Harness::with(
        controller::Controller::new(
            controller::Config::default(),
            controller::Scene::paper_default(),
        )
        .expect("the default scene"),
    );
    for chunk in data.chunks_exact(ACTION_LEN).take(MAX_ACTIONS) {
        let a = Action::decode(
            chunk[0],
            u64_at(chunk, 1),
            u64_at(chunk, 9),
            u64_at(chunk, 17),
        );
        h.step(&a);
    }
    h.finish();
});
