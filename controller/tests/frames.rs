//! The frame codec: CRC check value, round trips, and recovery from every kind of damage.

use controller::crc::crc16;
use controller::frame::{encode, kind, Decoder, Event, FrameError, MAX_FRAME, MAX_PAYLOAD};
use proptest::prelude::*;

#[derive(Debug, PartialEq, Eq)]
enum Got {
    Frame(u8, u16, u64, Vec<u8>),
    Rejected(FrameError),
}

fn decode_all(chunks: &[&[u8]]) -> Vec<Got> {
    let mut d = Decoder::new();
    let mut out = Vec::new();
    for c in chunks {
        d.feed(c, |e| {
            out.push(match e {
                Event::Frame(f) => Got::Frame(f.kind, f.sequence, f.time_us, f.payload.to_vec()),
                Event::Rejected(r) => Got::Rejected(r),
            })
        });
    }
    out
}

fn frame(seq: u16, payload: &[u8]) -> Vec<u8> {
    let mut buf = [0u8; MAX_FRAME];
    let n = encode(kind::NAV, seq, 1_000 + u64::from(seq), payload, &mut buf).unwrap();
    buf[..n].to_vec()
}

#[test]
fn crc_check_value() {
    // The standard check value of CRC-16/CCITT-FALSE.
    assert_eq!(crc16(b"123456789"), 0x29B1);
}

#[test]
fn round_trip_in_any_chunking() {
    let stream: Vec<u8> = [
        frame(1, b"abc"),
        frame(2, &[]),
        frame(3, &[0xEB, 0x90, 1, 2]),
    ]
    .concat();
    let whole = decode_all(&[&stream]);
    assert_eq!(whole.len(), 3);
    assert_eq!(whole[0], Got::Frame(kind::NAV, 1, 1_001, b"abc".to_vec()));
    assert_eq!(
        whole[2],
        Got::Frame(kind::NAV, 3, 1_003, vec![0xEB, 0x90, 1, 2])
    );
    let bytes: Vec<&[u8]> = stream.chunks(1).collect();
    assert_eq!(decode_all(&bytes), whole);
}

#[test]
fn damage_costs_the_damaged_frame_only() {
    let (a, b, c) = (frame(1, b"first"), frame(2, b"second"), frame(3, b"third"));
    // A flipped bit in the payload.
    let mut bad = b.clone();
    bad[18] ^= 0x10;
    let got = decode_all(&[&[a.clone(), bad, c.clone()].concat()]);
    assert_eq!(got.len(), 3);
    assert_eq!(got[1], Got::Rejected(FrameError::BadCrc));
    assert!(matches!(got[2], Got::Frame(_, 3, _, _)));
    // A frame cut short, then a good one.
    let cut = &b[..b.len() - 5];
    let got = decode_all(&[&[a.clone(), cut.to_vec(), c.clone()].concat()]);
    assert_eq!(got[0], Got::Frame(kind::NAV, 1, 1_001, b"first".to_vec()));
    assert_eq!(got[1], Got::Rejected(FrameError::Truncated));
    assert!(matches!(got[2], Got::Frame(_, 3, _, _)), "{got:?}");
    // Noise between frames is skipped without a rejection.
    let got = decode_all(&[&[a.clone(), vec![0, 1, 0xEB, 7, 0x55], c.clone()].concat()]);
    assert_eq!(got.len(), 2);
    // Unknown version and oversized length.
    let mut v2 = b.clone();
    v2[2] = controller::frame::VERSION + 1;
    let mut big = b.clone();
    big[4..6].copy_from_slice(&((MAX_PAYLOAD + 1) as u16).to_le_bytes());
    let got = decode_all(&[&[v2, big, c].concat()]);
    assert_eq!(got[0], Got::Rejected(FrameError::UnknownVersion));
    assert_eq!(got[1], Got::Rejected(FrameError::Oversized));
    assert!(matches!(got[2], Got::Frame(_, 3, _, _)));
}

proptest! {
    /// Any bytes at all: no panic, and good frames appended after them still arrive.
    #[test]
    fn survives_any_bytes(noise in proptest::collection::vec(any::<u8>(), 0..2000), chunk in 1usize..64) {
        let tail = frame(77, b"after the noise");
        let mut stream = noise.clone();
        // Close any frame the noise may have opened, so the tail starts clean.
        stream.extend(std::iter::repeat_n(0u8, MAX_FRAME));
        stream.extend(&tail);
        let chunks: Vec<&[u8]> = stream.chunks(chunk).collect();
        let got = decode_all(&chunks);
        prop_assert_eq!(got.last(), Some(&Got::Frame(kind::NAV, 77, 1_077, b"after the noise".to_vec())));
    }
}
