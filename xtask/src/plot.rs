//! Line plots and heatmaps to PNG, drawn by `plotters` on its bitmap backend.
//!
//! Reproducible by construction: the text is set in the DejaVu Sans file bundled in
//! `xtask/fonts/` (loaded through plotters' `ab_glyph` feature, so no system font is ever
//! looked up) and the pixels are encoded by the `png` crate without a time stamp. The
//! same plot gives the same bytes on every run and every machine.
//!
//! ```ignore
//! Plot::new("Title", "x (unit)", "y (unit)")
//!     .series(Series::line("first", points))
//!     .series(Series::line("floor", floor).dashed())
//!     .save(Path::new("out.png"))?;
//! ```

use anyhow::{anyhow, bail, Context, Result};
use std::ops::Range;
use std::path::Path;
use std::sync::OnceLock;

use plotters::coord::ranged1d::{
    BoldPoints, KeyPointHint, NoDefaultFormatting, Ranged, ValueFormatter,
};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;

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

const GRID: RGBColor = RGBColor(225, 225, 225);
const GRID_MINOR: RGBColor = RGBColor(242, 242, 242);

/// Text sizes (pixels per em) of the title, the axis names and the tick labels.
const TITLE_PX: f64 = 26.0;
const DESC_PX: f64 = 22.0;
const LABEL_PX: f64 = 20.0;
/// Length of the tick marks (pixels); the labels stand twice that from the axis.
const TICK_PX: u32 = 6;
/// Room around the figure and between its parts (pixels).
const MARGIN: u32 = 14;
/// At most this many labelled ticks per axis (plotters picks 1-2-5 steps within it).
const MAX_TICKS: usize = 10;

/// The bundled font, registered with plotters as its default family once per process.
fn font_ready() -> Result<()> {
    static READY: OnceLock<bool> = OnceLock::new();
    const TTF: &[u8] = include_bytes!("../fonts/DejaVuSans.ttf");
    if !*READY.get_or_init(|| {
        plotters::style::register_font("sans-serif", FontStyle::Normal, TTF).is_ok()
    }) {
        bail!("the bundled font xtask/fonts/DejaVuSans.ttf is unreadable");
    }
    Ok(())
}

fn text(px: f64) -> TextStyle<'static> {
    TextStyle::from(("sans-serif", px).into_font()).color(&BLACK)
}

fn rgb(c: Rgb) -> RGBColor {
    RGBColor(c[0], c[1], c[2])
}

/// Any plotters error as our error text.
fn drawing<E: std::fmt::Debug>(e: E) -> anyhow::Error {
    anyhow!("plotting: {e:?}")
}

/// One labelled curve.
#[derive(Clone, Debug)]
pub struct Series {
    pub label: String,
    /// (x, y) in data units; non-finite points (and y <= 0 on a log axis) break the line.
    pub points: Vec<(f64, f64)>,
    /// None: the next palette colour.
    pub colour: Option<Rgb>,
    pub dashed: bool,
    /// Line width in pixels (drawn to the nearest whole pixel).
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

    fn style(&self, index: usize) -> ShapeStyle {
        let colour = self.colour.unwrap_or(PALETTE[index % PALETTE.len()]);
        rgb(colour).stroke_width(self.width.round().max(1.0) as u32)
    }
}

/// Where the legend box goes inside the plot area.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Legend {
    TopRight,
    BottomRight,
    BottomLeft,
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
    /// None: the data's extent (y with a margin of 5 %).
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
    pub fn to_png(&self) -> Result<Vec<u8>> {
        encode_png(self.width, self.height, &self.render()?)
    }

    /// Renders and writes a PNG file.
    pub fn save(&self, path: &Path) -> Result<()> {
        write_png(path, &self.to_png()?)
    }

    /// A y value as plotted: log10 of it on a log axis; None where it cannot be drawn.
    fn plotted_y(&self, y: f64) -> Option<f64> {
        match self.log_y {
            true if y > 0.0 => Some(y.log10()).filter(|v| v.is_finite()),
            true => None,
            false => Some(y).filter(|v| v.is_finite()),
        }
    }

    fn axes(&self) -> Result<(Axis, Axis)> {
        let points = || self.series.iter().flat_map(|s| &s.points);
        let drawable = || {
            points().filter_map(|&(x, y)| Some((x, self.plotted_y(y)?)).filter(|p| p.0.is_finite()))
        };
        let x = match self.x_range {
            Some((lo, hi)) => Axis::linear(lo, hi)?,
            None => {
                let (lo, hi) = extent(drawable().map(|p| p.0)).context("no finite data to plot")?;
                Axis::linear(lo, hi)?
            }
        };
        let y = match (self.y_range, self.log_y) {
            (Some((lo, hi)), false) => Axis::linear(lo, hi)?,
            (Some((lo, hi)), true) => {
                if !(lo > 0.0 && hi > lo) {
                    bail!("log y range must be positive");
                }
                Axis::decades(lo.log10(), hi.log10())?
            }
            (None, log) => {
                let (lo, hi) = extent(drawable().map(|p| p.1)).context(if log {
                    "no positive data for a log axis"
                } else {
                    "no finite data to plot"
                })?;
                let pad = 0.05 * (hi - lo);
                if log {
                    Axis::decades(lo - pad.max(0.02), hi + pad.max(0.02))?
                } else {
                    Axis::linear(lo - pad, hi + pad)?
                }
            }
        };
        Ok((x, y))
    }

    /// The RGB pixels, row by row.
    fn render(&self) -> Result<Vec<u8>> {
        check_size(self.width, self.height, (200, 150))?;
        let (x_axis, y_axis) = self.axes()?;
        render_rgb((self.width, self.height), &self.title, |_, body| {
            let names = (self.x_label.as_str(), self.y_label.as_str());
            let mut chart = labelled_chart(body, (&x_axis, &y_axis), names, true)?;
            frame(&chart)?;
            for (i, s) in self.series.iter().enumerate() {
                let style = s.style(i);
                for (k, run) in self.runs(s).into_iter().enumerate() {
                    let drawn = match s.dashed {
                        true => chart.draw_series([DashedPathElement::new(run, 10, 6, style)]),
                        false => chart.draw_series([PathElement::new(run, style)]),
                    };
                    let drawn = drawn.map_err(drawing)?;
                    if k == 0 && !s.label.is_empty() {
                        let dashed = s.dashed;
                        drawn.label(&s.label).legend(move |(x, y)| {
                            let key = [(x, y), (x + 30, y)];
                            match dashed {
                                true => DashedPathElement::new(key, 10, 6, style).into_dyn(),
                                false => PathElement::new(key, style).into_dyn(),
                            }
                        });
                    }
                }
            }
            let position = match self.legend {
                Legend::TopRight => SeriesLabelPosition::UpperRight,
                Legend::BottomRight => SeriesLabelPosition::LowerRight,
                Legend::BottomLeft => SeriesLabelPosition::LowerLeft,
            };
            let labelled = self.series.iter().any(|s| !s.label.is_empty());
            if labelled {
                chart
                    .configure_series_labels()
                    .position(position)
                    .margin(10)
                    .legend_area_size(40)
                    .label_font(text(LABEL_PX))
                    .background_style(WHITE)
                    .border_style(BLACK)
                    .draw()
                    .map_err(drawing)?;
            }
            Ok(())
        })
    }

    /// The drawable stretches of a series, in plotted units.
    fn runs(&self, s: &Series) -> Vec<Vec<(f64, f64)>> {
        let mut runs = vec![Vec::new()];
        for &(x, y) in &s.points {
            match self.plotted_y(y).filter(|_| x.is_finite()) {
                Some(y) => runs.last_mut().into_iter().for_each(|r| r.push((x, y))),
                None => runs.push(Vec::new()),
            }
        }
        runs.retain(|r| !r.is_empty());
        runs
    }
}

/// The smallest and largest of `values`.
fn extent(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    values.fold(None, |acc, v| match acc {
        None => Some((v, v)),
        Some((lo, hi)) => Some((v.min(lo), v.max(hi))),
    })
}

fn check_size(width: u32, height: u32, (min_w, min_h): (u32, u32)) -> Result<()> {
    if width < min_w || height < min_h || width > 8000 || height > 8000 {
        bail!("plot size {width}x{height} out of range");
    }
    Ok(())
}

/// Height under the plot: one line of tick labels and one of the axis name.
const X_LABEL_AREA: u32 = (LABEL_PX + DESC_PX + 24.0) as u32;

/// The widths (pixels) of an axis's tick labels, in order.
fn label_widths(area: &Area<'_>, axis: &Axis) -> Result<Vec<u32>> {
    let width = |v| area.estimate_text_size(&axis.label(v), &text(LABEL_PX));
    let ticks = axis.key_points(BoldPoints(MAX_TICKS)).into_iter();
    ticks.map(|v| Ok(width(v).map_err(drawing)?.0)).collect()
}

/// Width left of the plot: the widest tick label and the (rotated) axis name.
fn y_label_area(area: &Area<'_>, axis: &Axis) -> Result<u32> {
    let widest = label_widths(area, axis)?.into_iter().max().unwrap_or(0);
    Ok(widest + DESC_PX as u32 + 24)
}

/// The drawing area of a figure (RGB pixels in memory).
type Area<'a> = DrawingArea<BitMapBackend<'a>, Shift>;

/// A figure of `width` x `height` pixels with `title` on top: `draw` gets the whole
/// figure and the part under the title. Returns the RGB pixels, row by row.
fn render_rgb(
    (width, height): (u32, u32),
    title: &str,
    draw: impl FnOnce(&Area<'_>, &Area<'_>) -> Result<()>,
) -> Result<Vec<u8>> {
    font_ready()?;
    let mut pixels = vec![255u8; width as usize * height as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut pixels, (width, height)).into_drawing_area();
        let body = root.titled(title, text(TITLE_PX)).map_err(drawing)?;
        draw(&root, &body)?;
        root.present().map_err(drawing)?;
    }
    Ok(pixels)
}

/// A chart of `x` against `y` on `area`, both axes named (`names`) with tick labels and
/// tick marks; with `grid`, grid lines at the ticks (minor ones too on a decade axis).
fn labelled_chart<'a, 'b>(
    area: &'a Area<'b>,
    (x, y): (&Axis, &Axis),
    (x_name, y_name): (&str, &str),
    grid: bool,
) -> Result<ChartContext<'a, BitMapBackend<'b>, Cartesian2d<Axis, Axis>>> {
    let mut chart = ChartBuilder::on(area)
        .margin(MARGIN)
        .margin_right(right_margin(area, x)?)
        .x_label_area_size(X_LABEL_AREA)
        .y_label_area_size(y_label_area(area, y)?)
        .build_cartesian_2d(x.clone(), y.clone())
        .map_err(drawing)?;
    let (x_fmt, y_fmt) = (|v: &f64| x.label(*v), |v: &f64| y.label(*v));
    let mut mesh = chart.configure_mesh();
    mesh.x_desc(x_name)
        .y_desc(y_name)
        .x_labels(MAX_TICKS)
        .y_labels(MAX_TICKS)
        .x_label_formatter(&x_fmt)
        .y_label_formatter(&y_fmt)
        .label_style(text(LABEL_PX))
        .axis_desc_style(text(DESC_PX))
        .set_all_tick_mark_size(TICK_PX);
    if grid {
        mesh.bold_line_style(GRID)
            .light_line_style(GRID_MINOR)
            .max_light_lines(1);
    } else {
        mesh.disable_mesh();
    }
    mesh.draw().map_err(drawing)?;
    Ok(chart)
}

/// Room right of the plot for half of the last x tick label, centred on the frame.
fn right_margin(area: &Area<'_>, x_axis: &Axis) -> Result<u32> {
    let last = label_widths(area, x_axis)?.pop().unwrap_or(0);
    Ok(MARGIN.max(last / 2 + 6))
}

/// A black frame around the plot area (the mesh draws only the left and bottom axes).
fn frame<DB: DrawingBackend>(chart: &ChartContext<'_, DB, Cartesian2d<Axis, Axis>>) -> Result<()> {
    let (x, y) = (chart.x_range(), chart.y_range());
    chart
        .plotting_area()
        .draw(&Rectangle::new([(x.start, y.start), (x.end, y.end)], BLACK))
        .map_err(drawing)
}

/// An axis in plotted units: the value itself, or log10 of it on a decade axis, whose
/// ticks fall on decades (also on 2 and 5 times a decade when it spans few) with the
/// other whole multiples as minor grid lines. Linear ticks are plotters' own.
#[derive(Clone, Debug)]
pub struct Axis {
    lo: f64,
    hi: f64,
    decades: bool,
}

impl Axis {
    pub fn linear(lo: f64, hi: f64) -> Result<Axis> {
        Axis::new(lo, hi, false)
    }

    pub fn decades(lo: f64, hi: f64) -> Result<Axis> {
        Axis::new(lo, hi, true)
    }

    fn new(lo: f64, hi: f64, decades: bool) -> Result<Axis> {
        if !(lo.is_finite() && hi.is_finite()) {
            bail!("bad axis range [{lo}, {hi}]");
        }
        // A flat extent (one value) still gets an axis around it.
        let (lo, hi) = if hi - lo > 1e-12 * (1.0 + lo.abs()) {
            (lo, hi)
        } else if hi >= lo {
            (lo - 0.5 * (1.0 + lo.abs()), hi + 0.5 * (1.0 + hi.abs()))
        } else {
            bail!("bad axis range [{lo}, {hi}]");
        };
        Ok(Axis { lo, hi, decades })
    }

    /// Labelled tick positions, and the minor ones too when `minor`.
    fn ticks(&self, max: usize, minor: bool) -> Vec<f64> {
        if !self.decades {
            let plain = RangedCoordf64::from(self.lo..self.hi);
            return plain.key_points(BoldPoints(max));
        }
        let few = self.hi - self.lo < 2.5;
        let mut ticks = Vec::new();
        for d in self.lo.floor() as i32..=self.hi.ceil() as i32 {
            for m in 1..10 {
                let p = (m as f64).log10() + d as f64;
                let inside = p >= self.lo - 1e-9 && p <= self.hi + 1e-9;
                let labelled = m == 1 || (few && (m == 2 || m == 5));
                if inside && (labelled || minor) {
                    ticks.push(p);
                }
            }
        }
        ticks
    }

    /// The text of the tick at `v`: on a decade axis the value 10^v (plain from 0.001 to
    /// 10000, as 1e-5 beyond); on a linear one with the decimals its tick step needs.
    pub fn label(&self, v: f64) -> String {
        if self.decades {
            let d = v.floor();
            let m = 10f64.powf(v - d).round() as i32;
            let (m, d) = if m == 10 {
                (1, d as i32 + 1)
            } else {
                (m, d as i32)
            };
            return if (-3..=4).contains(&d) {
                let dec = (-d).max(0) as usize;
                format!("{:.dec$}", m as f64 * 10f64.powi(d))
            } else {
                format!("{m}e{d}")
            };
        }
        let ticks = self.ticks(MAX_TICKS, false);
        let step = ticks
            .windows(2)
            .map(|w| w[1] - w[0])
            .fold(f64::INFINITY, f64::min);
        let dec = if step.is_finite() {
            (-(step.log10() + 1e-9).floor()).max(0.0) as usize
        } else {
            0
        };
        // Avoid "-0.0".
        let v = if v.abs() < 1e-9 * (self.hi - self.lo) {
            0.0
        } else {
            v
        };
        format!("{v:.dec$}")
    }
}

impl Ranged for Axis {
    type FormatOption = NoDefaultFormatting;
    type ValueType = f64;

    fn map(&self, v: &f64, (from, to): (i32, i32)) -> i32 {
        let t = (v - self.lo) / (self.hi - self.lo);
        (f64::from(from) + t * f64::from(to - from)).round() as i32
    }

    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        let minor = hint.weight().allow_light_points() && hint.max_num_points() > 0;
        self.ticks(hint.bold_points(), minor)
    }

    fn range(&self) -> Range<f64> {
        self.lo..self.hi
    }
}

impl ValueFormatter<f64> for Axis {
    fn format_ext(&self, v: &f64) -> String {
        self.label(*v)
    }
}

/// Encodes RGB pixels as an 8-bit RGB PNG (no time stamp: the bytes depend only on the
/// pixels).
fn encode_png(width: u32, height: u32, rgb: &[u8]) -> Result<Vec<u8>> {
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, width, height);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_compression(png::Compression::High);
    let mut w = enc.write_header().context("png")?;
    w.write_image_data(rgb).context("png")?;
    w.finish().context("png")?;
    Ok(out)
}

fn write_png(path: &Path, bytes: &[u8]) -> Result<()> {
    std::fs::write(path, bytes).with_context(|| format!("writing {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Plot {
        Plot::new("t", "x (s)", "y (m)")
            .series(Series::line("a", vec![(0.0, 1.0), (1.0, 2.0), (2.0, 1.5)]))
            .series(Series::line("b", vec![(0.0, 0.5), (2.0, 0.7)]).dashed())
    }

    /// The figures under docs/ are committed: regenerating one must give the same bytes.
    #[test]
    fn renders_deterministically() {
        let a = sample().to_png().unwrap();
        assert_eq!(a, sample().to_png().unwrap());
        assert_eq!(&a[1..4], b"PNG");
        let log = sample().log_y(true);
        assert_eq!(log.to_png().unwrap(), log.to_png().unwrap());
    }

    /// Text is drawn (dark pixels in the title band), so the bundled font was found.
    #[test]
    fn draws_the_title_in_the_bundled_font() {
        let mut p = sample();
        p.title = "TITLE OF THE PLOT".into();
        let rgb = p.render().unwrap();
        let band = &rgb[..p.width as usize * 3 * 40];
        let dark = band
            .chunks(3)
            .filter(|px| px.iter().all(|&c| c < 100))
            .count();
        assert!(dark > 100, "{dark} dark pixels in the title band");
    }

    #[test]
    fn refuses_empty() {
        assert!(Plot::new("t", "x", "y").to_png().is_err());
        assert!(Plot::new("t", "x", "y")
            .log_y(true)
            .series(Series::line("neg", vec![(0.0, -1.0), (1.0, 0.0)]))
            .to_png()
            .is_err());
    }

    #[test]
    fn ticks_and_labels() {
        let d = Axis::decades(-15.0, -2.0).unwrap();
        let labelled = d.ticks(MAX_TICKS, false);
        assert_eq!(labelled.len(), 14);
        assert_eq!(d.label(labelled[0]), "1e-15");
        assert_eq!(d.label(-2.0), "0.01");
        assert_eq!(d.label(3.0), "1000");
        let short = Axis::decades(-0.5, 1.0).unwrap();
        let texts: Vec<String> = short
            .ticks(MAX_TICKS, false)
            .iter()
            .map(|&v| short.label(v))
            .collect();
        assert_eq!(texts, ["0.5", "1", "2", "5", "10"]);
        assert!(d.ticks(MAX_TICKS, true).len() > 100);
        let lin = Axis::linear(0.0, 1.0).unwrap();
        let texts: Vec<String> = lin
            .ticks(MAX_TICKS, false)
            .iter()
            .map(|&v| lin.label(v))
            .collect();
        assert_eq!(texts, ["0.0", "0.2", "0.4", "0.6", "0.8", "1.0"]);
        assert!(Axis::linear(1.0, 0.0).is_err());
    }
}
