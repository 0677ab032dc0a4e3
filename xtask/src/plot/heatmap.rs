//! Heatmaps to PNG: a regular grid of cells coloured by value (plotters' viridis), a
//! colour bar with labelled ticks, linear or decade axes, cells without a value drawn
//! grey, optional ring markers. Same font, axes and encoding as the line plots of
//! [`super::Plot`], and the same bytes on every run.
//!
//! ```ignore
//! let map = Heatmap {
//!     y_range: (-5.0, 2.0),
//!     y_decades: true,
//!     z_range: (-10.0, -4.0),
//!     z_decades: true,
//!     ..Heatmap::new("Title", "x (unit)", "y (unit)", "log10 err", (nx, ny), values)
//! };
//! map.save(Path::new("out.png"))?;
//! ```

use anyhow::{bail, Result};
use std::path::Path;

use plotters::prelude::*;

use super::{
    check_size, drawing, encode_png, labelled_chart, render_rgb, text, write_png, y_label_area,
    Area, Axis, Rgb, DESC_PX, LABEL_PX, MARGIN, MAX_TICKS, TICK_PX, X_LABEL_AREA,
};

/// Colour of a cell without a value.
pub const MISSING: Rgb = [205, 205, 205];

/// Width of the colour bar (pixels).
const BAR_PX: u32 = 26;
/// Bands the colour bar is drawn in.
const BAR_BANDS: usize = 256;

/// The viridis colour of t in [0, 1] (clamped; a non-finite t gets the low end).
pub fn viridis(t: f64) -> RGBColor {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    ViridisRGB.get_color(t)
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
            y_decades: false,
            z_decades: false,
            marks: Vec::new(),
            z_marks: Vec::new(),
            missing_label: "no value".to_string(),
            width: 860,
            height: 600,
        }
    }

    fn axis((lo, hi): (f64, f64), decades: bool) -> Result<Axis> {
        if !(lo.is_finite() && hi.is_finite() && hi > lo) {
            bail!("bad heatmap range [{lo}, {hi}]");
        }
        if decades {
            Axis::decades(lo, hi)
        } else {
            Axis::linear(lo, hi)
        }
    }

    /// The value of cell (ix, iy), if it has one.
    fn value(&self, ix: usize, iy: usize) -> Option<f64> {
        self.values[iy * self.nx + ix].filter(|v| v.is_finite())
    }

    /// Renders and encodes as an 8-bit RGB PNG.
    pub fn to_png(&self) -> Result<Vec<u8>> {
        encode_png(self.width, self.height, &self.render()?)
    }

    /// Renders and writes a PNG file.
    pub fn save(&self, path: &Path) -> Result<()> {
        write_png(path, &self.to_png()?)
    }

    /// The RGB pixels, row by row: title on top, the map on the left, the colour bar on
    /// the right with the same top and bottom.
    fn render(&self) -> Result<Vec<u8>> {
        check_size(self.width, self.height, (300, 200))?;
        if self.nx == 0 || self.ny == 0 || self.values.len() != self.nx * self.ny {
            bail!(
                "heatmap: {} values for {} x {} cells",
                self.values.len(),
                self.nx,
                self.ny
            );
        }
        let x_axis = Self::axis(self.x_range, false)?;
        let y_axis = Self::axis(self.y_range, self.y_decades)?;
        let z_axis = Self::axis(self.z_range, self.z_decades)?;
        render_rgb((self.width, self.height), &self.title, |root, body| {
            let bar_labels = y_label_area(root, &z_axis)?;
            let strip = MARGIN + BAR_PX + bar_labels + MARGIN;
            if strip + 200 > self.width {
                bail!("heatmap too narrow for its colour bar");
            }
            let (map_area, bar_area) = body.split_horizontally(self.width - strip);
            self.draw_map(&map_area, &x_axis, &y_axis)?;
            self.draw_bar(&bar_area, z_axis, bar_labels)?;
            if self.values.iter().any(|v| !v.is_some_and(f64::is_finite))
                && !self.missing_label.is_empty()
            {
                self.draw_missing_swatch(root)?;
            }
            Ok(())
        })
    }

    fn draw_map(&self, area: &Area<'_>, x_axis: &Axis, y_axis: &Axis) -> Result<()> {
        let names = (self.x_label.as_str(), self.y_label.as_str());
        let mut chart = labelled_chart(area, (x_axis, y_axis), names, false)?;
        let (x0, x1) = self.x_range;
        let (y0, y1) = self.y_range;
        let (dx, dy) = ((x1 - x0) / self.nx as f64, (y1 - y0) / self.ny as f64);
        let (z0, z1) = self.z_range;
        let cells = (0..self.ny).flat_map(|iy| (0..self.nx).map(move |ix| (ix, iy)));
        chart
            .draw_series(cells.map(|(ix, iy)| {
                let colour = match self.value(ix, iy) {
                    Some(z) => viridis((z - z0) / (z1 - z0)),
                    None => super::rgb(MISSING),
                };
                let (xa, ya) = (x0 + ix as f64 * dx, y0 + iy as f64 * dy);
                Rectangle::new([(xa, ya), (xa + dx, ya + dy)], colour.filled())
            }))
            .map_err(drawing)?;
        // A black ring around a white one: visible on any colour.
        chart
            .draw_series(self.marks.iter().flat_map(|&p| {
                [
                    Circle::new(p, 9, BLACK.stroke_width(3)),
                    Circle::new(p, 6, WHITE.stroke_width(2)),
                ]
            }))
            .map_err(drawing)?;
        super::frame(&chart)
    }

    /// The colour bar: z from bottom to top, ticks and the z label on its right, each z
    /// mark a black line with a white core across it.
    fn draw_bar(&self, area: &Area<'_>, z_axis: Axis, labels_px: u32) -> Result<()> {
        let (z0, z1) = self.z_range;
        let mut chart = ChartBuilder::on(area)
            .margin(MARGIN)
            .x_label_area_size(X_LABEL_AREA)
            .right_y_label_area_size(labels_px)
            .build_cartesian_2d(Axis::linear(0.0, 1.0)?, z_axis.clone())
            .map_err(drawing)?;
        let z_fmt = |v: &f64| z_axis.label(*v);
        chart
            .configure_mesh()
            .disable_mesh()
            .disable_x_axis()
            .y_desc(&self.z_label)
            .y_labels(MAX_TICKS)
            .y_label_formatter(&z_fmt)
            .label_style(text(LABEL_PX))
            .axis_desc_style(text(DESC_PX))
            .set_all_tick_mark_size(TICK_PX)
            .draw()
            .map_err(drawing)?;
        let band = (z1 - z0) / BAR_BANDS as f64;
        chart
            .draw_series((0..BAR_BANDS).map(|k| {
                let z = z0 + k as f64 * band;
                let colour = viridis((k as f64 + 0.5) / BAR_BANDS as f64);
                Rectangle::new([(0.0, z), (1.0, z + band)], colour.filled())
            }))
            .map_err(drawing)?;
        let marks = self.z_marks.iter().filter(|&&z| (z0..=z1).contains(&z));
        chart
            .draw_series(marks.flat_map(|&z| {
                [
                    PathElement::new([(0.0, z), (1.0, z)], BLACK.stroke_width(5)),
                    PathElement::new([(0.0, z), (1.0, z)], WHITE.stroke_width(1)),
                ]
            }))
            .map_err(drawing)?;
        super::frame(&chart)
    }

    /// A grey square and `missing_label` in the bottom right corner of the figure.
    fn draw_missing_swatch(&self, root: &Area<'_>) -> Result<()> {
        let style = text(LABEL_PX);
        let (tw, th) = root
            .estimate_text_size(&self.missing_label, &style)
            .map_err(drawing)?;
        let side = LABEL_PX as i32;
        let (w, h) = (self.width as i32, self.height as i32);
        let y = h - MARGIN as i32 - side;
        let tx = w - MARGIN as i32 - tw as i32;
        let sx = tx - 8 - side;
        let square = [(sx, y), (sx + side, y + side)];
        root.draw(&Rectangle::new(square, super::rgb(MISSING).filled()))
            .map_err(drawing)?;
        root.draw(&Rectangle::new(square, BLACK)).map_err(drawing)?;
        root.draw(&Text::new(
            self.missing_label.clone(),
            (tx, y + (side - th as i32) / 2),
            style,
        ))
        .map_err(drawing)?;
        Ok(())
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
        Heatmap {
            x_range: (0.0, 7.0),
            y_range: (-5.0, 0.0),
            y_decades: true,
            z_range: (-8.0, -1.0),
            z_decades: true,
            marks: vec![(3.5, -2.5)],
            z_marks: vec![-2.0],
            ..Heatmap::new("t", "x", "y", "z", (nx, ny), values)
        }
    }

    /// The maps under docs/stability/ are committed: regenerating one must give the same
    /// bytes.
    #[test]
    fn renders_deterministically() {
        let a = sample().to_png().unwrap();
        assert_eq!(a, sample().to_png().unwrap());
        assert_eq!(&a[1..4], b"PNG");
    }

    #[test]
    fn colours_follow_the_values() {
        assert_eq!(viridis(0.0), RGBColor(68, 1, 84));
        assert_eq!(viridis(1.0), RGBColor(254, 232, 37));
        assert_eq!(viridis(2.0), viridis(1.0));
        assert_eq!(viridis(f64::NAN), viridis(0.0));
        // Six of the 35 cells have no value: a good part of the map is grey.
        let rgb = sample().render().unwrap();
        let greys = rgb.chunks(3).filter(|px| *px == MISSING).count();
        assert!(greys > 5000, "{greys}");
    }

    #[test]
    fn refuses_bad_shapes() {
        let h = Heatmap::new("t", "x", "y", "z", (2, 2), vec![Some(1.0); 3]);
        assert!(h.to_png().is_err());
        let h = Heatmap {
            z_range: (1.0, 1.0),
            ..Heatmap::new("t", "x", "y", "z", (2, 2), vec![Some(1.0); 4])
        };
        assert!(h.to_png().is_err());
    }
}
