//! The DEM frames' payloads: DEM_BEGIN decoded (the camera) and encoded (host tools and
//! tests), DEM_CHUNK's nodes, the tile's CRC-32.

use core_math::earth::dem::DemGrid;

use super::{DEM_BEGIN_LEN, DEM_CHUNK_HEADER_LEN, DEM_CHUNK_NODES};
use crate::bytes::Reader;
use crate::crc;

/// The DEM_BEGIN payload's fields.
pub(super) struct Begin {
    pub(super) id: u32,
    pub(super) grid: DemGrid,
    pub(super) crc32: u32,
}

pub(super) fn decode_begin(payload: &[u8]) -> Option<Begin> {
    let mut r = Reader::new(payload);
    let id = r.u32()?;
    let rows = r.u16()?;
    let cols = r.u16()?;
    let crc32 = r.u32()?;
    let _reserved = r.u32()?;
    let grid = DemGrid {
        lat0_deg: r.f64()?,
        lon0_deg: r.f64()?,
        dlat_deg: r.f64()?,
        dlon_deg: r.f64()?,
        nrows: usize::from(rows),
        ncols: usize::from(cols),
    };
    r.is_done().then_some(Begin { id, grid, crc32 })
}

/// Node `k` of a chunk's heights (little-endian i16 pairs).
pub(super) fn node(bytes: &[u8], k: usize) -> i16 {
    match bytes.get(2 * k..2 * k + 2) {
        Some(&[lo, hi]) => i16::from_le_bytes([lo, hi]),
        _ => 0,
    }
}

/// The DEM_BEGIN payload of an upload `id` of `grid` whose heights have CRC-32 `crc32`
/// (host tools and tests; the camera only decodes).
pub fn encode_begin(id: u32, grid: &DemGrid, crc32: u32) -> [u8; DEM_BEGIN_LEN] {
    let mut out = [0u8; DEM_BEGIN_LEN];
    let mut put = |at: usize, b: &[u8]| {
        if let Some(d) = out.get_mut(at..at + b.len()) {
            d.copy_from_slice(b);
        }
    };
    put(0, &id.to_le_bytes());
    put(4, &(grid.nrows as u16).to_le_bytes());
    put(6, &(grid.ncols as u16).to_le_bytes());
    put(8, &crc32.to_le_bytes());
    let angles = [grid.lat0_deg, grid.lon0_deg, grid.dlat_deg, grid.dlon_deg];
    for (k, a) in angles.iter().enumerate() {
        put(16 + 8 * k, &a.to_le_bytes());
    }
    out
}

/// The CRC-32 of a tile's heights as DEM_BEGIN carries it: over their little-endian
/// bytes, row-major from the south-west node.
pub fn heights_crc32(heights_m: &[i16]) -> u32 {
    let c = heights_m
        .iter()
        .fold(crc::INIT32, |c, h| crc::update32(c, &h.to_le_bytes()));
    crc::finish32(c)
}

/// Writes chunk `index` of an upload `id` of `heights_m` (row-major) into `out`;
/// returns its length, `None` past the last chunk or when `out` is too small.
pub fn encode_chunk(id: u32, index: u16, heights_m: &[i16], out: &mut [u8]) -> Option<usize> {
    let first = usize::from(index) * DEM_CHUNK_NODES;
    let nodes = heights_m.get(first..)?;
    let nodes = nodes.get(..nodes.len().min(DEM_CHUNK_NODES))?;
    if nodes.is_empty() {
        return None;
    }
    let len = DEM_CHUNK_HEADER_LEN + 2 * nodes.len();
    let out = out.get_mut(..len)?;
    out.get_mut(0..4)?.copy_from_slice(&id.to_le_bytes());
    out.get_mut(4..6)?.copy_from_slice(&index.to_le_bytes());
    out.get_mut(6..8)?
        .copy_from_slice(&(nodes.len() as u16).to_le_bytes());
    for (k, h) in nodes.iter().enumerate() {
        let at = DEM_CHUNK_HEADER_LEN + 2 * k;
        out.get_mut(at..at + 2)?.copy_from_slice(&h.to_le_bytes());
    }
    Some(len)
}
