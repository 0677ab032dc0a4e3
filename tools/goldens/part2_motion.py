#!/usr/bin/env python3
"""Independent goldens for the image motion of shared/EARTH-MODEL.md, Part II (the bus's
state frames, attitude quaternion, body rates and camera mounting), without a DEM.

Writes core-math/tests/data/part2_motion.csv: a few hundred seeded cases (state in the
inertial frame, the ITRF or the GCRF; quaternion relative to the GCRF or the ITRF; body
rates; identity or random camera mountings; every line of sight well inside the limb)
and the image motion (v1, v2) evaluated from the definition with this file's own code,
sharing nothing with the Rust crate:

- quaternions act by the Hamilton product x_ref = q x_body q* (no matrix formula);
- C2T is ERFA's eraC2t06a(TT, UT1, 0, 0) (pyerfa), written to the row (c2t_ij) so that
  a backend can be compared with and without its own C2T;
- r_I, v_I per frame (itrf: v + w x r; gcrf: C2T r, C2T v); B0 = C2T R(q) R(cam_q) or
  R(q) R(cam_q), Omega = R(cam_q)^T w, B(t) = B0 exp([Omega]x t) (Rodrigues);
- r(t) = r + v t - GM r / (2 |r|^3) t^2 (any r(t) with the right r(0) and r'(0) gives
  the same first derivative);
- the first intersection of r + s d with the ellipsoid (A, A, B) = (a + h, a + h, b + h)
  from the quadratic, in mpmath at 50 digits; G(t) = Rz(omega t) G;
- (v1, v2) = d/dt of P = -f (c1, c2) / c3, c(t) = B(t)^T (G(t) - r(t)), by a fourth-order
  central difference (step 1e-4 s, Richardson 2h / h) at 50 digits: truncation far below
  1e-12 relative (the motion's time scales are seconds or more).

Time: TT = GPS + 51.184 s, UT1 = GPS - gps_utc_s + dut1_s; two-part Julian dates as
(2444244.5 + whole days, fraction) from the GPS epoch 1980-01-06.

Test-only dependencies: pyerfa, mpmath, numpy (tools/goldens/requirements.txt).
Run from the repository root: python3 tools/goldens/part2_motion.py
"""

import math
import os
import random

import erfa
import mpmath as mp
import numpy as np

OUT = os.path.join(os.path.dirname(__file__), "..", "..", "core-math", "tests", "data",
                   "part2_motion.csv")
SEED = 2302
N_CASES = 300
mp.mp.dps = 50

GM = mp.mpf("3.986004418e14")
A_WGS84 = 6378137.0
F_WGS84 = 1.0 / 298.257223563
EARTH_RATE = 7.2921159e-5
GPS_EPOCH_JD = 2444244.5
DAY_S = 86400.0


# --- quaternions (scalar first, Hamilton), mpmath --------------------------------------

def qmul(p, q):
    pw, px, py, pz = p
    qw, qx, qy, qz = q
    return (pw * qw - px * qx - py * qy - pz * qz,
            pw * qx + px * qw + py * qz - pz * qy,
            pw * qy - px * qz + py * qw + pz * qx,
            pw * qz + px * qy - py * qx + pz * qw)


def qconj(q):
    return (q[0], -q[1], -q[2], -q[3])


def qnormalise(q):
    n = mp.sqrt(sum(mp.mpf(c) ** 2 for c in q))
    return tuple(mp.mpf(c) / n for c in q)


def qrotate(q, x):
    """q x q* for a unit q: body coordinates to the reference frame."""
    r = qmul(qmul(q, (mp.mpf(0), x[0], x[1], x[2])), qconj(q))
    return mp.matrix([r[1], r[2], r[3]])


def qmatrix(q):
    """The matrix whose columns are the rotated basis vectors."""
    cols = [qrotate(q, [mp.mpf(int(i == j)) for i in range(3)]) for j in range(3)]
    return mp.matrix([[cols[j][i] for j in range(3)] for i in range(3)])


def quat_from_matrix(m):
    """A unit quaternion of a rotation matrix (float; Shepperd's method)."""
    m = np.asarray(m, dtype=float)
    tr = np.trace(m)
    cands = [tr, m[0, 0], m[1, 1], m[2, 2]]
    k = int(np.argmax(cands))
    if k == 0:
        w = math.sqrt(1.0 + tr) / 2.0
        q = [w, (m[2, 1] - m[1, 2]) / (4 * w), (m[0, 2] - m[2, 0]) / (4 * w),
             (m[1, 0] - m[0, 1]) / (4 * w)]
    elif k == 1:
        x = math.sqrt(1.0 + 2 * m[0, 0] - tr) / 2.0
        q = [(m[2, 1] - m[1, 2]) / (4 * x), x, (m[0, 1] + m[1, 0]) / (4 * x),
             (m[0, 2] + m[2, 0]) / (4 * x)]
    elif k == 2:
        y = math.sqrt(1.0 + 2 * m[1, 1] - tr) / 2.0
        q = [(m[0, 2] - m[2, 0]) / (4 * y), (m[0, 1] + m[1, 0]) / (4 * y), y,
             (m[1, 2] + m[2, 1]) / (4 * y)]
    else:
        z = math.sqrt(1.0 + 2 * m[2, 2] - tr) / 2.0
        q = [(m[1, 0] - m[0, 1]) / (4 * z), (m[0, 2] + m[2, 0]) / (4 * z),
             (m[1, 2] + m[2, 1]) / (4 * z), z]
    return q


# --- small helpers ----------------------------------------------------------------------

def mpv(x):
    return mp.matrix([mp.mpf(c) for c in x])


def mpm(m):
    return mp.matrix([[mp.mpf(float(m[i][j])) for j in range(3)] for i in range(3)])


def cross(a, b):
    return mp.matrix([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                      a[0] * b[1] - a[1] * b[0]])


def rodrigues(omega, t):
    """exp([omega]x t)."""
    wn = mp.sqrt(sum(c ** 2 for c in omega))
    eye = mp.eye(3)
    if wn == 0:
        return eye
    k = omega / wn
    kx = mp.matrix([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    th = wn * t
    return eye + mp.sin(th) * kx + (1 - mp.cos(th)) * (kx * kx)


def c2t_erfa(gps_s, gps_utc_s, dut1_s):
    d, frac = divmod(gps_s, DAY_S)
    tt_s = frac + 51.184
    ut1_s = frac - gps_utc_s + dut1_s
    tt1 = GPS_EPOCH_JD + d
    return erfa.c2t06a(tt1, tt_s / DAY_S, tt1, ut1_s / DAY_S, 0.0, 0.0)


# --- the definition ---------------------------------------------------------------------

def ellipsoid_root(row, r_i, d):
    """The near root s of r_i + s d on the ellipsoid (a + h, a + h, b + h)."""
    a = mp.mpf(row["a_m"])
    b = a * (1 - mp.mpf(row["flattening"]))
    h = mp.mpf(row["ground_h_m"])
    ea, eb = a + h, b + h
    qa = (d[0] ** 2 + d[1] ** 2) / ea ** 2 + d[2] ** 2 / eb ** 2
    qb = 2 * ((r_i[0] * d[0] + r_i[1] * d[1]) / ea ** 2 + r_i[2] * d[2] / eb ** 2)
    qc = (r_i[0] ** 2 + r_i[1] ** 2) / ea ** 2 + r_i[2] ** 2 / eb ** 2 - 1
    disc = qb ** 2 - 4 * qa * qc
    assert qc > 0 and disc > 0 and qb < 0
    s = (-qb - mp.sqrt(disc)) / (2 * qa)
    assert s > 0
    return s


def motion(row, c2t, ground_s=None):
    """(v1, v2) of Part II for one row (dict of floats and strings); c2t a 3x3 or None.
    ground_s: the ground point as r_I + ground_s d (a DEM's, found by the caller) instead
    of the ellipsoid's."""
    r = mpv([row["x_m"], row["y_m"], row["z_m"]])
    v = mpv([row["vx_mps"], row["vy_mps"], row["vz_mps"]])
    w_e = mp.mpf(row["earth_rate_rad_s"])
    C = mpm(c2t) if c2t is not None else None
    if row["frame"] == "inertial":
        r_i, v_i = r, v
    elif row["frame"] == "itrf":
        r_i, v_i = r, v + cross(mp.matrix([0, 0, w_e]), r)
    else:
        r_i, v_i = C * r, C * v
    q = qnormalise([row["qw"], row["qx"], row["qy"], row["qz"]])
    cq = qnormalise([row["cam_qw"], row["cam_qx"], row["cam_qy"], row["cam_qz"]])
    b_frame = qmatrix(qmul(q, cq))
    b0 = C * b_frame if row["attitude_frame"] == "gcrf" else b_frame
    deg = mp.pi / 180
    w_body = mpv([row["wx_dps"], row["wy_dps"], row["wz_dps"]]) * deg
    omega = qrotate(qconj(cq), w_body)

    f = mp.mpf(row["f_m"])
    p1 = mp.mpf(row["p1_m"])
    p2 = mp.mpf(row["n_px"]) * mp.mpf(row["pixel_m"])
    d = b0 * mp.matrix([p1, p2, -f])
    if ground_s is None:
        s = ellipsoid_root(row, r_i, d)
    else:
        s = mp.mpf(ground_s)
    g0 = r_i + s * d
    acc = -GM * r_i / mp.norm(r_i) ** 3

    def proj(t):
        rt = r_i + v_i * t + acc * (t * t / 2)
        wt = w_e * t
        gt = mp.matrix([mp.cos(wt) * g0[0] - mp.sin(wt) * g0[1],
                        mp.sin(wt) * g0[0] + mp.cos(wt) * g0[1], g0[2]])
        bt = b0 * rodrigues(omega, t)
        c = bt.T * (gt - rt)
        return (-f * c[0] / c[2], -f * c[1] / c[2])

    def central(hh):
        pp, pm = proj(hh), proj(-hh)
        return [(pp[i] - pm[i]) / (2 * hh) for i in range(2)]

    hh = mp.mpf("1e-4")
    d1, d2 = central(hh), central(2 * hh)
    v12 = [(4 * d1[i] - d2[i]) / 3 for i in range(2)]
    # The projection reproduces the pixel (a check of the intersection and the axes; C2T
    # from ERFA is orthonormal to f64 rounding only).
    p0 = proj(mp.mpf(0))
    assert abs(p0[0] - p1) < 1e-12 * f and abs(p0[1] - p2) < 1e-12 * f
    return float(v12[0]), float(v12[1])


# --- cases ------------------------------------------------------------------------------

def unit(x):
    return x / np.linalg.norm(x)


def rot_axis(k, ang):
    k = unit(np.asarray(k, dtype=float))
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + math.sin(ang) * kx + (1 - math.cos(ang)) * kx @ kx


def random_rotation(rng):
    """A uniformly random rotation: its matrix (float) and quaternion."""
    q = unit(np.array([rng.gauss(0, 1) for _ in range(4)]))
    m = qmatrix(tuple(mp.mpf(c) for c in q))
    return np.array([[float(m[i, j]) for j in range(3)] for i in range(3)]), q


def make_case(rng, i):
    frame = ["inertial", "itrf", "gcrf"][i % 3]
    attitude_frame = ["gcrf", "itrf"][(i // 3) % 2]
    # GPS time over 2000-2050 (needed by gcrf anywhere; left empty otherwise in a third
    # of the rows that do not need it).
    gps_s = rng.uniform(7300.0 * DAY_S, 25900.0 * DAY_S)
    gps_utc_s = 18.0
    dut1_s = rng.uniform(-0.8, 0.8)
    needs_time = frame == "gcrf" or attitude_frame == "gcrf"
    c2t = np.array(c2t_erfa(gps_s, gps_utc_s, dut1_s)) if needs_time else None

    a, fl = (A_WGS84, F_WGS84) if i % 7 else (6378137.0, 0.0)
    # Orbit in I: altitude 300-900 km, eccentricity up to 0.01 (speed factor), any plane.
    alt = rng.uniform(300e3, 900e3)
    rn = a + alt
    inc = math.radians(rng.uniform(5.0, 175.0))
    node = rng.uniform(0.0, 2 * math.pi)
    u = rng.uniform(0.0, 2 * math.pi)
    r_i = rn * (rot_axis([0, 0, 1], node) @ rot_axis([1, 0, 0], inc)
                @ np.array([math.cos(u), math.sin(u), 0.0]))
    along = unit(np.cross(rot_axis([0, 0, 1], node) @ rot_axis([1, 0, 0], inc)
                          @ np.array([0, 0, 1.0]), r_i))
    speed = math.sqrt(3.986004418e14 / rn) * rng.uniform(0.995, 1.005)
    gamma = math.radians(rng.uniform(-0.5, 0.5))
    v_i = speed * (math.cos(gamma) * along + math.sin(gamma) * unit(r_i))

    # Camera axes in I: boresight -z_B up to 30 degrees off nadir, x_B near the flight
    # direction turned by a yaw within 40 degrees.
    nadir = -unit(r_i)
    tilt_axis = rot_axis(nadir, rng.uniform(0, 2 * math.pi)) @ unit(np.cross(nadir, along))
    look = rot_axis(tilt_axis, math.radians(rng.uniform(0.0, 30.0))) @ nadir
    z_b = -look
    x_b = unit(v_i - (v_i @ z_b) * z_b)
    x_b = rot_axis(z_b, math.radians(rng.uniform(-40.0, 40.0))) @ x_b
    y_b = np.cross(z_b, x_b)
    b0 = np.column_stack([x_b, y_b, z_b])

    # Camera mounting: identity in a third of the rows, else any rotation.
    if i % 3 == 1:
        cam_m, cam_q = np.eye(3), np.array([1.0, 0.0, 0.0, 0.0])
    else:
        cam_m, cam_q = random_rotation(rng)
    # R(q) = T^T B0 R(cam)^T, T = C2T for a GCRF quaternion.
    ref = (c2t.T @ b0) if attitude_frame == "gcrf" else b0
    q = np.array(quat_from_matrix(ref @ cam_m.T))
    if rng.random() < 0.5:
        q = -q
    # Norms off 1 by up to 5e-4 (normalised by the model).
    q = q * (1.0 + rng.uniform(-5e-4, 5e-4))
    cam_q = cam_q * (1.0 + rng.uniform(-5e-4, 5e-4))
    w_dps = [rng.uniform(-1.5, 1.5) for _ in range(3)] if i % 5 else [0.0, 0.0, 0.0]

    # The state in its frame.
    if frame == "inertial":
        r, v = r_i, v_i
    elif frame == "itrf":
        r, v = r_i, v_i - np.cross([0.0, 0.0, EARTH_RATE], r_i)
    else:
        r, v = c2t.T @ r_i, c2t.T @ v_i

    f_m = rng.choice([0.5, 1.0, 1.75])
    pixel_m = rng.choice([5e-6, 7e-6, 1e-5])
    n_px = rng.uniform(-4000.0, 4000.0)
    p1_m = rng.choice([0.0, rng.uniform(-2e-3, 2e-3)])
    row = {
        "case": i,
        "frame": frame,
        "gps_s": gps_s if (needs_time or i % 3 != 0) else "",
        "gps_utc_s": gps_utc_s,
        "dut1_s": dut1_s,
        "x_m": r[0], "y_m": r[1], "z_m": r[2],
        "vx_mps": v[0], "vy_mps": v[1], "vz_mps": v[2],
        "qw": q[0], "qx": q[1], "qy": q[2], "qz": q[3],
        "attitude_frame": attitude_frame,
        "wx_dps": w_dps[0], "wy_dps": w_dps[1], "wz_dps": w_dps[2],
        "cam_qw": cam_q[0], "cam_qx": cam_q[1], "cam_qy": cam_q[2], "cam_qz": cam_q[3],
        "ground_h_m": rng.uniform(-100.0, 3000.0),
        "f_m": f_m, "pixel_m": pixel_m, "n_px": n_px, "p1_m": p1_m,
        "a_m": a, "flattening": fl, "earth_rate_rad_s": EARTH_RATE,
    }
    row = {k: (float(x) if isinstance(x, (np.floating,)) else x) for k, x in row.items()}
    for k in range(9):
        row[f"c2t_{k // 3}{k % 3}"] = float(c2t[k // 3][k % 3]) if c2t is not None else ""
    return row, c2t


def fmt(x):
    if isinstance(x, float):
        return repr(x)
    return str(x)


def main():
    rng = random.Random(SEED)
    rows = []
    for i in range(N_CASES):
        row, c2t = make_case(rng, i)
        v1, v2 = motion(row, c2t)
        row["v1_mps"], row["v2_mps"] = v1, v2
        rows.append(row)
    cols = list(rows[0].keys())
    with open(OUT, "w") as fh:
        fh.write(",".join(cols) + "\n")
        for row in rows:
            fh.write(",".join(fmt(row[c]) for c in cols) + "\n")
    print(f"wrote {len(rows)} rows to {os.path.normpath(OUT)}")


if __name__ == "__main__":
    main()
