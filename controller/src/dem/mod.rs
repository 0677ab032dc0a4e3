//! The DEM tile upload (protocol version 4): a tile of int16 heights sent in chunks
//! (DEM_BEGIN with the grid and the whole tile's CRC-32, then DEM_CHUNK frames in
//! order), staged beside the tile in force and put in force only when every chunk has
//! arrived, in order, with heights in range, and the whole tile's CRC checks out.
//! Every refusal is typed and changes nothing (docs/telemetry.md, "The DEM upload").
//!
//! The tile memory ([`DemStore`]) is two slots: the tile in force and the staging one.
//! A commit swaps their roles (one index, no copy), so the tile in force never changes
//! under an upload. The store also holds the record of the tile in force, sealed by a
//! CRC, so that a store kept in RAM that survives a reset brings the tile back
//! ([`crate::Controller::restore_dem`]). It is 64 KiB: the controller borrows it
//! (`&'static mut`, [`crate::Controller::attach_dem`]) so that the firmware can place it
//! outside its `.bss` (docs/target.md, "Memory"); a controller without one refuses the
//! DEM frames as `unknown_kind`.

use core_math::earth::dem::{DemBounds, DemGrid, DemTile};
use core_math::earth::dem::{MAX_DEM_HEIGHT_M, MIN_DEM_HEIGHT_M};

use crate::bytes::Reader;
use crate::crc;
use crate::fault::Fault;

mod codec;
mod store;

use codec::{decode_begin, node};
pub use codec::{encode_begin, encode_chunk, heights_crc32};
pub use store::DemStore;
use store::{Record, MAGIC};

/// The most nodes a tile may hold (128 x 128, or any rows x cols up to it).
pub const DEM_MAX_NODES: usize = 128 * 128;
/// Nodes per DEM_CHUNK (the last one of a tile takes what is left): 8 + 2 x 224 = 456
/// bytes, the largest payload.
pub const DEM_CHUNK_NODES: usize = 224;
/// DEM_BEGIN's payload (bytes).
pub const DEM_BEGIN_LEN: usize = 48;
/// DEM_CHUNK's payload before its heights (bytes).
pub const DEM_CHUNK_HEADER_LEN: usize = 8;
/// Node heights a tile may hold (m), core-math's limits as integers.
const MIN_NODE_M: i16 = MIN_DEM_HEIGHT_M as i16;
const MAX_NODE_M: i16 = MAX_DEM_HEIGHT_M as i16;

/// The tile in force.
#[derive(Clone, Copy, Debug, PartialEq)]
struct InForce {
    slot: usize,
    id: u32,
    grid: DemGrid,
    bounds: DemBounds,
}

/// Integer bounds of the nodes received so far (what [`DemBounds`] needs).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Stats {
    min_m: i16,
    max_m: i16,
    step_lat_m: u16,
    step_lon_m: u16,
}

impl Stats {
    const EMPTY: Stats = Stats {
        min_m: i16::MAX,
        max_m: i16::MIN,
        step_lat_m: 0,
        step_lon_m: 0,
    };

    fn bounds(&self) -> DemBounds {
        DemBounds {
            min_m: f64::from(self.min_m),
            max_m: f64::from(self.max_m),
            step_lat_m: f64::from(self.step_lat_m),
            step_lon_m: f64::from(self.step_lon_m),
        }
    }
}

/// An upload in progress.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Upload {
    id: u32,
    grid: DemGrid,
    crc32: u32,
    /// The staging slot.
    slot: usize,
    chunks: u16,
    /// The chunk expected next.
    next: u16,
    /// The CRC-32 register over the heights received.
    crc_reg: u32,
    stats: Stats,
}

impl Upload {
    fn nodes(&self) -> usize {
        self.grid.nrows * self.grid.ncols
    }

    /// Nodes in chunk `index`.
    fn chunk_nodes(&self, index: u16) -> usize {
        self.nodes()
            .saturating_sub(usize::from(index) * DEM_CHUNK_NODES)
            .min(DEM_CHUNK_NODES)
    }
}

/// The upload's state, as STATUS reports it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DemStatus {
    /// The id of the tile in force (0: none).
    pub in_force_id: u32,
    /// The id of the upload in progress (0: none).
    pub upload_id: u32,
    /// The chunk it expects next, and its chunk count.
    pub next_chunk: u16,
    pub chunks: u16,
    /// Tiles put in force since boot (a restored one included).
    pub tiles_committed: u32,
}

/// The controller's DEM state: the store it borrows, the tile in force, the upload.
#[derive(Default)]
pub struct Dem {
    store: Option<&'static mut DemStore>,
    in_force: Option<InForce>,
    upload: Option<Upload>,
    committed: u32,
}

impl core::fmt::Debug for Dem {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Dem")
            .field("store", &self.store.is_some())
            .field("in_force", &self.in_force)
            .field("upload", &self.upload)
            .finish()
    }
}

/// A chunk that checked out: what applying it changes.
struct ChunkOk {
    upload: Upload,
    /// The tile goes in force (the last chunk, its CRC right).
    commit: bool,
}

/// Checks nodes `first..first + count` of a tile `cols` wide (heights in -500..9 000 m,
/// `dem_height`) and adds them to `stats` and the CRC-32 register `crc_reg`. Node k is
/// taken from `chunk` (little-endian pairs, its first node being node `first`) when
/// that is not empty, else from `tile`; the earlier nodes the steps need (one to the
/// west, one row down) from `tile` when they precede `first`. One routine for the
/// chunks and the check after a reset: flash is scarcer than the cycles of a call.
#[inline(never)]
fn scan(
    stats: &mut Stats,
    crc_reg: &mut u32,
    tile: &[i16],
    first: usize,
    count: usize,
    cols: usize,
    chunk: &[u8],
) -> Result<(), Fault> {
    let at = |k: usize| -> i16 {
        match k.checked_sub(first) {
            Some(i) if !chunk.is_empty() => node(chunk, i),
            _ => tile.get(k).copied().unwrap_or(0),
        }
    };
    let mut s = *stats;
    let mut c = *crc_reg;
    for k in first..first + count {
        let h = at(k);
        if !(MIN_NODE_M..=MAX_NODE_M).contains(&h) {
            return Err(Fault::DemHeight);
        }
        s.min_m = s.min_m.min(h);
        s.max_m = s.max_m.max(h);
        if !k.is_multiple_of(cols) {
            s.step_lon_m = s.step_lon_m.max(h.abs_diff(at(k - 1)));
        }
        if k >= cols {
            s.step_lat_m = s.step_lat_m.max(h.abs_diff(at(k - cols)));
        }
        c = crc::update32(c, &h.to_le_bytes());
    }
    *stats = s;
    *crc_reg = c;
    Ok(())
}

impl Dem {
    /// The tile in force, as the search takes it.
    pub fn tile(&self) -> Option<DemTile<'_, i16>> {
        let f = self.in_force.as_ref()?;
        let heights = self.store.as_deref()?.slots.get(f.slot)?;
        let heights = heights.get(..f.grid.nrows * f.grid.ncols)?;
        DemTile::with_bounds(f.grid, heights, f.bounds).ok()
    }

    /// The heights of the tile in force (its grid's nodes, row-major): what the
    /// update's route reads, without [`Dem::tile`]'s check of the grid.
    pub(crate) fn heights_in_force(&self) -> Option<&[i16]> {
        let f = self.in_force.as_ref()?;
        let slot = self.store.as_deref()?.slots.get(f.slot)?;
        slot.get(..f.grid.nrows * f.grid.ncols)
    }

    pub fn status(&self) -> DemStatus {
        DemStatus {
            in_force_id: self.in_force.map_or(0, |f| f.id),
            upload_id: self.upload.map_or(0, |u| u.id),
            next_chunk: self.upload.map_or(0, |u| u.next),
            chunks: self.upload.map_or(0, |u| u.chunks),
            tiles_committed: self.committed,
        }
    }

    /// A DEM_BEGIN's checks: its length (`bad_length`), finite angles (`non_finite`),
    /// the grid (`dem_grid`: id 0, at most [`DEM_MAX_NODES`] nodes, 2..=4096 along a
    /// side, spacings positive, no node past 88 deg of latitude or outside [-180, 180)
    /// of longitude), an id new to it (`dem_sequence`: not that of the tile in force,
    /// nor that of the upload in progress: a repeated DEM_BEGIN must not throw away a
    /// half-done upload).
    fn check_begin(&self, payload: &[u8]) -> Result<Upload, Fault> {
        if self.store.is_none() {
            return Err(Fault::UnknownKind);
        }
        if payload.len() != DEM_BEGIN_LEN {
            return Err(Fault::BadLength);
        }
        let b = decode_begin(payload).ok_or(Fault::BadLength)?;
        let g = b.grid;
        let angles = [g.lat0_deg, g.lon0_deg, g.dlat_deg, g.dlon_deg];
        if !angles.iter().all(|x| x.is_finite()) {
            return Err(Fault::NonFinite);
        }
        let nodes = g.nrows * g.ncols;
        if b.id == 0 || nodes > DEM_MAX_NODES || g.check().is_err() {
            return Err(Fault::DemGrid);
        }
        let in_force = self.in_force.map(|f| f.id);
        let uploading = self.upload.map(|u| u.id);
        if in_force == Some(b.id) || uploading == Some(b.id) {
            return Err(Fault::DemSequence);
        }
        let chunks = nodes.div_ceil(DEM_CHUNK_NODES) as u16;
        Ok(Upload {
            id: b.id,
            grid: g,
            crc32: b.crc32,
            slot: self.in_force.map_or(0, |f| 1 - f.slot),
            chunks,
            next: 0,
            crc_reg: crc::INIT32,
            stats: Stats::EMPTY,
        })
    }

    /// A DEM_CHUNK's checks: its length against its own count (`bad_length`: 8 + 2 x
    /// count, count 1..=224), an upload in progress with its id (`dem_sequence`: a
    /// chunk of no upload, or of another), the chunk expected next (`dem_sequence`:
    /// missing, repeated or out of order), the count the grid leaves for this chunk
    /// (`bad_length`), heights in -500..9 000 m (`dem_height`), and for the last one the
    /// whole tile's CRC-32 (`dem_crc`). Reads the staging slot, writes nothing.
    fn check_chunk(&self, payload: &[u8]) -> Result<ChunkOk, Fault> {
        let Some(store) = self.store.as_deref() else {
            return Err(Fault::UnknownKind);
        };
        let mut r = Reader::new(payload);
        let (Some(id), Some(index), Some(count)) = (r.u32(), r.u16(), r.u16()) else {
            return Err(Fault::BadLength);
        };
        let count = usize::from(count);
        if !(1..=DEM_CHUNK_NODES).contains(&count)
            || payload.len() != DEM_CHUNK_HEADER_LEN + 2 * count
        {
            return Err(Fault::BadLength);
        }
        let mut u = match self.upload {
            Some(u) if u.id == id => u,
            _ => return Err(Fault::DemSequence),
        };
        if index != u.next {
            return Err(Fault::DemSequence);
        }
        if count != u.chunk_nodes(index) {
            return Err(Fault::BadLength);
        }
        let heights = payload.get(DEM_CHUNK_HEADER_LEN..).unwrap_or(&[]);
        let staging = store.slots.get(u.slot).ok_or(Fault::DemSequence)?;
        let first = usize::from(index) * DEM_CHUNK_NODES;
        scan(
            &mut u.stats,
            &mut u.crc_reg,
            staging,
            first,
            count,
            u.grid.ncols,
            heights,
        )?;
        u.next += 1;
        let commit = u.next == u.chunks;
        if commit && crc::finish32(u.crc_reg) != u.crc32 {
            return Err(Fault::DemCrc);
        }
        Ok(ChunkOk { upload: u, commit })
    }

    // Out of line on the M4F: smaller than inlined into the frame intake there, larger
    // on the M3 (docs/target.md, flash).
    #[cfg_attr(all(target_arch = "arm", target_abi = "eabihf"), inline(never))]
    fn apply_chunk(&mut self, payload: &[u8], ok: ChunkOk) -> Result<(), Fault> {
        let u = ok.upload;
        let store = self.store.as_deref_mut().ok_or(Fault::UnknownKind)?;
        let first = usize::from(u.next - 1) * DEM_CHUNK_NODES;
        let heights = payload.get(DEM_CHUNK_HEADER_LEN..).unwrap_or(&[]);
        let slot = store.slots.get_mut(u.slot).ok_or(Fault::DemSequence)?;
        let dest = slot
            .get_mut(first..first + heights.len() / 2)
            .ok_or(Fault::DemSequence)?;
        for (k, h) in dest.iter_mut().enumerate() {
            *h = node(heights, k);
        }
        if !ok.commit {
            self.upload = Some(u);
            return Ok(());
        }
        let f = InForce {
            slot: u.slot,
            id: u.id,
            grid: u.grid,
            bounds: u.stats.bounds(),
        };
        let g = u.grid;
        let mut record = Record {
            magic: MAGIC,
            slot: u.slot as u32,
            id: u.id,
            crc32: u.crc32,
            rows: g.nrows as u32,
            cols: g.ncols as u32,
            angles: [g.lat0_deg, g.lon0_deg, g.dlat_deg, g.dlon_deg].map(f64::to_bits),
            seal: 0,
            reserved: 0,
        };
        record.seal = record.seal_of();
        store.record = record;
        self.in_force = Some(f);
        self.upload = None;
        self.committed = self.committed.saturating_add(1);
        Ok(())
    }

    /// Puts the store's recorded tile in force if its record's seal, its grid, its
    /// heights' range and its CRC-32 check out; otherwise nothing changes and the
    /// fault says why (`dem_grid`: no record or a bad one; `dem_height`; `dem_crc`).
    /// One pass over the tile: for a boot, after the periods are written.
    pub(crate) fn restore(&mut self) -> Result<u32, Fault> {
        let store = self.store.as_deref().ok_or(Fault::UnknownKind)?;
        let rec = store.record;
        let g = rec.grid();
        let nodes = g.nrows * g.ncols;
        if rec.magic != MAGIC
            || rec.seal != rec.seal_of()
            || rec.id == 0
            || nodes > DEM_MAX_NODES
            || g.check().is_err()
        {
            return Err(Fault::DemGrid);
        }
        let slot = usize::try_from(rec.slot).unwrap_or(usize::MAX);
        let heights = store
            .slots
            .get(slot)
            .and_then(|s| s.get(..nodes))
            .ok_or(Fault::DemGrid)?;
        let mut s = Stats::EMPTY;
        let mut crc_reg = crc::INIT32;
        scan(&mut s, &mut crc_reg, heights, 0, nodes, g.ncols, &[])?;
        if crc::finish32(crc_reg) != rec.crc32 {
            return Err(Fault::DemCrc);
        }
        self.in_force = Some(InForce {
            slot,
            id: rec.id,
            grid: g,
            bounds: s.bounds(),
        });
        self.upload = None;
        self.committed = self.committed.saturating_add(1);
        Ok(rec.id)
    }
}

impl Dem {
    /// Takes `store` as the tile memory (nothing in it trusted: no tile in force, no
    /// upload); returns the one it had.
    pub(crate) fn attach(&mut self, store: &'static mut DemStore) -> Option<&'static mut DemStore> {
        let old = self.store.replace(store);
        self.in_force = None;
        self.upload = None;
        old
    }

    /// Gives the tile memory back: no tile in force, no upload.
    pub(crate) fn detach(&mut self) -> Option<&'static mut DemStore> {
        self.in_force = None;
        self.upload = None;
        self.store.take()
    }

    /// DEM_BEGIN's checks alone.
    pub(crate) fn validate_begin(&self, payload: &[u8]) -> Result<(), Fault> {
        self.check_begin(payload).map(|_| ())
    }

    /// DEM_CHUNK's checks alone.
    pub(crate) fn validate_chunk(&self, payload: &[u8]) -> Result<(), Fault> {
        self.check_chunk(payload).map(|_| ())
    }

    /// DEM_BEGIN: a new upload; one in progress is given up.
    pub(crate) fn begin(&mut self, payload: &[u8]) -> Result<(), Fault> {
        self.upload = Some(self.check_begin(payload)?);
        Ok(())
    }

    /// DEM_CHUNK: staged; the last one puts the tile in force (then true).
    pub(crate) fn chunk(&mut self, payload: &[u8]) -> Result<bool, Fault> {
        let ok = self.check_chunk(payload)?;
        let commit = ok.commit;
        self.apply_chunk(payload, ok)?;
        Ok(commit)
    }
}
