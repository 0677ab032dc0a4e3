//! What every stability map shares, whatever the model: the spec of a 2-D map of the
//! envelope, the sweep of its cells (each the worst of a few sub-samples) over every
//! core, the cells' lookup and their heatmaps.

use anyhow::Result;
use std::path::Path;

use crate::plot::heatmap::Heatmap;

/// One 2-D map of the envelope, whose samples are points of type `P`.
pub struct Spec<P> {
    /// File stem under docs/stability/ and key in the document.
    pub key: &'static str,
    /// The map's letter in the document.
    pub letter: &'static str,
    pub title: &'static str,
    pub x_label: &'static str,
    pub y_label: &'static str,
    pub x_range: (f64, f64),
    pub y_range: (f64, f64),
    /// The y coordinate is log10 of the quantity (decade ticks).
    pub y_decades: bool,
    /// Cells and sub-samples per cell (full run).
    pub nx: usize,
    pub ny: usize,
    pub sub: usize,
    /// The point of sub-sample `s` at (x, y); None where the map has none.
    pub point: fn(x: f64, y: f64, s: usize) -> Option<P>,
    /// What the other variables are, for the document.
    pub others: &'static str,
    /// Label of the grey cells (no sample there).
    pub missing: &'static str,
}

/// One PNG of a map: file suffix, title, colour-bar label, z range (log10 unless
/// `linear`), the plotted value of a cell, and a line across the colour bar (the stated
/// bound, in the value's units before the log).
pub struct Panel<C> {
    pub suffix: &'static str,
    pub title: &'static str,
    pub z_label: &'static str,
    pub z_range: (f64, f64),
    pub linear: bool,
    pub value: fn(&C) -> f64,
    pub bound: Option<f64>,
}

/// The largest value of one quantity over a cell's samples (or an aggregate's cells),
/// and the sample behind it: each maximum a cell keeps is one of these, so that the
/// value and where it was found cannot drift apart.
#[derive(Clone, Copy, Debug)]
pub struct Worst<S> {
    pub max: f64,
    pub at: Option<S>,
}

impl<S> Default for Worst<S> {
    fn default() -> Self {
        Worst { max: 0.0, at: None }
    }
}

impl<S: Copy> Worst<S> {
    /// Takes `v` at `at` when nothing is held yet or `v` is larger (the first sample is
    /// kept whatever its value, so that a cell with samples always names one).
    pub fn offer(&mut self, v: f64, at: S) {
        self.take(v, Some(at));
    }

    /// Takes `v` at `at` only when it is larger than what is held (0 while empty).
    pub fn raise(&mut self, v: f64, at: S) {
        if v > self.max {
            *self = Worst {
                max: v,
                at: Some(at),
            };
        }
    }

    /// Folds another cell's maximum of the same quantity into this one, as `offer`.
    pub fn merge(&mut self, o: &Worst<S>) {
        self.take(o.max, o.at);
    }

    /// Folds another cell's maximum in, as `raise`.
    pub fn merge_raise(&mut self, o: &Worst<S>) {
        if o.max > self.max {
            *self = *o;
        }
    }

    fn take(&mut self, v: f64, at: Option<S>) {
        if self.at.is_none() || v > self.max {
            *self = Worst { max: v, at };
        }
    }
}

/// A map cell: what it keeps of its sub-samples.
pub trait Cell: Clone + Send {
    type Point: Sync + 'static;
    /// A cell with no sample yet.
    fn empty() -> Self;
    /// Evaluates one sub-sample and keeps what the cell keeps of it.
    fn sample(&mut self, point: &Self::Point);
    /// The samples it holds.
    fn n(&self) -> u64;
    /// Folds another cell (or aggregate of cells) into this one.
    fn merge(&mut self, other: &Self);
    /// Each stated bound this cell (or aggregate) breaks, and each refusal, one line each.
    fn broken(&self) -> Vec<String>;
}

/// What breaks a stated bound anywhere in `maps`, each line headed by its map's key.
pub fn broken<C: Cell>(maps: &[Map<C>]) -> Vec<String> {
    let key_each = |m: &Map<C>| {
        let key = m.spec.key;
        let bad = m.aggregate(|_, _| true).broken();
        bad.into_iter().map(move |b| format!("{key}: {b}"))
    };
    maps.iter().flat_map(key_each).collect()
}

/// All the cases of `maps`: each map's cells merged, then the maps in order.
pub fn merged<C: Cell>(maps: &[Map<C>]) -> C {
    let mut all = C::empty();
    for m in maps {
        all.merge(&m.aggregate(|_, _| true));
    }
    all
}

/// One column of a table of cells: its header, and a cell's entry.
pub type Column<C> = (&'static str, fn(&C) -> String);

/// The markdown table of `rows` (name, cell): a first column headed `first`, then
/// `columns`.
pub fn table<C>(first: &str, columns: &[Column<C>], rows: &[(String, C)]) -> String {
    let header: Vec<&str> = std::iter::once(first)
        .chain(columns.iter().map(|c| c.0))
        .collect();
    let entries = |(name, c): &(String, C)| {
        let each = columns.iter().map(|(_, f)| f(c));
        std::iter::once(name.clone())
            .chain(each)
            .collect::<Vec<_>>()
    };
    let rows: Vec<Vec<String>> = rows.iter().map(entries).collect();
    crate::markdown::table(&header, &rows)
}

/// A swept map: the cells, row-major from the bottom row (index iy * nx + ix).
pub struct Map<C: Cell> {
    pub spec: &'static Spec<C::Point>,
    pub nx: usize,
    pub ny: usize,
    /// Sub-samples per cell.
    pub sub: usize,
    pub cells: Vec<C>,
}

impl<C: Cell> Map<C> {
    /// The grid as the document describes it, with the cases `n` of its sweep.
    pub fn grid_text(&self, n: u64) -> String {
        let (nx, ny, sub) = (self.nx, self.ny, self.sub);
        format!("{nx} x {ny} cells, {sub} sub-samples each, {n} cases")
    }

    /// Sweeps `spec` with `nx` x `ny` cells and `sub` sub-samples per cell, on every core.
    pub fn sweep(spec: &'static Spec<C::Point>, nx: usize, ny: usize, sub: usize) -> Self {
        let (x0, x1) = spec.x_range;
        let (y0, y1) = spec.y_range;
        let (dx, dy) = ((x1 - x0) / nx as f64, (y1 - y0) / ny as f64);
        let cell = |ix: usize, iy: usize| {
            let mut c = C::empty();
            for s in 0..sub {
                let (fx, fy) = jitter(s, sub);
                let (x, y) = (x0 + (ix as f64 + fx) * dx, y0 + (iy as f64 + fy) * dy);
                if let Some(pt) = (spec.point)(x, y, s) {
                    c.sample(&pt);
                }
            }
            c
        };
        Map {
            spec,
            nx,
            ny,
            sub,
            cells: sweep_rows(nx, ny, cell),
        }
    }

    /// Cell centre in map coordinates.
    pub fn centre(&self, ix: usize, iy: usize) -> (f64, f64) {
        let (x0, x1) = self.spec.x_range;
        let (y0, y1) = self.spec.y_range;
        (
            x0 + (ix as f64 + 0.5) * (x1 - x0) / self.nx as f64,
            y0 + (iy as f64 + 0.5) * (y1 - y0) / self.ny as f64,
        )
    }

    /// One value per cell (None where the cell has no sample), for a heatmap.
    pub fn values(&self, f: impl Fn(&C) -> f64) -> Vec<Option<f64>> {
        self.cells
            .iter()
            .map(|c| if c.n() > 0 { Some(f(c)) } else { None })
            .collect()
    }

    /// The cell (ix, iy) maximising `f` over the cells with samples.
    pub fn argmax(&self, f: impl Fn(&C) -> f64) -> Option<(usize, usize)> {
        (0..self.cells.len())
            .filter(|&i| self.cells[i].n() > 0)
            .max_by(|&a, &b| f(&self.cells[a]).total_cmp(&f(&self.cells[b])))
            .map(|i| (i % self.nx, i / self.nx))
    }

    /// All cells whose centre (x, y) passes `keep`, merged.
    pub fn aggregate(&self, keep: impl Fn(f64, f64) -> bool) -> C {
        let mut a = C::empty();
        for iy in 0..self.ny {
            for ix in 0..self.nx {
                let (x, y) = self.centre(ix, iy);
                if keep(x, y) {
                    a.merge(&self.cells[iy * self.nx + ix]);
                }
            }
        }
        a
    }

    pub fn samples(&self) -> u64 {
        self.cells.iter().map(C::n).sum()
    }
}

impl<C: Cell> Map<C> {
    /// Writes one PNG per panel into `dir`, named `<key>-<suffix>.png`: the panel's value
    /// over the cells, titled by the map's letter, the largest cell ringed and the bound
    /// marked on the colour bar.
    pub fn write_pngs<'a>(
        &self,
        panels: impl IntoIterator<Item = &'a Panel<C>>,
        dir: &Path,
    ) -> Result<()>
    where
        C: 'a,
    {
        let s = self.spec;
        for p in panels {
            let title = format!("{}: {}", s.letter, p.title);
            let values = self.values(p.value);
            let bound = p.bound.map(|b| if p.linear { b } else { b.log10() });
            let argmax = self.argmax(p.value);
            let h = Heatmap {
                x_range: s.x_range,
                y_range: s.y_range,
                z_range: p.z_range,
                y_decades: s.y_decades,
                z_decades: !p.linear,
                marks: argmax
                    .map(|(ix, iy)| self.centre(ix, iy))
                    .into_iter()
                    .collect(),
                z_marks: bound.into_iter().collect(),
                missing_label: s.missing.into(),
                ..Heatmap::new(
                    &title,
                    s.x_label,
                    s.y_label,
                    p.z_label,
                    (self.nx, self.ny),
                    values,
                )
            };
            h.save(&dir.join(format!("{}-{}.png", s.key, p.suffix)))?;
        }
        Ok(())
    }
}

/// Sweeps every map of `specs` with its cells divided by `div` each way and `sub`
/// sub-samples per cell (None: the spec's).
pub fn sweep_all<C: Cell>(
    specs: &'static [Spec<C::Point>],
    div: usize,
    sub: Option<usize>,
) -> Vec<Map<C>> {
    let sweep = |s| Map::sweep(s, s.nx / div, s.ny / div, sub.unwrap_or(s.sub));
    specs.iter().map(sweep).collect()
}

/// Sub-sample `s` of `sub`: offsets in (0, 1) within the cell, stratified in x and
/// spread by the golden ratio in y (deterministic).
pub fn jitter(s: usize, sub: usize) -> (f64, f64) {
    let fx = (s as f64 + 0.5) / sub as f64;
    let fy = (0.5 + s as f64 * 0.618_033_988_749_894_9).fract();
    (fx, fy)
}

/// `cell(ix, iy)` over an nx x ny grid, rows spread over the available threads, in
/// row-major order (the same result for any number of threads).
fn sweep_rows<C: Clone + Send>(
    nx: usize,
    ny: usize,
    cell: impl Fn(usize, usize) -> C + Sync,
) -> Vec<C> {
    let workers = std::thread::available_parallelism().map_or(1, |n| n.get());
    let mut rows: Vec<Vec<C>> = vec![Vec::new(); ny];
    std::thread::scope(|scope| {
        let handles: Vec<_> = (0..workers)
            .map(|w| {
                let cell = &cell;
                scope.spawn(move || {
                    (w..ny)
                        .step_by(workers)
                        .map(|iy| (iy, (0..nx).map(|ix| cell(ix, iy)).collect::<Vec<_>>()))
                        .collect::<Vec<_>>()
                })
            })
            .collect();
        for h in handles {
            for (iy, row) in h.join().expect("sweep worker panicked") {
                rows[iy] = row;
            }
        }
    });
    rows.into_iter().flatten().collect()
}
