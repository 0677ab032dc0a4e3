//! A small line-plot renderer to PNG: title, axis labels, several labelled series,
//! linear or logarithmic y axis, a legend.
//!
//! Pure Rust and self-contained: the text is the public-domain 8x8 bitmap font of the
//! `font8x8` crate (drawn at twice its size), the lines are anti-aliased by distance to
//! the segment, and the image is encoded by the `png` crate. No system library or font
//! file is needed, and the same plot gives the same bytes on every run.
//!
//! ```ignore
//! Plot::new("Title", "x (unit)", "y (unit)")
//!     .series(Series::line("first", points))
//!     .series(Series::line("floor", floor).dashed())
//!     .save(Path::new("out.png"))?;
//! ```

// A helper for several commands: not every option is used by every build of them.
#![allow(dead_code)]

use std::path::Path;

pub mod heatmap;

/// An RGB colour.
pub type Rgb = [u8; 3];

/// Colours given to series in order (Tableau 10, easy to tell apart).
pub const PALETTE: [Rgb; 10] = [
    [31, 119, 180],
    [214, 39, 40],
    [44, 160, 44],
    [255, 127, 14],
    [148, 103, 189],
    [140, 86, 75],
    [227, 119, 194],
    [127, 127, 127],
    [188, 189, 34],
    [23, 190, 207],
];

const WHITE: Rgb = [255, 255, 255];
const BLACK: Rgb = [0, 0, 0];
const GRID: Rgb = [225, 225, 225];
/// Pixels per font pixel (the font is 8x8).
const TEXT_SCALE: i32 = 2;
const GLYPH: i32 = 8 * TEXT_SCALE;

/// One labelled curve.
#[derive(Clone, Debug)]
pub struct Series {
    pub label: String,
    /// (x, y) in data units; non-finite points (and y <= 0 on a log axis) break the line.
    pub points: Vec<(f64, f64)>,
    /// None: the next palette colour.
    pub colour: Option<Rgb>,
    pub dashed: bool,
    /// Line width in pixels.
    pub width: f64,
}

impl Series {
    pub fn line(label: &str, points: Vec<(f64, f64)>) -> Self {
        Series {
            label: label.to_string(),
            points,
            colour: None,
            dashed: false,
            width: 2.0,
        }
    }

    pub fn dashed(mut self) -> Self {
        self.dashed = true;
        self
    }

    /// The colour of palette entry `i` (wraps around).
    pub fn palette(mut self, i: usize) -> Self {
        self.colour = Some(PALETTE[i % PALETTE.len()]);
        self
    }

    pub fn colour(mut self, c: Rgb) -> Self {
        self.colour = Some(c);
        self
    }

    pub fn width(mut self, w: f64) -> Self {
        self.width = w;
        self
    }
}

/// Where the legend box goes inside the plot area.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Legend {
    TopRight,
    TopLeft,
    BottomRight,
    BottomLeft,
    None,
}

/// A line plot.
#[derive(Clone, Debug)]
pub struct Plot {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub log_y: bool,
    pub width: u32,
    pub height: u32,
    /// None: from the data, widened to whole tick steps.
    pub x_range: Option<(f64, f64)>,
    pub y_range: Option<(f64, f64)>,
    pub legend: Legend,
    pub series: Vec<Series>,
}

impl Plot {
    pub fn new(title: &str, x_label: &str, y_label: &str) -> Self {
        Plot {
            title: title.to_string(),
            x_label: x_label.to_string(),
            y_label: y_label.to_string(),
            log_y: false,
            width: 1000,
            height: 650,
            x_range: None,
            y_range: None,
            legend: Legend::TopRight,
            series: Vec::new(),
        }
    }

    pub fn log_y(mut self, on: bool) -> Self {
        self.log_y = on;
        self
    }

    pub fn size(mut self, width: u32, height: u32) -> Self {
        self.width = width;
        self.height = height;
        self
    }

    pub fn x_range(mut self, lo: f64, hi: f64) -> Self {
        self.x_range = Some((lo, hi));
        self
    }

    pub fn y_range(mut self, lo: f64, hi: f64) -> Self {
        self.y_range = Some((lo, hi));
        self
    }

    pub fn legend(mut self, at: Legend) -> Self {
        self.legend = at;
        self
    }

    pub fn series(mut self, s: Series) -> Self {
        self.series.push(s);
        self
    }

    /// Renders and encodes as an 8-bit RGB PNG.
    pub fn to_png(&self) -> Result<Vec<u8>, String> {
        let canvas = self.render()?;
        canvas.to_png()
    }

    /// Renders and writes a PNG file.
    pub fn save(&self, path: &Path) -> Result<(), String> {
        let bytes = self.to_png()?;
        std::fs::write(path, bytes).map_err(|e| format!("writing {}: {e}", path.display()))
    }

    /// Renders to an RGB canvas.
    pub fn render(&self) -> Result<Canvas, String> {
        if self.width < 200 || self.height < 150 || self.width > 8000 || self.height > 8000 {
            return Err(format!(
                "plot size {}x{} out of range",
                self.width, self.height
            ));
        }
        let usable = |y: f64| y.is_finite() && (!self.log_y || y > 0.0);
        let (mut xs, mut ys) = (Vec::new(), Vec::new());
        for s in &self.series {
            for &(x, y) in &s.points {
                if x.is_finite() && usable(y) {
                    xs.push(x);
                    ys.push(if self.log_y { y.log10() } else { y });
                }
            }
        }
        let x_axis = match self.x_range {
            Some((lo, hi)) => Axis::linear_fixed(lo, hi)?,
            None => Axis::linear_auto(&xs)?,
        };
        let y_axis = match (self.y_range, self.log_y) {
            (Some((lo, hi)), false) => Axis::linear_fixed(lo, hi)?,
            (None, false) => Axis::linear_auto(&ys)?,
            (Some((lo, hi)), true) => {
                if !(lo > 0.0 && hi > lo) {
                    return Err("log y range must be positive".into());
                }
                Axis::log(lo.log10(), hi.log10())
            }
            (None, true) => {
                let (lo, hi) = min_max(&ys).ok_or("no positive data for a log axis")?;
                let pad = ((hi - lo) * 0.05).max(0.02);
                Axis::log(lo - pad, hi + pad)
            }
        };

        // Layout, all in pixels.
        let (w, h) = (self.width as i32, self.height as i32);
        let y_tick_chars = y_axis.ticks.iter().map(|t| t.1.len()).max().unwrap_or(1) as i32;
        let left = 12 + GLYPH + 12 + y_tick_chars * GLYPH + 10;
        // Room for half of the last x tick label.
        let last_x_chars = x_axis.ticks.last().map_or(0, |t| t.1.len()) as i32;
        let right = (last_x_chars * GLYPH / 2 + 12).max(30);
        let top = 14 + GLYPH + 18;
        let bottom = 10 + GLYPH + 12 + GLYPH + 14;
        let (px0, px1, py0, py1) = (left, w - right, top, h - bottom);
        if px1 - px0 < 50 || py1 - py0 < 50 {
            return Err("plot area too small for the labels".into());
        }
        let map_x =
            |x: f64| px0 as f64 + (x - x_axis.lo) / (x_axis.hi - x_axis.lo) * (px1 - px0) as f64;
        let map_y =
            |y: f64| py1 as f64 - (y - y_axis.lo) / (y_axis.hi - y_axis.lo) * (py1 - py0) as f64;

        let mut c = Canvas::new(self.width, self.height);
        // Grid and ticks.
        for (v, label) in &x_axis.ticks {
            let x = map_x(*v).round() as i32;
            c.vline(x, py0, py1, GRID);
            c.vline(x, py1, py1 + 5, BLACK);
            let tw = label.len() as i32 * GLYPH;
            c.text(x - tw / 2, py1 + 10, label, BLACK);
        }
        for &v in &y_axis.minor {
            let y = map_y(v).round() as i32;
            c.hline(px0, px1, y, [240, 240, 240]);
            c.hline(px0 - 3, px0, y, BLACK);
        }
        for (v, label) in &y_axis.ticks {
            let y = map_y(*v).round() as i32;
            c.hline(px0, px1, y, GRID);
            c.hline(px0 - 6, px0, y, BLACK);
            let tw = label.len() as i32 * GLYPH;
            c.text(px0 - 10 - tw, y - GLYPH / 2, label, BLACK);
        }
        // Series, clipped to the plot area.
        let clip = (px0 as f64, py0 as f64, px1 as f64, py1 as f64);
        for (i, s) in self.series.iter().enumerate() {
            let colour = s.colour.unwrap_or(PALETTE[i % PALETTE.len()]);
            let mut path: Vec<(f64, f64)> = Vec::new();
            let flush = |path: &mut Vec<(f64, f64)>, c: &mut Canvas| {
                c.polyline(path, s.width, colour, s.dashed, clip);
                path.clear();
            };
            for &(x, y) in &s.points {
                if x.is_finite() && usable(y) {
                    let yv = if self.log_y { y.log10() } else { y };
                    path.push((map_x(x), map_y(yv)));
                } else {
                    flush(&mut path, &mut c);
                }
            }
            flush(&mut path, &mut c);
        }
        // Frame.
        c.hline(px0, px1, py0, BLACK);
        c.hline(px0, px1, py1, BLACK);
        c.vline(px0, py0, py1, BLACK);
        c.vline(px1, py0, py1, BLACK);
        // Title and axis labels.
        let tw = self.title.len() as i32 * GLYPH;
        c.text((w - tw) / 2, 14, &self.title, BLACK);
        let xw = self.x_label.len() as i32 * GLYPH;
        c.text((px0 + px1 - xw) / 2, h - 14 - GLYPH, &self.x_label, BLACK);
        let yw = self.y_label.len() as i32 * GLYPH;
        c.text_up(12, (py0 + py1 + yw) / 2, &self.y_label, BLACK);
        self.draw_legend(&mut c, (px0, py0, px1, py1));
        Ok(c)
    }

    fn draw_legend(&self, c: &mut Canvas, (px0, py0, px1, py1): (i32, i32, i32, i32)) {
        let entries: Vec<(usize, &Series)> = self
            .series
            .iter()
            .enumerate()
            .filter(|(_, s)| !s.label.is_empty())
            .collect();
        if entries.is_empty() || self.legend == Legend::None {
            return;
        }
        let sample = 40;
        let row = GLYPH + 8;
        let chars = entries
            .iter()
            .map(|(_, s)| s.label.len())
            .max()
            .unwrap_or(0) as i32;
        let bw = 10 + sample + 8 + chars * GLYPH + 10;
        let bh = 8 + row * entries.len() as i32;
        let (bx, by) = match self.legend {
            Legend::TopRight => (px1 - 10 - bw, py0 + 10),
            Legend::TopLeft => (px0 + 10, py0 + 10),
            Legend::BottomRight => (px1 - 10 - bw, py1 - 10 - bh),
            Legend::BottomLeft | Legend::None => (px0 + 10, py1 - 10 - bh),
        };
        c.fill_rect(bx, by, bw, bh, WHITE);
        c.hline(bx, bx + bw, by, BLACK);
        c.hline(bx, bx + bw, by + bh, BLACK);
        c.vline(bx, by, by + bh, BLACK);
        c.vline(bx + bw, by, by + bh, BLACK);
        let clip = (0.0, 0.0, c.width as f64, c.height as f64);
        for (k, (i, s)) in entries.iter().enumerate() {
            let colour = s.colour.unwrap_or(PALETTE[i % PALETTE.len()]);
            let y = by + 8 + row * k as i32 + GLYPH / 2;
            let seg = [
                ((bx + 10) as f64, y as f64),
                ((bx + 10 + sample) as f64, y as f64),
            ];
            c.polyline(&seg, s.width, colour, s.dashed, clip);
            c.text(bx + 10 + sample + 8, y - GLYPH / 2, &s.label, BLACK);
        }
    }
}

fn min_max(v: &[f64]) -> Option<(f64, f64)> {
    let mut it = v.iter().copied();
    let first = it.next()?;
    Some(it.fold((first, first), |(lo, hi), x| (lo.min(x), hi.max(x))))
}

/// An axis in plotted units (log10 of the value for a log axis).
struct Axis {
    lo: f64,
    hi: f64,
    /// (position, label)
    ticks: Vec<(f64, String)>,
    /// Unlabelled minor positions (log axis only).
    minor: Vec<f64>,
}

/// A "nice" step (1, 2 or 5 times a power of ten) for about `target` intervals.
fn nice_step(span: f64, target: f64) -> f64 {
    let raw = span / target;
    let mag = 10f64.powf(raw.log10().floor());
    let r = raw / mag;
    let m = if r < 1.5 {
        1.0
    } else if r < 3.0 {
        2.0
    } else if r < 7.0 {
        5.0
    } else {
        10.0
    };
    m * mag
}

fn decimals(step: f64) -> usize {
    let d = -(step.log10() + 1e-9).floor();
    if d > 0.0 {
        d as usize
    } else {
        0
    }
}

impl Axis {
    fn linear_auto(data: &[f64]) -> Result<Axis, String> {
        let (mut lo, mut hi) = min_max(data).ok_or("no finite data to plot")?;
        if hi - lo < 1e-12 * (1.0 + lo.abs()) {
            lo -= 0.5 * (1.0 + lo.abs());
            hi += 0.5 * (1.0 + hi.abs());
        }
        let step = nice_step(hi - lo, 6.0);
        let lo = (lo / step - 1e-9).floor() * step;
        let hi = (hi / step + 1e-9).ceil() * step;
        Ok(Axis::linear_with_step(lo, hi, step))
    }

    fn linear_fixed(lo: f64, hi: f64) -> Result<Axis, String> {
        if !(lo.is_finite() && hi.is_finite() && hi > lo) {
            return Err(format!("bad axis range [{lo}, {hi}]"));
        }
        Ok(Axis::linear_with_step(lo, hi, nice_step(hi - lo, 6.0)))
    }

    fn linear_with_step(lo: f64, hi: f64, step: f64) -> Axis {
        let d = decimals(step);
        let mut ticks = Vec::new();
        let mut k = (lo / step - 1e-9).ceil() as i64;
        loop {
            let v = k as f64 * step;
            if v > hi + step * 1e-9 {
                break;
            }
            // Avoid "-0.0".
            let v = if v.abs() < step * 1e-9 { 0.0 } else { v };
            ticks.push((v, format!("{v:.d$}")));
            k += 1;
        }
        Axis {
            lo,
            hi,
            ticks,
            minor: Vec::new(),
        }
    }

    /// A log10 axis from 10^lo to 10^hi: labelled decades, 2 and 5 as well when the
    /// span is short, the other integers as minor lines.
    fn log(lo: f64, hi: f64) -> Axis {
        let (d0, d1) = (lo.floor() as i32, hi.ceil() as i32);
        let few = hi - lo < 2.5;
        let mut ticks = Vec::new();
        let mut minor = Vec::new();
        for d in d0..=d1 {
            for m in 1..10 {
                let v = m as f64 * 10f64.powi(d);
                let p = v.log10();
                if p < lo - 1e-9 || p > hi + 1e-9 {
                    continue;
                }
                if m == 1 || (few && (m == 2 || m == 5)) {
                    ticks.push((p, log_label(m, d)));
                } else {
                    minor.push(p);
                }
            }
        }
        Axis {
            lo,
            hi,
            ticks,
            minor,
        }
    }
}

fn log_label(m: i32, d: i32) -> String {
    if (-3..=4).contains(&d) {
        let v = m as f64 * 10f64.powi(d);
        let dec = if d < 0 { (-d) as usize } else { 0 };
        format!("{v:.dec$}")
    } else if m == 1 {
        format!("1e{d}")
    } else {
        format!("{m}e{d}")
    }
}

/// An RGB raster.
pub struct Canvas {
    pub width: u32,
    pub height: u32,
    pub rgb: Vec<u8>,
}

impl Canvas {
    pub fn new(width: u32, height: u32) -> Self {
        Canvas {
            width,
            height,
            rgb: vec![255; width as usize * height as usize * 3],
        }
    }

    /// Mixes `colour` into pixel (x, y) with weight `alpha` in [0, 1].
    fn blend(&mut self, x: i32, y: i32, colour: Rgb, alpha: f64) {
        if x < 0 || y < 0 || x >= self.width as i32 || y >= self.height as i32 || alpha <= 0.0 {
            return;
        }
        let a = alpha.min(1.0);
        let i = (y as usize * self.width as usize + x as usize) * 3;
        for (px, &c) in self.rgb[i..i + 3].iter_mut().zip(colour.iter()) {
            let old = *px as f64;
            *px = (old + (c as f64 - old) * a).round() as u8;
        }
    }

    fn set(&mut self, x: i32, y: i32, colour: Rgb) {
        self.blend(x, y, colour, 1.0);
    }

    fn hline(&mut self, x0: i32, x1: i32, y: i32, colour: Rgb) {
        for x in x0.min(x1)..=x0.max(x1) {
            self.set(x, y, colour);
        }
    }

    fn vline(&mut self, x: i32, y0: i32, y1: i32, colour: Rgb) {
        for y in y0.min(y1)..=y0.max(y1) {
            self.set(x, y, colour);
        }
    }

    fn fill_rect(&mut self, x: i32, y: i32, w: i32, h: i32, colour: Rgb) {
        for yy in y..=y + h {
            self.hline(x, x + w, yy, colour);
        }
    }

    /// An anti-aliased polyline of width `width`, optionally dashed (dash length
    /// measured along the path), clipped to (x0, y0, x1, y1).
    fn polyline(
        &mut self,
        pts: &[(f64, f64)],
        width: f64,
        colour: Rgb,
        dashed: bool,
        clip: (f64, f64, f64, f64),
    ) {
        let half = 0.5 * width;
        let (dash_on, dash_period) = (10.0, 16.0);
        if pts.len() == 1 {
            let (x, y) = pts[0];
            self.disc(x, y, half + 0.5, colour, clip);
            return;
        }
        let mut s0 = 0.0;
        // Each pixel takes the largest coverage over all segments, so that joints are
        // not painted twice.
        let mut cover: std::collections::BTreeMap<(i32, i32), f64> = Default::default();
        for w in pts.windows(2) {
            let ((ax, ay), (bx, by)) = (w[0], w[1]);
            let (dx, dy) = (bx - ax, by - ay);
            let len2 = dx * dx + dy * dy;
            let len = len2.sqrt();
            let r = half + 1.0;
            let xa = (ax.min(bx) - r).floor().max(clip.0) as i32;
            let xb = (ax.max(bx) + r).ceil().min(clip.2) as i32;
            let ya = (ay.min(by) - r).floor().max(clip.1) as i32;
            let yb = (ay.max(by) + r).ceil().min(clip.3) as i32;
            for y in ya..=yb {
                for x in xa..=xb {
                    let (px, py) = (x as f64, y as f64);
                    let t = if len2 > 0.0 {
                        (((px - ax) * dx + (py - ay) * dy) / len2).clamp(0.0, 1.0)
                    } else {
                        0.0
                    };
                    if dashed && (s0 + t * len) % dash_period > dash_on {
                        continue;
                    }
                    let (qx, qy) = (ax + t * dx - px, ay + t * dy - py);
                    let d = (qx * qx + qy * qy).sqrt();
                    let a = (half + 0.5 - d).clamp(0.0, 1.0);
                    if a > 0.0 {
                        let e = cover.entry((y, x)).or_insert(0.0);
                        *e = e.max(a);
                    }
                }
            }
            s0 += len;
        }
        for ((y, x), a) in cover {
            self.blend(x, y, colour, a);
        }
    }

    fn disc(&mut self, cx: f64, cy: f64, r: f64, colour: Rgb, clip: (f64, f64, f64, f64)) {
        let xa = (cx - r - 1.0).floor().max(clip.0) as i32;
        let xb = (cx + r + 1.0).ceil().min(clip.2) as i32;
        let ya = (cy - r - 1.0).floor().max(clip.1) as i32;
        let yb = (cy + r + 1.0).ceil().min(clip.3) as i32;
        for y in ya..=yb {
            for x in xa..=xb {
                let d = ((x as f64 - cx).powi(2) + (y as f64 - cy).powi(2)).sqrt();
                self.blend(x, y, colour, (r + 0.5 - d).clamp(0.0, 1.0));
            }
        }
    }

    /// The 8x8 glyph of `ch` (printable ASCII; anything else is drawn as '?').
    fn glyph(ch: char) -> [u8; 8] {
        let code = if ch.is_ascii() && !ch.is_ascii_control() {
            ch as usize
        } else {
            '?' as usize
        };
        font8x8::legacy::BASIC_LEGACY[code]
    }

    /// Text left to right with its top-left corner at (x, y).
    fn text(&mut self, x: i32, y: i32, s: &str, colour: Rgb) {
        self.glyph_pixels(s, colour, |i, gx, gy| (x + i * GLYPH + gx, y + gy));
    }

    /// Text rotated a quarter turn anticlockwise (reading upward), starting at the
    /// bottom-left corner (x, y).
    fn text_up(&mut self, x: i32, y: i32, s: &str, colour: Rgb) {
        // Glyph column gx goes up, glyph row gy goes right.
        self.glyph_pixels(s, colour, |i, gx, gy| (x + gy, y - i * GLYPH - gx));
    }

    /// Sets every pixel of the glyphs of `s`, scaled by TEXT_SCALE; `place` maps
    /// (character index, scaled glyph column, scaled glyph row) to the canvas.
    fn glyph_pixels(&mut self, s: &str, colour: Rgb, place: impl Fn(i32, i32, i32) -> (i32, i32)) {
        for (i, ch) in s.chars().enumerate() {
            let g = Self::glyph(ch);
            for (gy, bits) in g.iter().enumerate() {
                for gx in 0..8 {
                    if bits & (1 << gx) != 0 {
                        for sy in 0..TEXT_SCALE {
                            for sx in 0..TEXT_SCALE {
                                let (px, py) = place(
                                    i as i32,
                                    gx * TEXT_SCALE + sx,
                                    gy as i32 * TEXT_SCALE + sy,
                                );
                                self.set(px, py, colour);
                            }
                        }
                    }
                }
            }
        }
    }

    /// Encodes as an 8-bit RGB PNG (no time stamp: the bytes depend only on the pixels).
    pub fn to_png(&self) -> Result<Vec<u8>, String> {
        let mut out = Vec::new();
        {
            let mut enc = png::Encoder::new(&mut out, self.width, self.height);
            enc.set_color(png::ColorType::Rgb);
            enc.set_depth(png::BitDepth::Eight);
            enc.set_compression(png::Compression::High);
            let mut w = enc.write_header().map_err(|e| format!("png: {e}"))?;
            w.write_image_data(&self.rgb)
                .map_err(|e| format!("png: {e}"))?;
            w.finish().map_err(|e| format!("png: {e}"))?;
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nice_steps() {
        assert_eq!(nice_step(10.0, 5.0), 2.0);
        assert_eq!(nice_step(1.0, 6.0), 0.2);
        assert_eq!(nice_step(90.0, 6.0), 20.0);
    }

    #[test]
    fn renders_deterministically() {
        let p = Plot::new("t", "x (s)", "y (m)")
            .series(Series::line("a", vec![(0.0, 1.0), (1.0, 2.0), (2.0, 1.5)]))
            .series(Series::line("b", vec![(0.0, 0.5), (2.0, 0.7)]).dashed());
        let a = p.to_png().unwrap();
        let b = p.to_png().unwrap();
        assert_eq!(a, b);
        assert_eq!(&a[1..4], b"PNG");
        let log = p.clone().log_y(true).to_png().unwrap();
        assert!(!log.is_empty());
    }

    #[test]
    fn refuses_empty() {
        assert!(Plot::new("t", "x", "y").render().is_err());
    }
}
