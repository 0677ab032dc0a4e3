//! The golden DEM tile of `tools/goldens/dem_crossing.py` (`tests/data/dem_tile.csv`, the
//! contract's DEM CSV), shared by the tests that fly over it.

use core_math::earth::dem::DemGrid;

const TILE_CSV: &str = include_str!("../data/dem_tile.csv");

/// The tile's grid and its heights (m, row-major from the south).
pub fn tile_data() -> (DemGrid, Vec<f64>) {
    let mut lines = TILE_CSV.lines();
    assert_eq!(
        lines.next().unwrap(),
        "lat0_deg,lon0_deg,dlat_deg,dlon_deg,nrows,ncols"
    );
    let g: Vec<f64> = lines
        .next()
        .unwrap()
        .split(',')
        .map(|x| x.parse().unwrap())
        .collect();
    let grid = DemGrid {
        lat0_deg: g[0],
        lon0_deg: g[1],
        dlat_deg: g[2],
        dlon_deg: g[3],
        nrows: g[4] as usize,
        ncols: g[5] as usize,
    };
    let heights: Vec<f64> = lines
        .flat_map(|l| l.split(',').map(|x| x.parse::<f64>().unwrap()))
        .collect();
    (grid, heights)
}
