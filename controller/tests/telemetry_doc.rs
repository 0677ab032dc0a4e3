//! The wire figures docs/telemetry.md states, tied to the constants and to what the
//! decoder does (issue 25, item 3: the page still named version 1's sync bytes and a
//! partial frame of an older payload limit).

use controller::frame::{
    encode, kind, Decoder, Event, FrameError, MAX_FRAME, MAX_PAYLOAD, SYNC, VERSION,
};

const DOC: &str = include_str!("../../docs/telemetry.md");

/// The page, its lines joined (a figure may be wrapped over two lines).
fn doc() -> String {
    DOC.split_whitespace().collect::<Vec<_>>().join(" ")
}

#[test]
fn the_truncated_rule_names_this_versions_sync_bytes() {
    let marker = format!("`{:02X} {:02X} {:02X}`", SYNC[0], SYNC[1], VERSION);
    let doc = doc();
    assert!(
        doc.contains(&format!(
            "A failed CRC whose span contains another {marker} "
        )),
        "docs/telemetry.md does not name {marker} in the truncated rule"
    );
    // No other version's sync bytes anywhere on the page.
    for v in (0..=u8::MAX).filter(|&v| v != VERSION) {
        let other = format!("`{:02X} {:02X} {:02X}`", SYNC[0], SYNC[1], v);
        assert!(!doc.contains(&other), "docs/telemetry.md names {other}");
    }
    assert!(doc.contains(&format!("| 2 | 1 | version, {VERSION} ")));
    assert!(doc.contains(&format!("payload length L, at most {MAX_PAYLOAD} ")));
    assert!(doc.contains(&format!("length field over {MAX_PAYLOAD} ")));
}

/// The rule itself: a frame cut short by the next one (whose sync and version lie in the
/// cut frame's span) is `truncated`; the same frame damaged in place is `bad_crc`.
#[test]
fn a_cut_frame_is_truncated_and_a_damaged_one_bad_crc() {
    let mut a = [0u8; MAX_FRAME];
    let n = encode(kind::TIME, 1, 1_000, &[], &mut a).unwrap();
    let mut b = [0u8; MAX_FRAME];
    let m = encode(kind::NAV, 2, 2_000, &[0x11; 72], &mut b).unwrap();
    let verdicts = |bytes: &[u8]| {
        let mut v = Vec::new();
        Decoder::new().feed(bytes, |e| {
            if let Event::Rejected(r) = e {
                v.push(r)
            }
        });
        v
    };
    // NAV cut after 10 bytes, then a whole NAV.
    let cut: Vec<u8> = b[..10].iter().chain(&b[..m]).copied().collect();
    assert_eq!(verdicts(&cut)[0], FrameError::Truncated);
    // NAV with a payload byte flipped, then a TIME frame.
    let mut damaged: Vec<u8> = b[..m].to_vec();
    damaged[30] ^= 0x40;
    damaged.extend_from_slice(&a[..n]);
    assert_eq!(verdicts(&damaged)[0], FrameError::BadCrc);
}

/// The decoder never holds more than one frame less a byte: the figure the "Counters"
/// table gives.
#[test]
fn the_decoder_holds_at_most_the_documented_partial_frame() {
    let largest = MAX_FRAME - 1;
    let doc = doc();
    assert!(
        doc.contains(&format!("holds at most one partial frame ({largest} bytes")),
        "docs/telemetry.md's partial frame is not {largest} bytes"
    );
    // A largest frame, fed byte by byte: held until its last byte, then delivered.
    let mut f = [0u8; MAX_FRAME];
    let n = encode(0x7E, 1, 1_000, &[0x5A; MAX_PAYLOAD], &mut f).unwrap();
    assert_eq!(n, MAX_FRAME);
    let mut d = Decoder::new();
    let mut most = 0;
    let mut frames = 0;
    for &byte in &f[..n] {
        d.feed(&[byte], |e| {
            if let Event::Frame(_) = e {
                frames += 1;
            }
        });
        most = most.max(d.buffered());
    }
    assert_eq!((most, frames, d.buffered()), (largest, 1, 0));
}
