#!/usr/bin/env python3
"""Golden values from ERFA (pyerfa) for core_math::earth::frames.

Writes, under core-math/tests/data/:

- erfa_c2t.csv: the celestial-to-terrestrial matrix eraC2t06a(TT, UT1, 0, 0)
  (SOFA iauC2t06a, IAU 2006/2000A, CIO based, polar motion zero) at GPS instants
  spread over 2000-2050 (seeded random draws, both ends of the span, and both sides
  of the leap seconds of 2005-2016), with the pieces the Rust code is built from at
  the same TT and UT1: eraNut00b, eraPfw06, the CIP X, Y of eraPnm06a (IAU 2000A),
  eraS06 at those X, Y, eraEra00, eraSp00.
- erfa_geodetic.csv: eraGd2gce (geodetic -> geocentric) and eraGc2gde (back) for
  WGS 84, Krassovsky 1940 and a sphere, latitudes up to the poles, heights
  -500 m .. 2000 km.

Time scales as in shared/EARTH-MODEL.md, Part II: TT = GPS + 51.184 s,
UTC = GPS - gps_utc_s, UT1 = UTC + dut1_s. The two-part Julian dates handed to ERFA
are computed exactly (fractions.Fraction) from the float gps_s and dut1_s printed
in the same row, as (2451545.0 + whole days, fraction of a day).

Test-only dependency: pyerfa (tools/goldens/requirements.txt).
Run from the repository root: python3 tools/goldens/erfa_frames.py
"""

import datetime
import math
import os
import random
from fractions import Fraction

import erfa

OUT = os.path.join(os.path.dirname(__file__), "..", "..", "core-math", "tests", "data")
SEED = 23
DAY_S = 86400
# J2000.0 (2000-01-01T12:00:00 in its own scale) is 7300.5 days after the GPS
# epoch 1980-01-06T00:00:00.
J2000_FROM_GPS_EPOCH_D = Fraction(14601, 2)
TT_MINUS_GPS_S = Fraction(51184, 1000)

# UTC dates (days since the GPS epoch at 00:00 UTC) from which GPS - UTC takes
# the value: 1999-01-01 13, 2006-01-01 14, 2009-01-01 15, 2012-07-01 16,
# 2015-07-01 17, 2017-01-01 18 (assumed unchanged to 2050).
LEAPS = [(6935, 13), (9492, 14), (10588, 15), (11865, 16), (12960, 17), (13510, 18)]


def _days(y, m, d):
    return (datetime.date(y, m, d) - datetime.date(1980, 1, 6)).days


assert [d for d, _ in LEAPS] == [_days(1999, 1, 1), _days(2006, 1, 1), _days(2009, 1, 1),
                                 _days(2012, 7, 1), _days(2015, 7, 1), _days(2017, 1, 1)]
assert (_days(2000, 1, 1), _days(2051, 1, 1)) == (7300, 25928)


def gps_of_utc_day(day, leap):
    """GPS seconds of 00:00:00 UTC on `day` days after the GPS epoch."""
    return day * DAY_S + leap


def leap_at(gps_s):
    leap = LEAPS[0][1]
    for day, n in LEAPS:
        if gps_s >= gps_of_utc_day(day, n):
            leap = n
    return leap


def split(seconds_since_gps_epoch):
    """Exact days since J2000 of a Fraction of seconds, as ERFA's (date1, date2)."""
    days = Fraction(seconds_since_gps_epoch) / DAY_S - J2000_FROM_GPS_EPOCH_D
    whole = math.floor(days)
    return 2451545.0 + whole, float(days - whole)


def g(x):
    return repr(float(x))


def c2t_rows():
    rng = random.Random(SEED)
    start = gps_of_utc_day(7300, 13)  # 2000-01-01T00:00:00 UTC
    end = gps_of_utc_day(25928, 18) - 1  # 2050-12-31T23:59:59 UTC (2051-01-01 is day 25928)
    cases = [(float(start), 13, 0.0), (float(end), 18, 0.0)]
    cases.append((float(start), 13, 0.3554))
    cases.append((float(end), 18, -0.8999))
    for day, n in LEAPS[1:]:
        t = gps_of_utc_day(day, n)
        cases.append((t - 0.5, n - 1, rng.uniform(-0.9, 0.9)))
        cases.append((float(t), n, rng.uniform(-0.9, 0.9)))
    for _ in range(300):
        t = rng.uniform(start, end)
        # Quantise to 1/1024 s so that the float prints short and round-trips.
        t = round(t * 1024) / 1024
        dut1 = round(rng.uniform(-0.9, 0.9), 7)
        cases.append((t, leap_at(t), dut1))
    rows = []
    for gps_s, leap, dut1 in cases:
        gps = Fraction(gps_s)
        tt1, tt2 = split(gps + TT_MINUS_GPS_S)
        ut11, ut12 = split(gps - leap + Fraction(dut1))
        r = erfa.c2t06a(tt1, tt2, ut11, ut12, 0.0, 0.0)
        dpsi, deps = erfa.nut00b(tt1, tt2)
        gamb, phib, psib, epsa = erfa.pfw06(tt1, tt2)
        x, y = erfa.bpn2xy(erfa.pnm06a(tt1, tt2))
        s = erfa.s06(tt1, tt2, x, y)
        era = erfa.era00(ut11, ut12)
        sp = erfa.sp00(tt1, tt2)
        row = [gps_s, leap, dut1, tt1, tt2, ut11, ut12]
        row += [r[i][j] for i in range(3) for j in range(3)]
        row += [dpsi, deps, gamb, phib, psib, epsa, x, y, s, era, sp]
        rows.append(row)
    head = ("gps_s,gps_utc_s,dut1_s,tt1,tt2,ut11,ut12,"
            "r00,r01,r02,r10,r11,r12,r20,r21,r22,"
            "nut00b_dpsi,nut00b_deps,pfw06_gamb,pfw06_phib,pfw06_psib,pfw06_epsa,"
            "x06a,y06a,s06,era00,sp00")
    return head, rows


ELLIPSOIDS = [
    ("wgs84", 6378137.0, 1.0 / 298.257223563),
    ("krassovsky", 6378245.0, 1.0 / 298.3),
    ("sphere", 6371000.0, 0.0),
]


def geodetic_rows():
    rng = random.Random(SEED + 1)
    rows = []
    for name, a, f in ELLIPSOIDS:
        cases = []
        for lat_deg in (90.0, -90.0, 0.0, 89.9999999, -45.0, 1e-9):
            for h in (-500.0, 0.0, 2.0e6):
                cases.append((math.radians(lat_deg), rng.uniform(-math.pi, math.pi), h))
        for _ in range(100):
            lat = math.asin(rng.uniform(-1.0, 1.0))
            lon = rng.uniform(-math.pi, math.pi)
            # Heights: half uniform over -500 m .. 2000 km, half log-spread near the ground.
            if rng.random() < 0.5:
                h = rng.uniform(-500.0, 2.0e6)
            else:
                h = 10 ** rng.uniform(-3, 4) * rng.choice((-1, 1))
            cases.append((lat, lon, h))
        for lat, lon, h in cases:
            xyz = erfa.gd2gce(a, f, lon, lat, h)
            elong, phi, height = erfa.gc2gde(a, f, xyz)
            rows.append([name, a, f, lat, lon, h, *xyz, phi, elong, height])
    head = "ellipsoid,a_m,flattening,lat_rad,lon_rad,h_m,x_m,y_m,z_m,gc2gde_lat_rad,gc2gde_lon_rad,gc2gde_h_m"
    return head, rows


def write(name, head, rows):
    path = os.path.join(OUT, name)
    with open(path, "w") as out:
        out.write(f"# {erfa.__name__} {erfa.__version__} (ERFA {erfa.version.erfa_version}, SOFA {erfa.version.sofa_version}); tools/goldens/erfa_frames.py, seed {SEED}\n")
        out.write(head + "\n")
        for row in rows:
            out.write(",".join(c if isinstance(c, str) else (str(c) if isinstance(c, int) else g(c)) for c in row) + "\n")
    print(f"{path}: {len(rows)} rows")


if __name__ == "__main__":
    write("erfa_c2t.csv", *c2t_rows())
    write("erfa_geodetic.csv", *geodetic_rows())
