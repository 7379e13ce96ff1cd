#!/usr/bin/env python3
"""Independent sun and moon positions for hikari-math's `astro` module.

Writes crates/hikari-math/tests/fixtures/ephemeris.json: about 100 cases (local date, local
time, UTC offset, latitude, longitude) spread over 1900-2100, both hemispheres, latitudes near
+-89 degrees, longitudes at the date line and the moon near the horizon, each with the sun's and
the moon's topocentric azimuth (clockwise from north) and elevation (geometric: no refraction),
their distances and the moon's illuminated fraction.

Reference: PyEphem (`pip install ephem`, libastro: VSOP87 for the sun, its own lunar theory),
with `observer.pressure = 0` so that its altitudes carry no refraction, elevation 0 m above the
ellipsoid. PyEphem reads dates as UT and applies its own Delta T. The sun's distance comes from
ERFA's epv00 (`pip install pyerfa`) instead: PyEphem's differs from it by ~3e-5 au.

Cross-check: a handful of cases are recomputed from ERFA alone
(epv00 for the Earth, moon98 for the Moon, pnm06a for precession-nutation, gst06a for sidereal
time, gd2gc for the observer, ab for the sun's aberration, hd2ae for the horizon) and the script
stops if PyEphem and ERFA disagree by more than 0.003 deg (sun) or 0.02 deg (moon).

Usage: python3 tools/ephemeris_reference.py   (deterministic: fixed seed)
"""

import datetime as dt
import json
import math
import os
import random
import sys
import tempfile

import ephem
import erfa
import warnings

warnings.simplefilter("ignore", erfa.ErfaWarning)  # epv00 outside 1900-2100 by hours

AU_KM = 149597870.7
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "crates/hikari-math/tests/fixtures/ephemeris.json")


def utc_of(local: dt.datetime, offset_h: float) -> dt.datetime:
    return local - dt.timedelta(hours=offset_h)


def observer(lat, lon, utc: dt.datetime) -> ephem.Observer:
    o = ephem.Observer()
    o.lat = math.radians(lat)
    o.lon = math.radians(lon)
    o.elevation = 0.0
    o.pressure = 0.0  # no refraction: geometric altitudes
    o.date = ephem.Date(
        (utc.year, utc.month, utc.day, utc.hour, utc.minute, utc.second + utc.microsecond * 1e-6)
    )
    return o


def pyephem_case(lat, lon, utc):
    o = observer(lat, lon, utc)
    s = ephem.Sun(o)
    m = ephem.Moon(o)
    return {
        "sun": {
            "azimuth_deg": math.degrees(float(s.az)),
            "elevation_deg": math.degrees(float(s.alt)),
            "distance_au": float(s.earth_distance),
        },
        "moon": {
            "azimuth_deg": math.degrees(float(m.az)),
            "elevation_deg": math.degrees(float(m.alt)),
            # With an observer, PyEphem's earth_distance is measured from the place.
            "distance_km": float(m.earth_distance) * AU_KM,
            "geocentric_distance_km": float(ephem.Moon(o.date).earth_distance) * AU_KM,
            "illuminated_fraction": float(m.moon_phase),
        },
    }


def separation_deg(az1, el1, az2, el2):
    a1, e1, a2, e2 = map(math.radians, (az1, el1, az2, el2))
    c = math.sin(e1) * math.sin(e2) + math.cos(e1) * math.cos(e2) * math.cos(a1 - a2)
    return math.degrees(math.acos(max(-1.0, min(1.0, c))))


def delta_t_espenak_meeus(year_frac):
    """Espenak & Meeus (NASA 2006) polynomials, 1860-2150, seconds (for ERFA's TT only)."""
    y = year_frac
    if y < 1900:
        t = y - 1860
        return 7.62 + 0.5737 * t - 0.251754 * t**2 + 0.01680668 * t**3 - 0.0004473624 * t**4 + t**5 / 233174
    if y < 1920:
        t = y - 1900
        return -2.79 + 1.494119 * t - 0.0598939 * t**2 + 0.0061966 * t**3 - 0.000197 * t**4
    if y < 1941:
        t = y - 1920
        return 21.20 + 0.84493 * t - 0.076100 * t**2 + 0.0020936 * t**3
    if y < 1961:
        t = y - 1950
        return 29.07 + 0.407 * t - t**2 / 233 + t**3 / 2547
    if y < 1986:
        t = y - 1975
        return 45.45 + 1.067 * t - t**2 / 260 - t**3 / 718
    if y < 2005:
        t = y - 2000
        return 63.86 + 0.3345 * t - 0.060374 * t**2 + 0.0017275 * t**3 + 0.000651814 * t**4 + 0.00002373599 * t**5
    if y < 2050:
        t = y - 2000
        return 62.92 + 0.32217 * t + 0.005589 * t**2
    return -20 + 32 * ((y - 1820) / 100) ** 2 - 0.5628 * (2150 - y)


def erfa_sun_distance_au(utc):
    import erfa

    d1, d2 = erfa.cal2jd(utc.year, utc.month, utc.day)
    d2 = d2 + (utc.hour + utc.minute / 60 + utc.second / 3600) / 24
    d2 += delta_t_espenak_meeus(utc.year + (utc.month - 0.5) / 12) / 86400
    pvh, _ = erfa.epv00(d1, d2)
    return float(math.sqrt(sum(x * x for x in pvh[0])))


def erfa_case(lat, lon, utc):
    """Sun and moon alt/az from ERFA alone (UT1 = UTC, TT = UT1 + Delta T)."""
    import erfa
    import numpy as np

    ut1_1, ut1_2 = erfa.cal2jd(utc.year, utc.month, utc.day)
    ut1_2 = ut1_2 + (utc.hour + utc.minute / 60 + utc.second / 3600) / 24
    dtt = delta_t_espenak_meeus(utc.year + (utc.month - 0.5) / 12)
    tt1, tt2 = ut1_1, ut1_2 + dtt / 86400
    pvh, pvb = erfa.epv00(tt1, tt2)
    rbpn = erfa.pnm06a(tt1, tt2)  # GCRS -> true equator and equinox of date
    gast = erfa.gst06a(ut1_1, ut1_2, tt1, tt2)

    # Observer: geodetic -> geocentric (WGS84), rotated by the apparent sidereal time into the
    # true-of-date equatorial frame (polar motion neglected).
    xyz = erfa.gd2gc(1, math.radians(lon), math.radians(lat), 0.0) / 1000.0  # km
    c, s_ = math.cos(gast), math.sin(gast)
    obs = np.array([c * xyz[0] - s_ * xyz[1], s_ * xyz[0] + c * xyz[1], xyz[2]])

    def altaz(body_km):
        v = body_km - obs
        ra = math.atan2(v[1], v[0])
        dec = math.atan2(v[2], math.hypot(v[0], v[1]))
        ha = gast + math.radians(lon) - ra
        az, el = erfa.hd2ae(ha, dec, math.radians(lat))
        return math.degrees(az) % 360.0, math.degrees(el)

    # Sun: geocentric direction with annual aberration (Earth's barycentric velocity).
    sun_gcrs = -pvh[0]
    r = np.linalg.norm(sun_gcrs)
    v_c = pvb[1] * (AU_KM * 1000 / 86400) / 299792458.0
    bm1 = math.sqrt(1 - np.dot(v_c, v_c))
    sun_dir = erfa.ab(sun_gcrs / r, v_c, r, bm1)
    sun_km = rbpn @ sun_dir * r * AU_KM
    # Moon: geometric geocentric (light time and aberration nearly cancel for the Moon).
    moon_gcrs = erfa.moon98(tt1, tt2)[0]
    moon_km = rbpn @ moon_gcrs * AU_KM
    m2s = sun_gcrs * AU_KM - moon_gcrs * AU_KM
    m2e = -moon_gcrs * AU_KM
    cos_i = np.dot(m2s, m2e) / (np.linalg.norm(m2s) * np.linalg.norm(m2e))
    return {"sun": altaz(sun_km), "moon": altaz(moon_km), "fraction": (1 + cos_i) / 2}


def random_case(rng, lat=None, lon=None, offset=None, year=None):
    year = year if year is not None else rng.randint(1900, 2100)
    start = dt.datetime(year, 1, 1)
    local = start + dt.timedelta(seconds=rng.randrange(0, 365 * 86400))
    local = local.replace(microsecond=0)
    if local.year != year:
        local = local.replace(year=year, month=12, day=31)
    lat = lat if lat is not None else round(rng.uniform(-89.9, 89.9), 4)
    lon = lon if lon is not None else round(rng.uniform(-180.0, 180.0), 4)
    offset = offset if offset is not None else rng.choice(
        [-12, -10, -9.5, -8, -5, -3.5, -1, 0, 1, 2, 3, 4.5, 5.5, 5.75, 8, 9, 9.5, 10, 12.75, 13, 14]
    )
    return local, offset, lat, lon


def moon_near_horizon(rng):
    """A random place and day, then the first 2-minute step where the moon is within 1 deg."""
    while True:
        local, offset, lat, lon = random_case(rng, lat=round(rng.uniform(-60, 60), 3))
        local = local.replace(hour=0, minute=0, second=0)
        for step in range(0, 24 * 30):
            t = local + dt.timedelta(minutes=2 * step)
            if t.day != local.day:
                break
            o = observer(lat, lon, utc_of(t, offset))
            if abs(math.degrees(float(ephem.Moon(o).alt))) < 1.0:
                return t, offset, lat, lon


def main():
    rng = random.Random(16)
    cases = []
    # Tsushima on the default date, noon and 23:00 (the renderer's defaults).
    cases.append((dt.datetime(2024, 7, 21, 12, 0, 0), 9, 34.4, 129.3))
    cases.append((dt.datetime(2024, 7, 21, 23, 0, 0), 9, 34.4, 129.3))
    # The ends of the allowed date range, with offsets that push UTC outside it.
    cases.append((dt.datetime(1900, 1, 1, 0, 0, 0), 14, 10.0, 170.0))
    cases.append((dt.datetime(1900, 1, 1, 6, 30, 0), -12, -40.0, -170.0))
    cases.append((dt.datetime(2100, 12, 31, 23, 59, 59), -12, 51.5, -0.1))
    cases.append((dt.datetime(2100, 6, 21, 12, 0, 0), 0, 89.0, 0.0))
    # Near the poles' limits.
    for lat in (89.0, 89.9, -89.0, -89.9, 89.99, -89.99):
        cases.append(random_case(rng, lat=lat))
    # At the date line.
    for lon in (180.0, -180.0, 179.99, -179.99):
        for _ in range(2):
            cases.append(random_case(rng, lon=lon))
    # Moon near the horizon.
    for _ in range(10):
        cases.append(moon_near_horizon(rng))
    # Spread over the years, both hemispheres.
    for i in range(72):
        year = 1900 + round(200 * i / 71)
        cases.append(random_case(rng, year=year))

    out = []
    for local, offset, lat, lon in cases:
        ref = pyephem_case(lat, lon, utc_of(local, offset))
        ref["sun"]["distance_au"] = erfa_sun_distance_au(utc_of(local, offset))
        out.append(
            {
                "date": local.strftime("%Y-%m-%d"),
                "time": local.strftime("%H:%M:%S"),
                "utc_offset_h": offset,
                "lat_deg": lat,
                "lon_deg": lon,
                **ref,
            }
        )

    # Cross-check the reference itself on a few cases: PyEphem against ERFA.
    worst = [0.0, 0.0, 0.0]
    for case, (local, offset, lat, lon) in list(zip(out, cases))[:2] + list(zip(out, cases))[-6:]:
        e = erfa_case(lat, lon, utc_of(local, offset))
        ds = separation_deg(*e["sun"], case["sun"]["azimuth_deg"], case["sun"]["elevation_deg"])
        dm = separation_deg(*e["moon"], case["moon"]["azimuth_deg"], case["moon"]["elevation_deg"])
        df = abs(e["fraction"] - case["moon"]["illuminated_fraction"])
        worst = [max(worst[0], ds), max(worst[1], dm), max(worst[2], df)]
    print(
        f"PyEphem vs ERFA on 8 cases: sun {worst[0]:.5f} deg, moon {worst[1]:.5f} deg, "
        f"illuminated fraction {worst[2]:.5f}"
    )
    if worst[0] > 0.003 or worst[1] > 0.02 or worst[2] > 0.002:
        sys.exit("PyEphem and ERFA disagree: not writing the fixture")

    doc = {
        "source": "PyEphem "
        + ephem.__version__
        + " (libastro), observer elevation 0 m, pressure 0 (no refraction); the sun's distance "
        "from ERFA epv00 (pyerfa " + erfa.__version__ + "); "
        "written by tools/ephemeris_reference.py",
        "cases": out,
    }
    fd, tmp = tempfile.mkstemp(dir=os.path.dirname(OUT), suffix=".tmp")
    with os.fdopen(fd, "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")
    os.replace(tmp, OUT)
    print(f"wrote {len(out)} cases to {os.path.relpath(OUT, ROOT)}")


if __name__ == "__main__":
    main()
