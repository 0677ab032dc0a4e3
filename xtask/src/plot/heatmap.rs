//! Heatmaps to PNG: a regular grid of cells coloured by value (viridis), a colour bar
//! with labelled ticks, linear or decade axes, cells without a value drawn grey, optional
//! ring markers. Same text, axes and PNG encoding as the line plots of [`super::Plot`],
//! and the same bytes on every run.
//!
//! ```ignore
//! Heatmap::new("Title", "x (unit)", "y (unit)", "log10 err", (nx, ny), values)
//!     .x_range(0.0, 1.0)
//!     .y_range(-5.0, 2.0)
//!     .y_decades(true)
//!     .z_range(-10.0, -4.0)
//!     .z_decades(true)
//!     .save(Path::new("out.png"))?;
//! ```

use std::path::Path;

use super::{Axis, Canvas, Rgb, BLACK, GLYPH, WHITE};

/// Colour of a cell without a value.
pub const MISSING: Rgb = [205, 205, 205];

/// Viridis (matplotlib's perceptually uniform map), 9 stops, linearly interpolated.
const VIRIDIS: [Rgb; 9] = [
    [68, 1, 84],
    [71, 44, 122],
    [59, 81, 139],
    [44, 113, 142],
    [33, 144, 141],
    [39, 173, 129],
    [92, 200, 99],
    [170, 220, 50],
    [253, 231, 37],
];

/// The viridis colour of t in [0, 1] (clamped).
pub fn viridis(t: f64) -> Rgb {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = t * (VIRIDIS.len() - 1) as f64;
    let i = (x.floor() as usize).min(VIRIDIS.len() - 2);
    let f = x - i as f64;
    let (a, b) = (VIRIDIS[i], VIRIDIS[i + 1]);
    let mix = |k: usize| (a[k] as f64 + (b[k] as f64 - a[k] as f64) * f).round() as u8;
    [mix(0), mix(1), mix(2)]
}

/// A heatmap of `nx` x `ny` cells over `x_range` x `y_range`.
#[derive(Clone, Debug)]
pub struct Heatmap {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    /// Label of the colour bar.
    pub z_label: String,
    pub nx: usize,
    pub ny: usize,
    /// Row-major from the bottom row: the cell (ix, iy) is `values[iy * nx + ix]`, iy = 0
    /// at the low end of `y_range`. None (or a non-finite value): no value, drawn grey.
    pub values: Vec<Option<f64>>,
    pub x_range: (f64, f64),
    pub y_range: (f64, f64),
    /// Colour scale: values at or below the low end get the first colour, at or above
    /// the high end the last.
    pub z_range: (f64, f64),
    /// The coordinate (or value) is log10 of the quantity: ticks at decades, labelled
    /// 1e-5, 0.01, 1, 100, ...
    pub x_decades: bool,
    pub y_decades: bool,
    pub z_decades: bool,
    /// Ring markers at these (x, y) data coordinates.
    pub marks: Vec<(f64, f64)>,
    /// Lines across the colour bar at these z values (a threshold, a bound).
    pub z_marks: Vec<f64>,
    /// Shown next to a grey swatch under the colour bar when some cell has no value.
    pub missing_label: String,
    pub width: u32,
    pub height: u32,
}

impl Heatmap {
    pub fn new(
        title: &str,
        x_label: &str,
        y_label: &str,
        z_label: &str,
        (nx, ny): (usize, usize),
        values: Vec<Option<f64>>,
    ) -> Self {
        Heatmap {
            title: title.to_string(),
            x_label: x_label.to_string(),
            y_label: y_label.to_string(),
            z_label: z_label.to_string(),
            nx,
            ny,
            values,
            x_range: (0.0, 1.0),
            y_range: (0.0, 1.0),
            z_range: (0.0, 1.0),
            x_decades: false,
            y_decades: false,
            z_decades: false,
            marks: Vec::new(),
            z_marks: Vec::new(),
            missing_label: "no value".to_string(),
            width: 860,
            height: 600,
        }
    }

    pub fn x_range(mut self, lo: f64, hi: f64) -> Self {
        self.x_range = (lo, hi);
        self
    }

    pub fn y_range(mut self, lo: f64, hi: f64) -> Self {
        self.y_range = (lo, hi);
        self
    }

    pub fn z_range(mut self, lo: f64, hi: f64) -> Self {
        self.z_range = (lo, hi);
        self
    }

    pub fn x_decades(mut self, on: bool) -> Self {
        self.x_decades = on;
        self
    }

    pub fn y_decades(mut self, on: bool) -> Self {
        self.y_decades = on;
        self
    }

    pub fn z_decades(mut self, on: bool) -> Self {
        self.z_decades = on;
        self
    }

    pub fn mark(mut self, x: f64, y: f64) -> Self {
        self.marks.push((x, y));
        self
    }

    pub fn z_mark(mut self, z: f64) -> Self {
        self.z_marks.push(z);
        self
    }

    pub fn missing_label(mut self, s: &str) -> Self {
        self.missing_label = s.to_string();
        self
    }

    pub fn size(mut self, width: u32, height: u32) -> Self {
        self.width = width;
        self.height = height;
        self
    }

    fn axis(range: (f64, f64), decades: bool) -> Result<Axis, String> {
        let (lo, hi) = range;
        if !(lo.is_finite() && hi.is_finite() && hi > lo) {
            return Err(format!("bad heatmap range [{lo}, {hi}]"));
        }
        if decades {
            Ok(Axis::log(lo, hi))
        } else {
            Axis::linear_fixed(lo, hi)
        }
    }

    /// Renders to an RGB canvas.
    pub fn render(&self) -> Result<Canvas, String> {
        if self.width < 300 || self.height < 200 || self.width > 8000 || self.height > 8000 {
            return Err(format!(
                "heatmap size {}x{} out of range",
                self.width, self.height
            ));
        }
        if self.nx == 0 || self.ny == 0 || self.values.len() != self.nx * self.ny {
            return Err(format!(
                "heatmap: {} values for {} x {} cells",
                self.values.len(),
                self.nx,
                self.ny
            ));
        }
        let x_axis = Self::axis(self.x_range, self.x_decades)?;
        let y_axis = Self::axis(self.y_range, self.y_decades)?;
        let z_axis = Self::axis(self.z_range, self.z_decades)?;

        // Layout (pixels): y label, y tick labels, plot, colour bar, its labels, z label.
        let (w, h) = (self.width as i32, self.height as i32);
        let y_tick_chars = y_axis.ticks.iter().map(|t| t.1.len()).max().unwrap_or(1) as i32;
        let z_tick_chars = z_axis.ticks.iter().map(|t| t.1.len()).max().unwrap_or(1) as i32;
        let left = 12 + GLYPH + 12 + y_tick_chars * GLYPH + 10;
        let bar_w = 26;
        let right = 24 + bar_w + 8 + z_tick_chars * GLYPH + 12 + GLYPH + 12;
        let top = 14 + GLYPH + 18;
        let bottom = 10 + GLYPH + 12 + GLYPH + 14;
        let (px0, px1, py0, py1) = (left, w - right, top, h - bottom);
        if px1 - px0 < 60 || py1 - py0 < 60 {
            return Err("heatmap area too small for the labels".into());
        }
        let (x_lo, x_hi) = self.x_range;
        let (y_lo, y_hi) = self.y_range;
        let map_x = |x: f64| px0 as f64 + (x - x_lo) / (x_hi - x_lo) * (px1 - px0) as f64;
        let map_y = |y: f64| py1 as f64 - (y - y_lo) / (y_hi - y_lo) * (py1 - py0) as f64;
        let (z_lo, z_hi) = self.z_range;
        let colour = |z: f64| viridis((z - z_lo) / (z_hi - z_lo));

        let mut c = Canvas::new(self.width, self.height);
        // Cells: each plot pixel takes the colour of the cell under its centre.
        let mut any_missing = false;
        for py in py0..=py1 {
            let fy = (py1 as f64 - py as f64) / (py1 - py0 + 1) as f64;
            let iy = ((fy * self.ny as f64) as usize).min(self.ny - 1);
            for px in px0..=px1 {
                let fx = (px as f64 - px0 as f64) / (px1 - px0 + 1) as f64;
                let ix = ((fx * self.nx as f64) as usize).min(self.nx - 1);
                let v = self.values[iy * self.nx + ix].filter(|v| v.is_finite());
                let rgb = match v {
                    Some(z) => colour(z),
                    None => {
                        any_missing = true;
                        MISSING
                    }
                };
                c.set(px, py, rgb);
            }
        }
        // Ticks outside the plot area.
        for (v, label) in &x_axis.ticks {
            let x = map_x(*v).round() as i32;
            c.vline(x, py1, py1 + 6, BLACK);
            let tw = label.len() as i32 * GLYPH;
            c.text(x - tw / 2, py1 + 10, label, BLACK);
        }
        for &v in &x_axis.minor {
            let x = map_x(v).round() as i32;
            c.vline(x, py1, py1 + 3, BLACK);
        }
        for (v, label) in &y_axis.ticks {
            let y = map_y(*v).round() as i32;
            c.hline(px0 - 6, px0, y, BLACK);
            let tw = label.len() as i32 * GLYPH;
            c.text(px0 - 10 - tw, y - GLYPH / 2, label, BLACK);
        }
        for &v in &y_axis.minor {
            let y = map_y(v).round() as i32;
            c.hline(px0 - 3, px0, y, BLACK);
        }
        // Markers: a black ring around a white ring, visible on any colour.
        for &(x, y) in &self.marks {
            let (cx, cy) = (map_x(x), map_y(y));
            ring(&mut c, cx, cy, 9.0, 2.5, BLACK, (px0, py0, px1, py1));
            ring(&mut c, cx, cy, 6.0, 1.5, WHITE, (px0, py0, px1, py1));
        }
        // Frame.
        c.hline(px0, px1, py0, BLACK);
        c.hline(px0, px1, py1, BLACK);
        c.vline(px0, py0, py1, BLACK);
        c.vline(px1, py0, py1, BLACK);

        // Colour bar: z from bottom to top, ticks and labels on its right.
        let bx0 = px1 + 24;
        let bx1 = bx0 + bar_w;
        for py in py0..=py1 {
            let t = (py1 - py) as f64 / (py1 - py0) as f64;
            c.hline(bx0, bx1, py, viridis(t));
        }
        c.hline(bx0, bx1, py0, BLACK);
        c.hline(bx0, bx1, py1, BLACK);
        c.vline(bx0, py0, py1, BLACK);
        c.vline(bx1, py0, py1, BLACK);
        let map_z = |z: f64| py1 as f64 - (z - z_lo) / (z_hi - z_lo) * (py1 - py0) as f64;
        for (v, label) in &z_axis.ticks {
            let y = map_z(*v).round() as i32;
            c.hline(bx1, bx1 + 6, y, BLACK);
            c.text(bx1 + 10, y - GLYPH / 2, label, BLACK);
        }
        for &v in &z_axis.minor {
            let y = map_z(v).round() as i32;
            c.hline(bx1, bx1 + 3, y, BLACK);
        }
        // Marks across the bar: black with a white core, sticking out on the left.
        for &z in &self.z_marks {
            if z >= z_lo && z <= z_hi {
                let y = map_z(z).round() as i32;
                c.fill_rect(bx0 - 8, y - 2, bx1 - bx0 + 8, 4, BLACK);
                c.hline(bx0 - 6, bx1 - 2, y, WHITE);
            }
        }
        let zl = self.z_label.len() as i32 * GLYPH;
        let zx = bx1 + 10 + z_tick_chars * GLYPH + 12;
        c.text_up(zx, (py0 + py1 + zl) / 2, &self.z_label, BLACK);
        // Grey swatch for the cells without a value, under the plot on the right.
        if any_missing && !self.missing_label.is_empty() {
            let tw = self.missing_label.len() as i32 * GLYPH;
            let sy = h - 14 - GLYPH;
            let sx = w - 12 - tw - 8 - GLYPH;
            c.fill_rect(sx, sy, GLYPH, GLYPH, MISSING);
            c.hline(sx, sx + GLYPH, sy, BLACK);
            c.hline(sx, sx + GLYPH, sy + GLYPH, BLACK);
            c.vline(sx, sy, sy + GLYPH, BLACK);
            c.vline(sx + GLYPH, sy, sy + GLYPH, BLACK);
            c.text(sx + GLYPH + 8, sy, &self.missing_label, BLACK);
        }

        // Title and axis labels.
        let tw = self.title.len() as i32 * GLYPH;
        c.text(((w - tw) / 2).max(4), 14, &self.title, BLACK);
        let xw = self.x_label.len() as i32 * GLYPH;
        c.text((px0 + px1 - xw) / 2, h - 14 - GLYPH, &self.x_label, BLACK);
        let yw = self.y_label.len() as i32 * GLYPH;
        c.text_up(12, (py0 + py1 + yw) / 2, &self.y_label, BLACK);
        Ok(c)
    }

    /// Renders and encodes as an 8-bit RGB PNG.
    pub fn to_png(&self) -> Result<Vec<u8>, String> {
        self.render()?.to_png()
    }

    /// Renders and writes a PNG file.
    pub fn save(&self, path: &Path) -> Result<(), String> {
        let bytes = self.to_png()?;
        std::fs::write(path, bytes).map_err(|e| format!("writing {}: {e}", path.display()))
    }
}

/// An anti-aliased ring of radius `r` and width `width` centred at (cx, cy), clipped.
fn ring(
    c: &mut Canvas,
    cx: f64,
    cy: f64,
    r: f64,
    width: f64,
    colour: Rgb,
    (x0, y0, x1, y1): (i32, i32, i32, i32),
) {
    let reach = (r + width + 1.0).ceil() as i32;
    let (icx, icy) = (cx.round() as i32, cy.round() as i32);
    for y in (icy - reach).max(y0)..=(icy + reach).min(y1) {
        for x in (icx - reach).max(x0)..=(icx + reach).min(x1) {
            let d = ((x as f64 - cx).powi(2) + (y as f64 - cy).powi(2)).sqrt();
            let a = (0.5 * width + 0.5 - (d - r).abs()).clamp(0.0, 1.0);
            c.blend(x, y, colour, a);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Heatmap {
        let (nx, ny) = (7, 5);
        let values = (0..nx * ny)
            .map(|i| {
                if i % 6 == 0 {
                    None
                } else {
                    Some(i as f64 / 5.0 - 8.0)
                }
            })
            .collect();
        Heatmap::new("t", "x", "y", "z", (nx, ny), values)
            .x_range(0.0, 7.0)
            .y_range(-5.0, 0.0)
            .y_decades(true)
            .z_range(-8.0, -1.0)
            .z_decades(true)
            .mark(3.5, -2.5)
            .z_mark(-2.0)
    }

    #[test]
    fn renders_deterministically() {
        let a = sample().to_png().unwrap();
        assert_eq!(a, sample().to_png().unwrap());
        assert_eq!(&a[1..4], b"PNG");
    }

    #[test]
    fn colours_follow_the_values() {
        assert_eq!(viridis(0.0), VIRIDIS[0]);
        assert_eq!(viridis(1.0), VIRIDIS[8]);
        assert_eq!(viridis(2.0), VIRIDIS[8]);
        // The bottom-left cell has no value (grey), the one to its right a value.
        let c = sample().render().unwrap();
        let at = |x: usize, y: usize| {
            let i = (y * c.width as usize + x) * 3;
            [c.rgb[i], c.rgb[i + 1], c.rgb[i + 2]]
        };
        let mut greys = 0;
        for y in 0..c.height as usize {
            for x in 0..c.width as usize {
                greys += (at(x, y) == MISSING) as usize;
            }
        }
        assert!(greys > 1000, "{greys}");
    }

    #[test]
    fn refuses_bad_shapes() {
        let h = Heatmap::new("t", "x", "y", "z", (2, 2), vec![Some(1.0); 3]);
        assert!(h.render().is_err());
        let h = Heatmap::new("t", "x", "y", "z", (2, 2), vec![Some(1.0); 4]).z_range(1.0, 1.0);
        assert!(h.render().is_err());
    }
}
