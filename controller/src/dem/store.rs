//! The DEM tile memory: two slots and the sealed record of the tile in force, laid
//! out so that RAM kept across a reset can hold it (any contents are a valid value,
//! checked by the seal before use).

use core_math::earth::dem::DemGrid;

use super::DEM_MAX_NODES;
use crate::crc;

/// The record of the tile in force, in the store. Only `u32`s and `u64`s: any contents
/// (RAM after power-on) are a valid value, checked by its seal before use.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct Record {
    pub(super) magic: u32,
    /// The slot holding the tile in force (0 or 1).
    pub(super) slot: u32,
    pub(super) id: u32,
    pub(super) crc32: u32,
    pub(super) rows: u32,
    pub(super) cols: u32,
    /// lat0, lon0, dlat, dlon (deg, f64 bits).
    pub(super) angles: [u64; 4],
    /// CRC-32 of the fields above.
    pub(super) seal: u32,
    pub(super) reserved: u32,
}

pub(super) const MAGIC: u32 = 0x4D45_4454; // "TDEM"

impl Record {
    pub(super) fn seal_of(&self) -> u32 {
        let mut c = crc::INIT32;
        for w in [
            self.magic, self.slot, self.id, self.crc32, self.rows, self.cols,
        ] {
            c = crc::update32(c, &w.to_le_bytes());
        }
        for a in self.angles {
            c = crc::update32(c, &a.to_le_bytes());
        }
        crc::finish32(c)
    }

    pub(super) fn grid(&self) -> DemGrid {
        let [lat0, lon0, dlat, dlon] = self.angles.map(f64::from_bits);
        DemGrid {
            lat0_deg: lat0,
            lon0_deg: lon0,
            dlat_deg: dlat,
            dlon_deg: dlon,
            nrows: self.rows as usize,
            ncols: self.cols as usize,
        }
    }
}

/// The tile memory: two slots of [`DEM_MAX_NODES`] heights (m, row-major from the
/// south-west) and the record of the tile in force. 65 600 bytes.
#[repr(C)]
pub struct DemStore {
    pub(super) record: Record,
    pub(super) slots: [[i16; DEM_MAX_NODES]; 2],
}

impl DemStore {
    /// An empty store (no tile recorded).
    pub const fn new() -> DemStore {
        DemStore {
            record: Record {
                magic: 0,
                slot: 0,
                id: 0,
                crc32: 0,
                rows: 0,
                cols: 0,
                angles: [0; 4],
                seal: 0,
                reserved: 0,
            },
            slots: [[0; DEM_MAX_NODES]; 2],
        }
    }

    /// Forgets the recorded tile (after power-on, when the RAM holds noise).
    pub fn forget(&mut self) {
        self.record = Record::default();
    }
}

impl Default for DemStore {
    fn default() -> Self {
        Self::new()
    }
}
