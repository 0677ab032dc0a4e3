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
