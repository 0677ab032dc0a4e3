//! CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF, no reflection, no final XOR): the CRC
//! of CCSDS transfer frames. Check value: crc16(b"123456789") = 0x29B1.

/// Half a byte at a time from a 16-entry table: 32 bytes of flash instead of a byte
/// table's 512, for twice the steps over a frame (at most a few hundred bytes).
const TABLE: [u16; 16] = {
    let mut t = [0u16; 16];
    let mut i = 0;
    while i < 16 {
        let mut c = (i as u16) << 12;
        let mut k = 0;
        while k < 4 {
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
        crc = (crc << 4) ^ TABLE[usize::from((crc >> 12) ^ u16::from(b >> 4))];
        crc = (crc << 4) ^ TABLE[usize::from((crc >> 12) ^ u16::from(b & 15))];
    }
    crc
}

pub const INIT: u16 = 0xFFFF;

pub fn crc16(bytes: &[u8]) -> u16 {
    update(INIT, bytes)
}

/// CRC-32 (IEEE 802.3, as zlib's `crc32`: reflected poly 0xEDB88320, init and final
/// XOR 0xFFFFFFFF) for a whole DEM tile (`crate::dem`): at 32 KiB a CRC-16 would pass one
/// corrupted tile in 65 536. Check value: crc32(b"123456789") = 0xCBF43926. Half a byte
/// at a time from a 16-entry table: 64 bytes of flash instead of a byte table's 1 KiB,
/// for twice the steps over the 448 bytes of a chunk.
const TABLE32: [u32; 16] = {
    let mut t = [0u32; 16];
    let mut i = 0;
    while i < 16 {
        let mut c = i as u32;
        let mut k = 0;
        while k < 4 {
            c = if c & 1 != 0 {
                (c >> 1) ^ 0xEDB8_8320
            } else {
                c >> 1
            };
            k += 1;
        }
        t[i] = c;
        i += 1;
    }
    t
};

/// The CRC-32 register after `bytes`, from `crc` ([`INIT32`] for a new message; the
/// CRC is the register's complement, [`finish32`]).
#[inline(never)]
pub fn update32(mut crc: u32, bytes: &[u8]) -> u32 {
    for &b in bytes {
        crc ^= u32::from(b);
        crc = (crc >> 4) ^ TABLE32[(crc & 15) as usize];
        crc = (crc >> 4) ^ TABLE32[(crc & 15) as usize];
    }
    crc
}

pub const INIT32: u32 = 0xFFFF_FFFF;

/// The CRC-32 of a message whose register is `crc`.
pub const fn finish32(crc: u32) -> u32 {
    !crc
}

pub fn crc32(bytes: &[u8]) -> u32 {
    finish32(update32(INIT32, bytes))
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use core_math::sample::SplitMix64;

    /// The CRC-16 by its definition, one bit at a time: the message's bits, most
    /// significant first, shifted through the register with the polynomial 0x1021.
    fn crc16_bitwise(bytes: &[u8]) -> u16 {
        let mut c = INIT;
        for &b in bytes {
            for k in (0..8).rev() {
                let top = (c >> 15) ^ u16::from((b >> k) & 1);
                c <<= 1;
                if top != 0 {
                    c ^= 0x1021;
                }
            }
        }
        c
    }

    /// The table's CRC against the bitwise definition over random messages of every
    /// length to 300 bytes, and the standard check value.
    #[test]
    fn crc16_matches_its_definition() {
        assert_eq!(crc16(b"123456789"), 0x29B1);
        assert_eq!(crc16_bitwise(b"123456789"), 0x29B1);
        let mut rng = SplitMix64(0xC2C1_6000_2026_1127);
        let mut buf = [0u8; 300];
        for len in 0..buf.len() {
            for _ in 0..20 {
                for b in buf.iter_mut().take(len) {
                    *b = rng.next_u64() as u8;
                }
                let msg = &buf[..len];
                assert_eq!(crc16(msg), crc16_bitwise(msg), "{msg:?}");
                // Split anywhere, the running state gives the same CRC.
                let cut = len / 3;
                assert_eq!(update(update(INIT, &msg[..cut]), &msg[cut..]), crc16(msg));
            }
        }
    }
}
