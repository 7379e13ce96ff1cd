#!/usr/bin/env python3
"""Brute-force spectral reference for hikari-atmosphere, written from first principles (no table,
no colour space: every quantity per wavelength, then through the CIE 1931 functions to Rec.709).

    pip install colour-science numpy
    python3 tools/atmosphere_reference.py   # writes crates/hikari-atmosphere/tests/fixtures/atmosphere_reference.json

What it computes, for the default Earth of hikari-atmosphere (radii 6360 / 6420 km; Rayleigh
lambda^-4, 8 km; grey Mie 4e-3 / (4e-3 / 0.9) km^-1, 1.2 km, Cornette-Shanks g = 0.8; ozone tent
10-40 km, 300 DU, measured cross-sections) lit by a D65-shaped sun of unit illuminance:

  * sky radiance from SINGLE scattering (sr^-1 per unit solar illuminance, linear Rec.709) for
    the sun at 30, 60, 85, 90 and 95 degrees from the zenith, seen from the ground, in 16 azimuths
    (from the sun's, every 22.5 degrees) x 8 elevations; each view ray is marched in 240 steps and
    at every step the optical depth to the sun is integrated along the sun ray in 120 steps (a
    point sun: none once the Earth hides it);
  * sky irradiance on a horizontal plane at the ground from single scattering (the same
    radiance on a 24 x 48 midpoint grid over the hemisphere);
  * spectral transmittance of the sun at the ground for sun zenith angles 60..90 degrees, for a
    pure Rayleigh atmosphere and the full one, as the Rec.709 colour of the transmitted and of the
    removed (outscattered) light.

Multiple scattering is NOT in this reference yet (see docs/atmosphere.md).
"""
import json
import os

import numpy as np

from atmosphere_common import (WL, XYZ_TO_REC709, ozone_absorption_per_km, rayleigh_per_km,
                               spectrum_to)

RB, RT = 6360.0, 6420.0
H_R, H_M = 8.0, 1.2
MIE_S, MIE_E, G = 4e-3, 4e-3 / 0.9, 0.8
BETA_R = rayleigh_per_km(WL)            # [wl]
BETA_O = ozone_absorption_per_km(WL)    # [wl]
SUN_ZENITHS = [30.0, 60.0, 85.0, 90.0, 95.0]
AZIMUTHS = np.arange(16) * 22.5
ELEVATIONS = np.array([1.0, 4.0, 9.0, 16.0, 25.0, 40.0, 60.0, 85.0])


def densities(h):
    oz = np.maximum(0.0, 1.0 - np.abs(h - 25.0) / 15.0)
    return np.exp(-h / H_R), np.exp(-h / H_M), oz


def dist_top(r, mu):
    return -r * mu + np.sqrt(np.maximum(0.0, r * r * (mu * mu - 1.0) + RT * RT))


def column(p, d, n):
    """Integrals of the three densities along rays from points p[..., 3] in unit directions
    d[..., 3] to the top of the atmosphere (trapezoid, n steps); inf where the ray hits the
    ground (so the transmittance is 0)."""
    r = np.linalg.norm(p, axis=-1)
    mu = np.sum(p * d, axis=-1) / r
    hits = (mu < 0) & (r * r * (mu * mu - 1) + RB * RB >= 0)
    length = dist_top(r, mu)
    t = np.linspace(0.0, 1.0, n + 1)
    w = np.full(n + 1, 1.0 / n)
    w[0] = w[-1] = 0.5 / n
    s = length[..., None] * t
    q = p[..., None, :] + s[..., None] * d[..., None, :]
    h = np.linalg.norm(q, axis=-1) - RB
    out = [np.sum(x * w, axis=-1) * length for x in densities(h)]
    for o in out:
        o[hits] = np.inf
    return out


def tau(cols):
    """Optical depth per wavelength from the three columns: [..., wl]."""
    cr, cm, co = cols
    with np.errstate(invalid="ignore"):
        t = cr[..., None] * BETA_R + cm[..., None] * MIE_E + co[..., None] * BETA_O
    return np.where(np.isfinite(t), t, np.inf)


def phase_r(nu):
    return 3.0 / (16.0 * np.pi) * (1.0 + nu * nu)


def phase_m(nu):
    k = 3.0 / (8.0 * np.pi) * (1.0 - G * G) / (2.0 + G * G)
    return k * (1.0 + nu * nu) / (1.0 + G * G - 2.0 * G * nu) ** 1.5


def single_scattering(view, sun, n_view=240, n_sun=120):
    """Spectral single-scattering radiance [rays, wl] seen from the ground along unit `view`
    directions [rays, 3] (z up), sun direction `sun` [3]."""
    origin = np.array([0.0, 0.0, RB])
    mu = view[:, 2]
    length = dist_top(RB, mu)
    t = np.linspace(0.0, 1.0, n_view + 1)
    w = np.full(n_view + 1, 1.0 / n_view)
    w[0] = w[-1] = 0.5 / n_view
    s = length[:, None] * t                                   # [rays, steps]
    pts = origin + s[..., None] * view[:, None, :]            # [rays, steps, 3]
    h = np.linalg.norm(pts, axis=-1) - RB
    dr, dm, _ = densities(h)
    # optical depth from the eye to each point: cumulative trapezoid of the extinction
    ext = (dr[..., None] * BETA_R + dm[..., None] * MIE_E
           + densities(h)[2][..., None] * BETA_O)             # [rays, steps, wl]
    ds = (length / n_view)[:, None, None]
    tau_view = np.concatenate([np.zeros_like(ext[:, :1]),
                               np.cumsum(0.5 * (ext[:, 1:] + ext[:, :-1]) * ds, axis=1)], axis=1)
    sun_dirs = np.broadcast_to(sun, pts.shape)
    tau_sun = tau(column(pts, sun_dirs, n_sun))               # [rays, steps, wl]
    nu = view @ sun
    trans = np.exp(-(tau_view + tau_sun))
    scat = (dr[..., None] * BETA_R * phase_r(nu)[:, None, None]
            + dm[..., None] * MIE_S * phase_m(nu)[:, None, None])
    return np.sum(trans * scat * w[None, :, None], axis=1) * length[:, None]


def direction(elev_deg, azim_deg):
    e, a = np.radians(elev_deg), np.radians(azim_deg)
    return np.stack([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)], axis=-1)


def sun_vector(zenith_deg):
    z = np.radians(zenith_deg)
    return np.array([np.sin(z), 0.0, np.cos(z)])  # azimuth 0


def to_rec709(spectra):
    return spectrum_to(XYZ_TO_REC709, spectra)


def sky_case(zenith):
    sun = sun_vector(zenith)
    el, az = np.meshgrid(ELEVATIONS, AZIMUTHS, indexing="ij")
    dirs = direction(el.ravel(), az.ravel())
    radiance = np.concatenate([single_scattering(dirs[i:i + 32], sun) for i in range(0, len(dirs), 32)])
    # irradiance on a horizontal plane: midpoint rule over elevation x azimuth
    ne, na = 24, 48
    de, da = 0.5 * np.pi / ne, 2.0 * np.pi / na
    e = (np.arange(ne) + 0.5) * de
    a = (np.arange(na) + 0.5) * da
    ee, aa = np.meshgrid(e, a, indexing="ij")
    hd = direction(np.degrees(ee.ravel()), np.degrees(aa.ravel()))
    hl = np.concatenate([single_scattering(hd[i:i + 32], sun, 160, 80) for i in range(0, len(hd), 32)])
    weight = (np.sin(ee) * np.cos(ee)).ravel() * de * da
    irradiance = (hl * weight[:, None]).sum(axis=0)
    return {
        "sun_zenith_deg": zenith,
        "radiance_rec709": to_rec709(radiance).tolist(),
        "irradiance_rec709": to_rec709(irradiance).tolist(),
    }


def transmittance_cases():
    zen = np.array([60.0, 70.0, 75.0, 80.0, 84.0, 86.0, 88.0, 89.0, 90.0])
    origin = np.array([[0.0, 0.0, RB]] * len(zen))
    dirs = np.stack([sun_vector(z) for z in zen])
    cr, cm, co = column(origin, dirs, 4000)
    out = {"sun_zenith_deg": zen.tolist()}
    for name, t in [("rayleigh_only", cr[:, None] * BETA_R),
                    ("full", cr[:, None] * BETA_R + cm[:, None] * MIE_E + co[:, None] * BETA_O)]:
        tr = np.exp(-t)
        out[name] = {"transmitted_rec709": to_rec709(tr).tolist(),
                     "outscattered_rec709": to_rec709(1.0 - tr).tolist()}
    return out


if __name__ == "__main__":
    result = {
        "about": "tools/atmosphere_reference.py: spectral single scattering, per unit D65 solar "
                 "illuminance, linear Rec.709; view directions z up, azimuth measured from the sun's",
        "elevations_deg": ELEVATIONS.tolist(),
        "azimuths_deg": AZIMUTHS.tolist(),
        "sky": [sky_case(z) for z in SUN_ZENITHS],
        "transmittance": transmittance_cases(),
    }
    path = os.path.join(os.path.dirname(__file__), "..", "crates", "hikari-atmosphere", "tests",
                        "fixtures", "atmosphere_reference.json")
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        json.dump(result, f, indent=1)
    os.replace(tmp, path)
    print("wrote", os.path.normpath(path))
