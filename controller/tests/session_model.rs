//! The stateful model test of `Session` (issue 13): random interleavings of valid
//! frames, damaged frames, noise, time jumps, re-synchronisations and scene changes,
//! checked after every action against the reference model in `tests/model/mod.rs`
//! (the documented behaviour of docs/telemetry.md): a refused input changes neither
//! the state, nor the scene, nor the periods, and increments exactly its counter; an
//! accepted frame takes effect; the counters reconcile; the next good frame after any
//! fault is accepted. The `session` fuzz target runs the same model.

mod model;

use model::{Action, Harness};
use proptest::prelude::*;

/// Enough to find each of the defects of issue 13 on the code before its fix (each
/// found within the first few cases; see docs/fuzzing.md), and to run in a few
/// seconds in `cargo test --release`.
const CASES: u32 = 4096;

fn actions() -> impl Strategy<Value = Vec<Action>> {
    proptest::collection::vec(
        (any::<u8>(), any::<u64>(), any::<u64>(), any::<u64>())
            .prop_map(|(sel, a, b, c)| Action::decode(sel, a, b, c)),
        1..60,
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: CASES, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn session_follows_the_model(actions in actions()) {
        let mut h = Harness::new();
        for a in &actions {
            h.step(a);
        }
        h.finish();
    }
}
