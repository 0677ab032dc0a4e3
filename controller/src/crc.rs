//! CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF, no reflection, no final XOR): the CRC
//! of CCSDS transfer frames. Check value: crc16(b"123456789") = 0x29B1.

/// Table for one byte at a time, built at compile time (512 bytes of flash).
const TABLE: [u16; 256] = {
    let mut t = [0u16; 256];
    let mut i = 0;
    while i < 256 {
        let mut c = (i as u16) << 8;
        let mut k = 0;
        while k < 8 {
            c = if c & 0x8000 != 0 {
                (c << 1) ^ 0x1021
            } else {
                c << 1
            };
            k += 1;
        }
        t[i] = c;
        i += 1;
    }
    t
};

/// The CRC state after `bytes`, starting from `crc` (use [`INIT`] for a new message).
/// Out of line: the frame decoder, the encoders and the retained record's checks all
/// call it, and inlined (its loop unrolled) it came to five copies in the flight binary.
#[inline(never)]
pub fn update(mut crc: u16, bytes: &[u8]) -> u16 {
    for &b in bytes {
        crc = (crc << 8) ^ TABLE[usize::from((crc >> 8) as u8 ^ b)];
    }
    crc
}

pub const INIT: u16 = 0xFFFF;

pub fn crc16(bytes: &[u8]) -> u16 {
    update(INIT, bytes)
}
