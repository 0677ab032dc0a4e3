//! The DEM tile upload (docs/telemetry.md, "The DEM upload"): a whole 128 x 128 tile in
//! 74 chunks goes in force with the bounds core-math finds in it; the tile in force
//! changes only when a complete new tile checks out; every refusal is counted under its
//! own fault and changes nothing; the tile recorded in the store comes back after a
//! reset only when its record and CRC-32 check out.
//!
//! Golden CRCs from Python's zlib, independent of `controller::crc`:
//! `python3 -c "import zlib,struct; h=lambda i,j:(i*131+j*71+i*j)%9501-500;
//! print(hex(zlib.crc32(b''.join(struct.pack('<h',h(i,j)) for i in range(128)
//! for j in range(128)))))"` gives 0xcf681000; 5 x 50 nodes give 0xe0308a42.

use controller::crc::crc32;
use controller::dem::{
    encode_begin, encode_chunk, heights_crc32, DemStatus, DemStore, DEM_CHUNK_NODES,
};
use controller::frame::{kind, Frame, MAX_PAYLOAD};
use controller::{Config, Controller, Fault, Scene};
use core_math::earth::dem::{DemGrid, DemTile};

const GOLDEN_128: u32 = 0xcf68_1000;
const GOLDEN_5X50: u32 = 0xe030_8a42;

fn node(i: usize, j: usize) -> i16 {
    ((i * 131 + j * 71 + i * j) % 9501) as i16 - 500
}

fn heights(rows: usize, cols: usize) -> Vec<i16> {
    (0..rows)
        .flat_map(|i| (0..cols).map(move |j| node(i, j)))
        .collect()
}

fn grid(rows: usize, cols: usize) -> DemGrid {
    DemGrid {
        lat0_deg: 35.0,
        lon0_deg: 138.0,
        dlat_deg: 1.0 / 1200.0,
        dlon_deg: 1.0 / 1200.0,
        nrows: rows,
        ncols: cols,
    }
}

/// What a refusal must leave as it was.
#[derive(Debug, PartialEq)]
struct Observed {
    status: DemStatus,
    tile: Option<(DemGrid, Vec<i16>, core_math::earth::dem::DemBounds)>,
    frames_accepted: u32,
}

struct Link {
    c: Controller,
    t_us: u64,
}

impl Link {
    fn new() -> Link {
        let mut c = Controller::new(Config::default(), Scene::paper_default()).unwrap();
        c.attach_dem(Box::leak(Box::new(DemStore::new())));
        Link { c, t_us: 1_000 }
    }

    fn observed(&self) -> Observed {
        Observed {
            status: self.c.dem_status(),
            tile: self.c.dem_tile().map(|t| {
                let g = *t.grid();
                let h = (0..g.nrows)
                    .flat_map(|i| (0..g.ncols).map(move |j| (i, j)))
                    .map(|(i, j)| {
                        t.height_at(g.lat_deg(i).to_radians(), g.lon_deg(j).to_radians())
                            .unwrap()
                            .round() as i16
                    })
                    .collect();
                (g, h, t.bounds())
            }),
            frames_accepted: self.c.frames_accepted,
        }
    }

    /// Sends one frame; `None` if accepted, else the fault it was refused with.
    fn send(&mut self, kind: u8, payload: &[u8]) -> Option<Fault> {
        self.t_us += 1_000;
        let before = self.c.counters;
        let accepted = self.c.frames_accepted;
        self.c.on_frame(&Frame {
            kind,
            sequence: 0,
            time_us: self.t_us,
            payload,
        });
        if self.c.frames_accepted == accepted + 1 {
            assert_eq!(self.c.counters, before, "an accepted frame counted a fault");
            return None;
        }
        let f = self.c.last_fault.expect("a refusal without a fault");
        assert_eq!(self.c.counters.total(), before.total() + 1);
        assert_eq!(self.c.counters.get(f), before.get(f) + 1);
        Some(f)
    }

    /// Sends a frame that must be refused with `want` and change nothing.
    fn refused(&mut self, kind: u8, payload: &[u8], want: Fault) {
        let before = self.observed();
        assert_eq!(self.send(kind, payload), Some(want));
        assert_eq!(self.observed(), before, "{want:?} changed something");
    }

    fn begin(&mut self, id: u32, g: &DemGrid, crc: u32) -> Option<Fault> {
        self.send(kind::DEM_BEGIN, &encode_begin(id, g, crc))
    }

    fn chunk(&mut self, id: u32, index: u16, h: &[i16]) -> Option<Fault> {
        self.send(kind::DEM_CHUNK, &chunk(id, index, h))
    }

    /// A whole upload, every frame accepted.
    fn upload(&mut self, id: u32, g: &DemGrid, h: &[i16]) {
        assert_eq!(self.begin(id, g, heights_crc32(h)), None);
        let chunks = h.len().div_ceil(DEM_CHUNK_NODES) as u16;
        for k in 0..chunks {
            assert_eq!(self.chunk(id, k, h), None, "chunk {k}");
        }
    }
}

fn chunk(id: u32, index: u16, h: &[i16]) -> Vec<u8> {
    let mut out = [0u8; MAX_PAYLOAD];
    let n = encode_chunk(id, index, h, &mut out).unwrap();
    out[..n].to_vec()
}

#[test]
fn crc32_matches_zlib() {
    assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
    assert_eq!(heights_crc32(&heights(128, 128)), GOLDEN_128);
    assert_eq!(heights_crc32(&heights(5, 50)), GOLDEN_5X50);
}

/// A 128 x 128 tile in 74 chunks of at most 224 nodes, each within the 456-byte payload;
/// in force after the last one, with the heights and the bounds core-math finds.
#[test]
fn a_whole_tile_goes_in_force_after_its_last_chunk() {
    let (g, h) = (grid(128, 128), heights(128, 128));
    let mut l = Link::new();
    assert_eq!(l.begin(7, &g, GOLDEN_128), None);
    assert_eq!(
        l.c.dem_status(),
        DemStatus {
            in_force_id: 0,
            upload_id: 7,
            next_chunk: 0,
            chunks: 74,
            tiles_committed: 0
        }
    );
    for k in 0..74u16 {
        assert!(chunk(7, k, &h).len() <= MAX_PAYLOAD);
        assert!(l.c.dem_tile().is_none(), "in force before chunk {k}");
        assert_eq!(l.chunk(7, k, &h), None);
    }
    let status = l.c.dem_status();
    assert_eq!((status.in_force_id, status.upload_id), (7, 0));
    assert_eq!(status.tiles_committed, 1);
    let tile = l.c.dem_tile().expect("the tile in force");
    let reference = DemTile::new(g, &h).unwrap();
    assert_eq!(tile.bounds(), reference.bounds());
    assert_eq!(*tile.grid(), g);
    let (_, got, _) = l.observed().tile.unwrap();
    assert_eq!(got, h);
}

/// The tile in force stays, node for node, through a second upload's chunks and its
/// faults, and changes at once when that upload's last chunk checks out; a third upload
/// stages into the first tile's slot without touching the second.
#[test]
fn the_tile_in_force_changes_only_when_a_complete_tile_checks_out() {
    let (ga, ha) = (grid(128, 128), heights(128, 128));
    let (gb, hb) = (grid(5, 50), heights(5, 50));
    let mut l = Link::new();
    l.upload(1, &ga, &ha);
    let a = l.observed().tile.unwrap();
    assert_eq!(l.begin(2, &gb, GOLDEN_5X50), None);
    assert_eq!(l.chunk(2, 0, &hb), None);
    assert_eq!(l.observed().tile.unwrap(), a);
    assert_eq!(l.chunk(2, 0, &hb), Some(Fault::DemSequence));
    assert_eq!(l.observed().tile.unwrap(), a);
    assert_eq!(l.chunk(2, 1, &hb), None);
    let b = l.observed().tile.unwrap();
    assert_eq!((b.0, &b.1), (gb, &hb));
    assert_eq!(l.c.dem_status().in_force_id, 2);
    // A third upload, cut off half-way and given up: the second tile stays.
    let hc: Vec<i16> = ha.iter().map(|x| x / 2).collect();
    assert_eq!(l.begin(3, &ga, heights_crc32(&hc)), None);
    for k in 0..40 {
        assert_eq!(l.chunk(3, k, &hc), None);
    }
    assert_eq!(l.observed().tile.unwrap(), b);
    // Given up for a fourth, which completes.
    l.upload(4, &ga, &hc);
    let (_, got, _) = l.observed().tile.unwrap();
    assert_eq!(got, hc);
    assert_eq!(l.c.dem_status().tiles_committed, 3);
}

/// Every refusal of the upload, each counted under its own fault and changing nothing:
/// the grid (id 0, too many nodes, one row, a spacing of 0, a pole, the antimeridian),
/// a NaN, lengths, a chunk of no upload or of another, missing, repeated and out of
/// order chunks, a repeated DEM_BEGIN, heights out of range, the whole tile's CRC.
#[test]
fn every_upload_fault_is_typed_and_changes_nothing() {
    let (g, h) = (grid(128, 128), heights(128, 128));
    let mut l = Link::new();
    let begin = |id: u32, g: DemGrid| encode_begin(id, &g, GOLDEN_128).to_vec();
    let bad_grids = [
        (0, g),
        (9, grid(129, 128)),
        (9, grid(1, 128)),
        (9, DemGrid { dlat_deg: 0.0, ..g }),
        (
            9,
            DemGrid {
                lat0_deg: 87.95,
                ..g
            },
        ),
        (
            9,
            DemGrid {
                lon0_deg: 179.95,
                ..g
            },
        ),
        (
            9,
            DemGrid {
                lon0_deg: -180.01,
                ..g
            },
        ),
    ];
    for (id, bad) in bad_grids {
        l.refused(kind::DEM_BEGIN, &begin(id, bad), Fault::DemGrid);
    }
    let nan = DemGrid {
        dlon_deg: f64::NAN,
        ..g
    };
    l.refused(kind::DEM_BEGIN, &begin(9, nan), Fault::NonFinite);
    l.refused(kind::DEM_BEGIN, &begin(9, g)[..47], Fault::BadLength);
    // A chunk of no upload.
    l.refused(kind::DEM_CHUNK, &chunk(9, 0, &h), Fault::DemSequence);
    // The upload, with every chunk fault on the way.
    assert_eq!(l.begin(9, &g, GOLDEN_128), None);
    l.refused(kind::DEM_BEGIN, &begin(9, g), Fault::DemSequence);
    l.refused(kind::DEM_CHUNK, &chunk(8, 0, &h), Fault::DemSequence);
    l.refused(kind::DEM_CHUNK, &chunk(9, 1, &h), Fault::DemSequence);
    assert_eq!(l.chunk(9, 0, &h), None);
    l.refused(kind::DEM_CHUNK, &chunk(9, 0, &h), Fault::DemSequence);
    l.refused(kind::DEM_CHUNK, &chunk(9, 2, &h), Fault::DemSequence);
    let mut short = chunk(9, 1, &h);
    short.pop();
    l.refused(kind::DEM_CHUNK, &short, Fault::BadLength);
    short.truncate(7);
    l.refused(kind::DEM_CHUNK, &short, Fault::BadLength);
    // A count the grid does not leave for this chunk (fewer nodes, consistent length).
    let fewer = chunk(9, 1, &h[..DEM_CHUNK_NODES + 100]);
    l.refused(kind::DEM_CHUNK, &fewer, Fault::BadLength);
    for bad in [9_001i16, -501, i16::MIN, i16::MAX] {
        let mut hh = h.clone();
        hh[DEM_CHUNK_NODES + 17] = bad;
        l.refused(kind::DEM_CHUNK, &chunk(9, 1, &hh), Fault::DemHeight);
    }
    // The limits themselves are heights.
    let mut hh = h.clone();
    hh[DEM_CHUNK_NODES + 3] = 9_000;
    hh[DEM_CHUNK_NODES + 4] = -500;
    // ... but not this tile's (its CRC is of `h`): the last chunk is refused.
    for k in 1..74u16 {
        assert_eq!(
            l.chunk(9, k, if k == 1 { &hh } else { &h }),
            if k == 73 { Some(Fault::DemCrc) } else { None }
        );
    }
    assert!(l.c.dem_tile().is_none());
    assert_eq!(l.c.dem_status().next_chunk, 73);
    l.refused(kind::DEM_CHUNK, &chunk(9, 73, &h), Fault::DemCrc);
    // Uploaded again under a new id, it goes in force; its id cannot start another.
    l.upload(10, &g, &h);
    assert_eq!(l.c.dem_status().in_force_id, 10);
    l.refused(kind::DEM_BEGIN, &begin(10, g), Fault::DemSequence);
    l.refused(kind::DEM_CHUNK, &chunk(10, 0, &h), Fault::DemSequence);
    let c = l.c.counters;
    assert_eq!(c.get(Fault::DemGrid), 7);
    assert_eq!(c.get(Fault::DemSequence), 8);
    assert_eq!(c.get(Fault::DemHeight), 4);
    assert_eq!(c.get(Fault::DemCrc), 2);
}

/// A controller without tile memory does not take the DEM frames.
#[test]
fn without_a_store_the_dem_frames_are_unknown() {
    let mut l = Link::new();
    l.c.detach_dem();
    let g = grid(5, 50);
    l.refused(
        kind::DEM_BEGIN,
        &encode_begin(1, &g, GOLDEN_5X50),
        Fault::UnknownKind,
    );
    l.refused(
        kind::DEM_CHUNK,
        &chunk(1, 0, &heights(5, 50)),
        Fault::UnknownKind,
    );
}

/// The store outlives the controller (as retained RAM outlives a reset): a new
/// controller given it takes the recorded tile back only when the record and the
/// tile's CRC-32 check out; an upload cut by the reset leaves the tile before it.
#[test]
fn the_recorded_tile_comes_back_after_a_reset_only_when_it_checks_out() {
    let (g, h) = (grid(128, 128), heights(128, 128));
    let mut l = Link::new();
    l.upload(5, &g, &h);
    let before = l.observed().tile.unwrap();
    // A second upload cut off by the reset: it wrote only the staging slot.
    let hb = heights(5, 50);
    assert_eq!(l.begin(6, &grid(5, 50), GOLDEN_5X50), None);
    assert_eq!(l.chunk(6, 0, &hb), None);
    let store = l.c.detach_dem().unwrap();
    let mut after = Link::new();
    after.c.detach_dem();
    after.c.attach_dem(store);
    assert!(after.c.dem_tile().is_none(), "trusted before the check");
    assert_eq!(after.c.restore_dem(), Ok(5));
    assert_eq!(after.observed().tile.unwrap(), before);
    assert_eq!(after.c.dem_status().in_force_id, 5);
    // One node changed in the store: refused, nothing in force.
    let store = after.c.detach_dem().unwrap();
    let raw = store as *mut DemStore as *mut u8;
    let record_len = 64;
    // SAFETY: a test poking one node of the slot in force (slot 0: the first commit)
    // inside the store it owns, as RAM corruption would.
    unsafe { *raw.add(record_len + 2 * 1000) ^= 1 };
    let mut again = Link::new();
    again.c.attach_dem(store);
    assert_eq!(again.c.restore_dem(), Err(Fault::DemCrc));
    assert!(again.c.dem_tile().is_none());
    // A forgotten record (power-on): nothing to restore.
    let store = again.c.detach_dem().unwrap();
    store.forget();
    again.c.attach_dem(store);
    assert_eq!(again.c.restore_dem(), Err(Fault::DemGrid));
}
