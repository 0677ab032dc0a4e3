#!/usr/bin/env python3
"""Independent goldens for the ground from a DEM tile (shared/EARTH-MODEL.md, Part II,
"The ground from a DEM"), sharing nothing with the Rust crate's search.

Writes core-math/tests/data/dem_tile.csv (the contract's DEM CSV: a 128 x 128 tile at
0.001 deg, a broad mountain, a knife-edge ridge two rows wide, a cliff and seeded noise,
heights 1 275..4 310 m in whole metres as a bus would upload them) and
core-math/tests/data/dem_cases.csv: Part II eval rows (state and attitude in the ITRF,
so no C2T enters) with the expected outcome, the ground point and the image motion.

The crossing is found by brute force, not by the crate's Lipschitz march:
- geodetic coordinates by ERFA's eraGc2gde (Fukushima's method; the crate uses
  Vermeille's closed form);
- f(s) = h(s) - H(lat, lon) sampled along the ray every 0.2 m of path from where it
  enters the ellipsoid raised by max(H) + 1 m to where it leaves it (or enters the one
  lowered to min(H) - 1 m, below which nothing is above the surface), bilinear H from
  the contract's definition;
- the first pair of samples, both inside the tile's box, with f > 0 then f <= 0, refined
  by bisection in the path parameter to 1e-9 m; none: `outside_dem` if the ray meets
  the ellipsoid lowered to min(H) ahead, else `line_of_sight_misses_earth`.
The cases keep crossings clear of the sampling step: rays that pass within a metre of a
ridge are built to pass 3 m above or below its crest.

The image motion at the ground point: part2_motion.motion (mpmath, 50 digits, finite
differences of the projection) with the ground point r + s d.

Run from the repository root: python3 tools/goldens/dem_crossing.py
"""

import math
import os
import random

import erfa
import numpy as np

import part2_motion as p2

HERE = os.path.dirname(__file__)
DATA = os.path.join(HERE, "..", "..", "core-math", "tests", "data")
SEED = 2303
A, FL = p2.A_WGS84, p2.F_WGS84
B = A * (1 - FL)
LAT0, LON0, DLAT, DLON, NROWS, NCOLS = 35.0, 100.0, 0.001, 0.001, 128, 128
RIDGE_ROW = 90
STEP_M = 0.2


def make_tile(rng):
    h = np.zeros((NROWS, NCOLS))
    for i in range(NROWS):
        for j in range(NCOLS):
            mountain = 3000.0 * math.exp(-((i - 50) ** 2 + (j - 60) ** 2) / (2 * 18.0 ** 2))
            h[i, j] = 1300.0 + mountain + rng.uniform(-25.0, 25.0)
    # A knife-edge ridge along two rows (2 000 m above its feet over one cell: a slope
    # of 18) and a cliff of 900 m across one column step on the east side.
    h[RIDGE_ROW, :] += 2000.0
    h[RIDGE_ROW + 1, :] += 1800.0
    h[:, 100:] += 900.0
    return np.round(h)


def bilinear(tile, lat, lon):
    u = (lat - LAT0) / DLAT
    v = (lon - LON0) / DLON
    i = np.clip(np.floor(u).astype(int), 0, NROWS - 2)
    j = np.clip(np.floor(v).astype(int), 0, NCOLS - 2)
    fu, fv = u - i, v - j
    h00, h01 = tile[i, j], tile[i, j + 1]
    h10, h11 = tile[i + 1, j], tile[i + 1, j + 1]
    south = h00 + (h01 - h00) * fv
    north = h10 + (h11 - h10) * fv
    return south + (north - south) * fu


def in_box(lat, lon):
    lat1, lon1 = LAT0 + (NROWS - 1) * DLAT, LON0 + (NCOLS - 1) * DLON
    return (lat >= LAT0) & (lat <= lat1) & (lon >= LON0) & (lon <= lon1)


def raised_roots(h, r, d):
    ea, eb = A + h, B + h
    qa = (d[0] ** 2 + d[1] ** 2) / ea ** 2 + d[2] ** 2 / eb ** 2
    qb = 2 * ((r[0] * d[0] + r[1] * d[1]) / ea ** 2 + r[2] * d[2] / eb ** 2)
    qc = (r[0] ** 2 + r[1] ** 2) / ea ** 2 + r[2] ** 2 / eb ** 2 - 1
    disc = qb * qb - 4 * qa * qc
    if disc < 0:
        return None
    q = math.sqrt(disc)
    return (-qb - q) / (2 * qa), (-qb + q) / (2 * qa)


def geodetic(x):
    """(lat deg, lon deg, h m) of ITRF points x (n x 3), by ERFA."""
    elong, phi, h = erfa.gc2gde(A, FL, x)
    return np.degrees(phi), np.degrees(elong), h


def f_of(tile, r, d, s):
    x = r[None, :] + s[:, None] * d[None, :]
    lat, lon, h = geodetic(x)
    box = in_box(lat, lon)
    f = np.where(box, h - bilinear(tile, lat, lon), np.nan)
    return f, box


def crossing(tile, r, d):
    """(outcome, s): the first passage from f > 0 to f <= 0 inside the box, by samples
    every STEP_M of path and bisection."""
    top = raised_roots(tile.max() + 1.0, r, d)
    low = raised_roots(tile.min(), r, d)
    miss = "outside_dem" if (low is not None and low[1] > 0) else "line_of_sight_misses_earth"
    if top is None or top[1] <= 0:
        return miss, None
    deep = raised_roots(tile.min() - 1.0, r, d)
    s0 = max(top[0], 0.0)
    s1 = top[1] if deep is None or deep[0] < s0 else deep[0]
    dn = np.linalg.norm(d)
    n = int((s1 - s0) * dn / STEP_M) + 2
    s = np.linspace(s0, s1, n)
    f, box = f_of(tile, r, d, s)
    down = box[:-1] & box[1:] & (f[:-1] > 0) & (f[1:] <= 0)
    idx = np.nonzero(down)[0]
    if len(idx) == 0:
        return miss, None
    lo, hi = s[idx[0]], s[idx[0] + 1]
    while (hi - lo) * dn > 1e-9:
        mid = 0.5 * (lo + hi)
        fm, bm = f_of(tile, r, d, np.array([mid]))
        if fm[0] > 0:
            lo = mid
        else:
            hi = mid
    return "", hi


def itrf(lat_deg, lon_deg, h):
    return np.array(erfa.gd2gce(A, FL, math.radians(lon_deg), math.radians(lat_deg), h))


def north_east(lat_deg, lon_deg):
    la, lo = math.radians(lat_deg), math.radians(lon_deg)
    north = np.array([-math.sin(la) * math.cos(lo), -math.sin(la) * math.sin(lo), math.cos(la)])
    east = np.array([-math.sin(lo), math.cos(lo), 0.0])
    return north, east


def make_case(rng, tile, i, kind):
    """One row: a satellite 700 km up, looking at a chosen point with the line of sight
    of pixel n_px; `kind` picks the point."""
    lat1, lon1 = LAT0 + (NROWS - 1) * DLAT, LON0 + (NCOLS - 1) * DLON
    # Where the satellite is: over the tile, or off to one side for an oblique look
    # (ground distance up to 1 300 km: incidence up to about 65 degrees).
    az = rng.uniform(0, 2 * math.pi)
    off_km = {"random": rng.uniform(0, 900), "grazing_over": 1300, "grazing_clip": 1300,
              "edge": 1000, "outside": rng.uniform(0, 500), "miss": 0}[kind]
    tlat = LAT0 + rng.uniform(0.1, 0.9) * (lat1 - LAT0)
    tlon = LON0 + rng.uniform(0.1, 0.9) * (lon1 - LON0)
    if kind in ("grazing_over", "grazing_clip"):
        # From the north, across the ridge's crest (row RIDGE_ROW), 3 m over or under it,
        # with the mountain's slopes behind it.
        az = rng.uniform(-0.2, 0.2)
        tlat = LAT0 + RIDGE_ROW * DLAT
        tlon = LON0 + rng.uniform(0.2, 0.8) * (lon1 - LON0)
    if kind == "edge":
        # From the west, at a point just inside the west edge.
        az = 1.5 * math.pi
        tlon = LON0 + rng.uniform(0.5, 3.0) * DLON
    if kind == "outside":
        tlat = lat1 + rng.uniform(0.05, 0.2)
    north, east = north_east(tlat, tlon)
    th = float(bilinear(tile, np.array([tlat]), np.array([tlon]))[0]) if kind != "outside" else 500.0
    if kind == "grazing_over":
        th += 3.0
    elif kind == "grazing_clip":
        th -= 3.0
    target = itrf(tlat, tlon, th)
    # Satellite: from the target's ground position, off_km along azimuth az, 700 km up.
    dist_rad = off_km * 1e3 / A
    slat = math.degrees(math.asin(math.sin(math.radians(tlat)) * math.cos(dist_rad)
                                  + math.cos(math.radians(tlat)) * math.sin(dist_rad) * math.cos(az)))
    slon = tlon + math.degrees(math.atan2(math.sin(az) * math.sin(dist_rad) * math.cos(math.radians(tlat)),
                                          math.cos(dist_rad) - math.sin(math.radians(tlat)) * math.sin(math.radians(slat))))
    r = itrf(slat, slon, 700e3)
    sn, se = north_east(slat, slon)
    heading = rng.uniform(0, 2 * math.pi)
    v_itrf = 7.45e3 * (math.cos(heading) * sn + math.sin(heading) * se)
    look = p2.unit(target - r)
    if kind == "miss":
        up = p2.unit(r)
        look = p2.unit(up + 0.2 * p2.unit(np.cross(up, sn)))
    # Camera: boresight -z_B along the look turned off by the pixel's field angle, so
    # that pixel n_px sees the target; x_B near the velocity.
    f_m, pixel_m = 1.0, 7e-6
    n_px = rng.uniform(-3000.0, 3000.0)
    p2_m = n_px * pixel_m
    z_b = -look
    x_b = p2.unit(v_itrf - (v_itrf @ z_b) * z_b)
    y_b = np.cross(z_b, x_b)
    # Turn about x_B so that (0, p2, -f) maps onto the look.
    ang = math.atan2(p2_m, f_m)
    rot = p2.rot_axis(x_b, -ang)
    b0 = rot @ np.column_stack([x_b, y_b, z_b])
    q = np.array(p2.quat_from_matrix(b0))
    w_dps = [rng.uniform(-0.5, 0.5) for _ in range(3)]
    row = {
        "case": i, "kind": kind, "frame": "itrf", "gps_s": 1.5e9, "gps_utc_s": 18.0,
        "dut1_s": 0.0,
        "x_m": r[0], "y_m": r[1], "z_m": r[2],
        "vx_mps": v_itrf[0], "vy_mps": v_itrf[1], "vz_mps": v_itrf[2],
        "qw": q[0], "qx": q[1], "qy": q[2], "qz": q[3], "attitude_frame": "itrf",
        "wx_dps": w_dps[0], "wy_dps": w_dps[1], "wz_dps": w_dps[2],
        "cam_qw": 1.0, "cam_qx": 0.0, "cam_qy": 0.0, "cam_qz": 0.0,
        "ground_h_m": "", "f_m": f_m, "pixel_m": pixel_m, "n_px": n_px, "p1_m": 0.0,
        "a_m": A, "flattening": FL, "earth_rate_rad_s": p2.EARTH_RATE,
    }
    return {k: (float(x) if isinstance(x, np.floating) else x) for k, x in row.items()}


def main():
    rng = random.Random(SEED)
    tile = make_tile(rng)
    with open(os.path.join(DATA, "dem_tile.csv"), "w") as fh:
        fh.write("lat0_deg,lon0_deg,dlat_deg,dlon_deg,nrows,ncols\n")
        fh.write(f"{LAT0!r},{LON0!r},{DLAT!r},{DLON!r},{NROWS},{NCOLS}\n")
        for i in range(NROWS):
            fh.write(",".join(str(int(x)) for x in tile[i]) + "\n")
    kinds = (["random"] * 40 + ["grazing_over"] * 4 + ["grazing_clip"] * 4 + ["edge"] * 4
             + ["outside"] * 4 + ["miss"] * 2)
    rows = []
    for i, kind in enumerate(kinds):
        row = make_case(rng, tile, i, kind)
        r = np.array([row["x_m"], row["y_m"], row["z_m"]])
        b0 = p2.qmatrix(tuple(p2.mp.mpf(c) for c in (row["qw"], row["qx"], row["qy"], row["qz"])))
        b0 = np.array([[float(b0[a, b]) for b in range(3)] for a in range(3)])
        d = b0 @ np.array([row["p1_m"], row["n_px"] * row["pixel_m"], -row["f_m"]])
        outcome, s = crossing(tile, r, d)
        row["error"] = outcome
        if s is None:
            for k in ("ground_x_m", "ground_y_m", "ground_z_m", "ground_lat_deg",
                      "ground_lon_deg", "ground_height_m", "v1_mps", "v2_mps"):
                row[k] = ""
        else:
            g = r + s * d
            lat, lon, h = geodetic(g[None, :])
            v1, v2 = p2.motion(row, None, ground_s=s)
            row.update({"ground_x_m": float(g[0]), "ground_y_m": float(g[1]),
                        "ground_z_m": float(g[2]),
                        "ground_lat_deg": float(lat[0]), "ground_lon_deg": float(lon[0]),
                        "ground_height_m": float(h[0]), "v1_mps": v1, "v2_mps": v2})
        rows.append(row)
        print(i, kind, outcome or "hit", flush=True)
    cols = list(rows[0].keys())
    with open(os.path.join(DATA, "dem_cases.csv"), "w") as fh:
        fh.write(",".join(cols) + "\n")
        for row in rows:
            fh.write(",".join(p2.fmt(row[c]) for c in cols) + "\n")


if __name__ == "__main__":
    main()
