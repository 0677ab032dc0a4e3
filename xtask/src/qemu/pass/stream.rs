//! The byte stream a pass sends: NAV frames at the samples' time tags, TERRAIN uploads,
//! TIME frames at every tick of the update period that has no other frame, the
//! injected faults, END.
//!
//! Every item knows whether it is an injected fault: the firmware gets all of them, the
//! host twin only the others ("the stream with the injected faulty frames removed").

use anyhow::{anyhow, bail, Context, Result};
use controller::bus::encode_time_scales;
use controller::dem::{encode_begin, encode_chunk, heights_crc32};
use controller::frame::{encode, kind, MAX_FRAME, SYNC};
use controller::nav::Nav;
use controller::Fault;
use core_math::earth::dem::DemGrid;

use controller::EARTH;
use core_math::vector::{norm, scale};

use super::bus::SCALES;
use super::scenario::{schedule, terrain_payload, us, Inject, Msg, Pass, SlotKind};

/// One piece of the stream.
#[derive(Clone, Debug)]
pub struct Item {
    pub bytes: Vec<u8>,
    /// The fault this item injects (None: good telemetry).
    pub fault: Option<usize>,
}

/// The built stream and what the injection should produce.
pub struct Stream {
    pub items: Vec<Item>,
    /// Per injected fault: the fault counter it must increment (None: noise, which the
    /// decoder skips and counts as skipped bytes, not as a fault).
    pub injected: Vec<Option<Fault>>,
}

impl Item {
    fn fault(bytes: Vec<u8>, k: usize) -> Item {
        Item {
            bytes,
            fault: Some(k),
        }
    }
}

impl Stream {
    /// What the firmware receives.
    pub fn faulty(&self) -> Vec<u8> {
        self.items
            .iter()
            .flat_map(|i| i.bytes.iter().copied())
            .collect()
    }
    /// The same without the injected faults.
    pub fn clean(&self) -> Vec<u8> {
        self.items
            .iter()
            .filter(|i| i.fault.is_none())
            .flat_map(|i| i.bytes.iter().copied())
            .collect()
    }
    /// Noise bytes injected.
    pub fn noise_bytes(&self) -> usize {
        self.items
            .iter()
            .filter(|i| i.fault.is_some() && !i.bytes.starts_with(&SYNC))
            .map(|i| i.bytes.len())
            .sum()
    }
}

/// Frames encoded in sequence (the sequence number wraps).
#[derive(Default)]
pub(super) struct Frames {
    sequence: u16,
}

impl Frames {
    /// A frame tagged `time_us` of pass time (GPS time less the pass's epoch).
    pub(super) fn frame(&mut self, kind: u8, time_us: u64, payload: &[u8]) -> Vec<u8> {
        let mut buf = [0u8; MAX_FRAME];
        let tag = time_us.saturating_add(super::check::epoch_us());
        let n = encode(kind, self.sequence, tag, payload, &mut buf).unwrap_or(0);
        self.sequence = self.sequence.wrapping_add(1);
        buf[..n].to_vec()
    }
    pub(super) fn nav(&mut self, time_us: u64, nav: &Nav) -> Vec<u8> {
        let mut payload = [0u8; 128];
        let n = nav.encode(&mut payload).unwrap_or(0);
        self.frame(kind::NAV, time_us, &payload[..n])
    }
    pub(super) fn msg(&mut self, time_us: u64, msg: &Msg) -> Vec<u8> {
        let mut p = [0u8; 64];
        let (kind, n) = match msg {
            Msg::Nav(nav) => return self.nav(time_us, nav),
            Msg::Gnss(g) => (kind::GNSS, g.encode(&mut p)),
            Msg::Attitude(a) => (kind::ATTITUDE, a.encode(&mut p)),
            Msg::Scales => (
                kind::TIME_SCALES,
                encode_time_scales(SCALES.gps_utc_s as i16, SCALES.dut1_s as f32, &mut p),
            ),
        };
        self.frame(kind, time_us, &p[..n.unwrap_or(0)])
    }
}

/// The ground's uploads at the start of a pass, from `t0_us` + 1 us on: the scene the
/// firmware booted with (with the camera's mounting for the bus's frames), so that the
/// flight binary plans a scene in flight (its deepest stack, docs/target.md); then the
/// DEM tile, its DEM_BEGIN and chunks 1 us apart.
pub(super) fn uploads(
    frames: &mut Frames,
    bus: bool,
    dem: Option<&(DemGrid, Vec<i16>)>,
    t0_us: u64,
) -> Vec<Vec<u8>> {
    let scene = super::scenario::pass_scene(bus);
    let mut p = vec![0u8; controller::frame::MAX_PAYLOAD];
    let n = scene.encode(&mut p).unwrap_or(0);
    let mut out = vec![frames.frame(kind::SCENE, t0_us + 1, &p[..n])];
    if let Some((grid, heights)) = dem {
        let id = super::scenario::PASS_DEM_ID;
        let begin = encode_begin(id, grid, heights_crc32(heights));
        out.push(frames.frame(kind::DEM_BEGIN, t0_us + 2, &begin));
        let mut k = 0u16;
        while let Some(n) = encode_chunk(id, k, heights, &mut p) {
            out.push(frames.frame(kind::DEM_CHUNK, t0_us + 3 + u64::from(k), &p[..n]));
            k += 1;
        }
    }
    out
}

/// Builds the stream of `pass`.
pub fn build(pass: &Pass) -> Result<Stream> {
    // The pass's time line (the same the player built it on): NAV samples, TERRAIN
    // uploads, TIME ticks in between.
    let nav_us: Vec<u64> = pass.samples.iter().map(|s| s.t_us).collect();
    let terrain_us: Vec<u64> = pass.terrain.iter().map(|t| t.0).collect();
    let slots = schedule(&nav_us, &terrain_us, pass.tick_us, pass.end_us);
    let (mut navs, mut terrain) = (pass.samples.iter(), pass.terrain.iter());

    let mut frames = Frames::default();
    let mut items: Vec<Item> = Vec::with_capacity(slots.len() + 16);
    // Index of the item carrying the NAV frame of each instant.
    let mut nav_item = std::collections::HashMap::new();
    for &(t, kind_of) in &slots {
        let bytes = match kind_of {
            SlotKind::Nav => {
                let s = navs
                    .next()
                    .context("the schedule has more telemetry slots than samples")?;
                nav_item.insert(s.t_us, items.len());
                frames.msg(s.t_us, &s.msg)
            }
            SlotKind::Terrain => {
                let (_, heights) = terrain
                    .next()
                    .context("the schedule has more TERRAIN slots than uploads")?;
                frames.frame(kind::TERRAIN, t, &terrain_payload(heights))
            }
            SlotKind::Time => frames.frame(kind::TIME, t, &[]),
        };
        items.push(Item { bytes, fault: None });
    }

    let mut injected = Vec::new();
    // Extra items, inserted after building (index to insert before, item).
    let mut extra: Vec<(usize, Item)> = Vec::new();
    let item_at = |t_s: f64| -> Result<usize> {
        nav_item
            .get(&us(t_s))
            .copied()
            .with_context(|| format!("no NAV frame at {t_s} s to inject a fault into"))
    };
    // The first item whose frame is time-tagged after `t_us` (extra frames go before it).
    let times: Vec<u64> = slots.iter().map(|s| s.0).collect();
    let after = |t_us: u64| times.iter().position(|&t| t > t_us).unwrap_or(times.len());
    let truth = pass
        .truth
        .as_deref()
        .context("faults are injected into the built-in passes only");
    // The truth's frames tagged `t_s` (a fix 50 ms before).
    let gnss = |t_s: f64| {
        truth
            .as_ref()
            .map(|a| a.gnss(t_s - 0.05, None))
            .map_err(|e| anyhow!("{e}"))
    };
    let star =
        |t_s: f64| -> Result<_> { truth.as_ref().map_err(|e| anyhow!("{e}"))?.star(t_s, None) };
    for (k, &(t_s, f)) in pass.faults.iter().enumerate() {
        let gnss_msg = |frames: &mut Frames, g| frames.msg(us(t_s), &Msg::Gnss(g));
        let star_msg = |frames: &mut Frames, a| frames.msg(us(t_s), &Msg::Attitude(a));
        // What the fault changes in place, or the frame (or noise) it adds after the
        // frames of `t_s`; and the counter it must increment.
        let (added, expect) = match f {
            Inject::BitFlip => {
                let i = item_at(t_s)?;
                items[i] = Item::fault(bit_flip(&items[i].bytes)?, k);
                (None, Some(Fault::BadCrc))
            }
            Inject::Truncate => {
                let i = item_at(t_s)?;
                items[i] = Item::fault(truncate(&items[i].bytes)?, k);
                (None, Some(Fault::Truncated))
            }
            Inject::Noise { bytes } => (Some(noise(bytes, k as u64)), None),
            Inject::Backwards { back_s } => {
                let t_old = t_s - back_s;
                let bytes = frames.msg(us(t_old), &Msg::Gnss(gnss(t_old)?));
                (Some(bytes), Some(Fault::TimeWentBackwards))
            }
            Inject::NaN => {
                let mut g = gnss(t_s)?;
                g.velocity_mps[0] = f64::NAN;
                (Some(gnss_msg(&mut frames, g)), Some(Fault::NonFinite))
            }
            Inject::Altitude { altitude_m } => {
                let mut g = gnss(t_s)?;
                let r = g.position_m;
                g.position_m = scale((EARTH.a_m + altitude_m) / norm(r), r);
                (Some(gnss_msg(&mut frames, g)), Some(Fault::OutOfRange))
            }
            // Cut out of the samples already: missing telemetry, in both runs.
            Inject::Gap { .. } => (None, Some(Fault::Stale)),
            Inject::TimeTag { tag_us } => (
                Some(frames.frame(kind::TIME, tag_us, &[])),
                Some(Fault::TimeJump),
            ),
            Inject::BadScene(probe) => {
                let bytes = frames.frame(kind::SCENE, us(t_s), &probe.payload());
                (Some(bytes), Some(Fault::InvalidScene))
            }
            Inject::Terrain { height_m } => {
                let n = pass.terrain.first().map_or(0, |t| t.1.len());
                let bytes =
                    frames.frame(kind::TERRAIN, us(t_s), &terrain_payload(&vec![height_m; n]));
                (Some(bytes), Some(Fault::OutOfRange))
            }
            Inject::Dem(probe) => {
                let (k, payload, fault) =
                    probe.frame(pass.dem.as_ref().context("DEM faults need a tile")?);
                (Some(frames.frame(k, us(t_s), &payload)), Some(fault))
            }
            Inject::Envelope => {
                let mut a = star(t_s)?;
                a.body_rate_rad_s[0] = 0.5;
                (
                    Some(star_msg(&mut frames, a)),
                    Some(Fault::AttitudeOutsideModel),
                )
            }
            Inject::Quaternion => {
                let mut a = star(t_s)?;
                a.q = a.q.map(|x| x * 1.01);
                (Some(star_msg(&mut frames, a)), Some(Fault::BadQuaternion))
            }
            Inject::FixAfterTag => {
                let mut g = gnss(t_s)?;
                g.fix_us = pass.epoch_us + us(t_s + 1.0);
                (Some(gnss_msg(&mut frames, g)), Some(Fault::FixTime))
            }
            Inject::LeapSeconds => {
                let mut p = [0u8; 8];
                let n = encode_time_scales(70, 0.0, &mut p).unwrap_or(0);
                let bytes = frames.frame(kind::TIME_SCALES, us(t_s), &p[..n]);
                (Some(bytes), Some(Fault::TimeScales))
            }
        };
        if let Some(bytes) = added {
            extra.push((after(us(t_s)), Item::fault(bytes, k)));
        }
        injected.push(expect);
    }
    // The ground's uploads after the first frame, before the first tick.
    if let (Some(&t0), Some(&t1)) = (times.first(), times.get(1)) {
        let dem = pass.dem.as_ref().filter(|_| t1 > t0 + 100);
        if t1 > t0 + 1 {
            let bus = pass.truth.as_deref().is_some();
            for bytes in uploads(&mut frames, bus, dem, t0) {
                extra.push((1, Item { bytes, fault: None }));
            }
        }
    }
    // Insert from the back so that earlier indices stay valid; equal indices keep
    // their order.
    extra.sort_by_key(|(i, _)| *i);
    for (i, item) in extra.into_iter().rev() {
        items.insert(i, item);
    }
    items.push(Item {
        bytes: frames.frame(kind::END, pass.end_us + 1, &[]),
        fault: None,
    });
    Ok(Stream { items, injected })
}

/// True when `bytes` holds the sync word anywhere.
fn has_sync(bytes: &[u8]) -> bool {
    bytes.windows(2).any(|w| w == SYNC)
}

/// The frame with one payload bit flipped: the first bit whose flip leaves no sync word
/// inside the frame, so that the decoder sees exactly one bad CRC and then skips the
/// frame's remains.
fn bit_flip(frame: &[u8]) -> Result<Vec<u8>> {
    let header = controller::frame::HEADER_LEN;
    for bit in 0..(frame.len() - header - 2) * 8 {
        let mut f = frame.to_vec();
        f[header + bit / 8] ^= 1 << (bit % 8);
        if !has_sync(&f[1..]) {
            return Ok(f);
        }
    }
    Err(anyhow!("no bit of the frame could be flipped cleanly"))
}

/// The frame cut after its header and 20 payload bytes (no sync word in the remains).
fn truncate(frame: &[u8]) -> Result<Vec<u8>> {
    let f = frame[..controller::frame::HEADER_LEN + 20].to_vec();
    if has_sync(&f[1..]) {
        bail!("the truncated frame holds a sync word: pick another instant");
    }
    Ok(f)
}

/// Deterministic line noise without the sync word's first byte.
fn noise(n: usize, seed: u64) -> Vec<u8> {
    let mut x = 0x9E37_79B9_7F4A_7C15u64 ^ seed;
    let mut out = Vec::with_capacity(n);
    while out.len() < n {
        x = x
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        let b = (x >> 56) as u8;
        if b != SYNC[0] {
            out.push(b);
        }
    }
    out
}
