#!/usr/bin/env python3
"""Derives the ozone absorption coefficients of hikari-atmosphere's two colour spaces
(crates/hikari-atmosphere/src/params.rs) from the measured spectral cross-sections.

    pip install colour-science numpy scipy
    python3 tools/atmosphere_lms_coefficients.py

Absorption coefficients do not project linearly (transmittance is exp(-k x), and the exponential of
a projection is not the projection of exponentials), so each channel's coefficient is *fitted*: the
k that makes exp(-k * column) best match the channel of the spectrally attenuated D65 sun, over
ozone columns from 1 to 12 times the vertical column (sun from the zenith to about 85 degrees),
weighting every column equally (the same idea as the talk's step 2 for Rayleigh). Mie is grey and
needs no conversion. The point samples at the primaries' dominant wavelengths (LMS: where the
spectral locus passes through each primary) and at Bruneton's 680/550/440 nm are printed too.
"""
import numpy as np
from scipy.optimize import minimize_scalar

from atmosphere_common import (WL, XYZ_TO_LMS, XYZ_TO_REC709, ozone_absorption_per_km,
                               spectrum_to, CMFS)

COLUMN_KM = 15.0  # the tent profile's integral: a vertical path sees peak density x 15 km
AIR_MASS = np.linspace(1.0, 12.0, 23)


def fit(m):
    k_spec = ozone_absorption_per_km(WL)
    target = np.array([spectrum_to(m, np.exp(-k_spec * a * COLUMN_KM)) for a in AIR_MASS])
    out = []
    for c in range(3):
        err = lambda k: np.sum((target[:, c] - np.exp(-k * AIR_MASS * COLUMN_KM)) ** 2)  # noqa
        out.append(minimize_scalar(err, bounds=(0.0, 0.01), method="bounded", options={"xatol": 1e-12}).x)
    return np.array(out)


def dominant_nm(xy):
    xs = CMFS[:, 0] / CMFS.sum(axis=1)
    ys = CMFS[:, 1] / CMFS.sum(axis=1)
    return WL[np.argmin((xs - xy[0]) ** 2 + (ys - xy[1]) ** 2)]


if __name__ == "__main__":
    print("ozone absorption at peak density, km^-1")
    print("  LMS Rayleigh, fitted:  ", np.array2string(fit(XYZ_TO_LMS), precision=7))
    print("  Rec.709, fitted:       ", np.array2string(fit(XYZ_TO_REC709), precision=7))
    print("  point 680/550/440 nm:  ", ozone_absorption_per_km(np.array([680.0, 550.0, 440.0])))
    nm = [dominant_nm(p) for p in [(0.6501, 0.3495), (0.1711, 0.7959), (0.1520, 0.0218)]]
    print("  LMS dominant wavelengths (5 nm grid):", nm, "->", ozone_absorption_per_km(np.array(nm)))
