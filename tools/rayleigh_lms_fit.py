#!/usr/bin/env python3
"""Reruns the two-step optimisation behind Ghost of Tsushima's LMS Rayleigh colour space
(Patry 2021, "Custom Rayleigh Color Space") and prints how close it comes to the talk's numbers.

How to run (from the repository root):

    pip install colour-science numpy scipy
    python3 tools/rayleigh_lms_fit.py

Problem, as the talk states it: minimise the error of Rayleigh *transmittance* computed in an
RGB space against spectral rendering, over a range of sun angles, weighting low sun (sunrise,
sunset) more heavily.
  1. choose three wavelengths (L, M, S) whose spectral-locus chromaticities are the primaries,
     with Rayleigh coefficients point-sampled at those wavelengths;
  2. keep those primaries and refine the three coefficients.

Choices the talk leaves open (ours, stated so they can be changed):
  * spectral Rayleigh beta(lambda): run twice, with (a) the physical formula
    8 pi^3 (n^2 - 1)^2 / (3 N lambda^4) * (6 + 3 rho) / (6 - 7 rho), n from Peck & Reeder 1972,
    N = 2.547e25 m^-3 (15 C, 1013.25 hPa), depolarisation rho = 0.0279 (Young 1980), and (b) the
    lambda^-4 law through Bruneton 2008's 5.8e-3 km^-1 at 680 nm;
  * scale height 8 km, Earth radius 6360 km, atmosphere top 100 km, viewer at sea level;
  * light source: D65 (the space's white), so the RGB model's sun is (1, 1, 1);
  * sun elevations 0..90 degrees, weight 1 / (sin(elevation) + 0.1);
  * error: squared difference in CIE XYZ divided by the spectral luminance (relative error, so
    the dim low-sun colours count).
"""
import warnings

warnings.filterwarnings("ignore")
import numpy as np  # noqa: E402
import colour  # noqa: E402
from scipy.optimize import minimize  # noqa: E402

TALK_PRIMARIES = np.array([[0.6501, 0.3495], [0.1711, 0.7959], [0.1520, 0.0218]])
TALK_BETA = np.array([0.0076224, 0.012935, 0.024845])
D65_XY = np.array([0.3127, 0.3290])

WL = np.arange(380.0, 781.0, 1.0)
CMFS = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(
    colour.SpectralShape(380, 780, 1)).values
D65 = colour.SDS_ILLUMINANTS["D65"].copy().align(colour.SpectralShape(380, 780, 1)).values
SUN = D65 / (CMFS[:, 1] @ D65)


def beta_bruneton(wl):
    return 5.8e-3 * (680.0 / wl) ** 4


def beta_physical(wl):
    s2 = (1000.0 / np.asarray(wl, dtype=float)) ** 2  # wavenumber^2, um^-2
    n_minus_1 = 1e-8 * (8060.51 + 2480990.0 / (132.274 - s2) + 17455.7 / (39.32957 - s2))
    n2m1 = (1.0 + n_minus_1) ** 2 - 1.0
    lam = np.asarray(wl, dtype=float) * 1e-9
    rho = 0.0279
    beta_m = 8 * np.pi ** 3 * n2m1 ** 2 / (3 * 2.547e25 * lam ** 4) * (6 + 3 * rho) / (6 - 7 * rho)
    return beta_m * 1000.0  # 1/m -> 1/km


beta_spectral = beta_physical


def optical_depth(elev_rad, h_scale=8.0, r_earth=6360.0, top=100.0, n=4000):
    """Relative air mass times scale height: integral of exp(-h/H) along the ray to the sun (km)."""
    mu = np.sin(elev_rad)
    # distance to the top of the atmosphere from sea level
    s_max = -r_earth * mu + np.sqrt((r_earth * mu) ** 2 + (r_earth + top) ** 2 - r_earth ** 2)
    s = np.linspace(0.0, 1.0, n)[None, :] * s_max[:, None]
    h = np.sqrt(r_earth ** 2 + s ** 2 + 2 * r_earth * s * mu[:, None]) - r_earth
    return np.trapezoid(np.exp(-h / h_scale), s, axis=1)


ELEV = np.radians(np.linspace(0.0, 90.0, 91))
TAU = optical_depth(ELEV)
W = 1.0 / (np.sin(ELEV) + 0.1)
W /= W.sum()
XYZ_SPEC = None


def set_model(beta_fn):
    """Spectral reference: XYZ of the D65 sun after Rayleigh extinction, per elevation."""
    global beta_spectral, XYZ_SPEC
    beta_spectral = beta_fn
    t_spec = np.exp(-beta_fn(WL)[None, :] * TAU[:, None])  # elev x wl
    XYZ_SPEC = (t_spec * SUN[None, :]) @ CMFS  # elev x 3


def rgb_to_xyz(primaries):
    return colour.normalised_primary_matrix(primaries, D65_XY)


def error(primaries, beta):
    m = rgb_to_xyz(primaries)
    rgb = np.exp(-np.asarray(beta)[None, :] * TAU[:, None])
    xyz = rgb @ m.T
    rel = (xyz - XYZ_SPEC) / XYZ_SPEC[:, 1:2]
    return float(np.sum(W * np.sum(rel ** 2, axis=1)))


def locus_xy(wl):
    xyz = np.array([np.interp(wl, WL, CMFS[:, k]) for k in range(3)])
    return xyz[:2] / xyz.sum()


def step1_error(lams):
    prim = np.array([locus_xy(l) for l in lams])
    try:
        return error(prim, beta_spectral(np.asarray(lams)))
    except Exception:
        return 1e9


def fit(label, beta_fn):
    set_model(beta_fn)
    print(f"=== spectral Rayleigh model: {label} ===")
    print("spectral beta at the talk's primaries' wavelengths (605, 532, 454 nm):", beta_fn(np.array([605.0, 532.0, 454.0])))
    # Step 1: coarse search over wavelength triples, then continuous refinement.
    best = (np.inf, None)
    for ll in range(580, 681, 4):
        for lm in range(500, 571, 4):
            for ls in range(420, 481, 4):
                e = step1_error((ll, lm, ls))
                if e < best[0]:
                    best = (e, (ll, lm, ls))
    res1 = minimize(step1_error, np.array(best[1], dtype=float), method="Nelder-Mead",
                    options={"xatol": 1e-3, "fatol": 1e-14, "maxiter": 4000})
    lams = res1.x
    prim = np.array([locus_xy(l) for l in lams])
    # Step 2: fixed primaries, refine the coefficients.
    res2 = minimize(lambda b: error(prim, b), beta_spectral(lams), method="Nelder-Mead",
                    options={"xatol": 1e-9, "fatol": 1e-16, "maxiter": 4000})
    beta = res2.x

    np.set_printoptions(precision=5, suppress=True)
    print("step 1 wavelengths (nm, L M S):", lams)
    print("primaries (xy):\n", prim)
    print("talk primaries (xy):\n", TALK_PRIMARIES)
    print("max |primary difference|:", np.abs(prim - TALK_PRIMARIES).max())
    print("step 1 point-sampled beta (1/km):", beta_spectral(lams))
    print("step 2 refined beta (1/km):      ", beta)
    print("talk beta (1/km):                ", TALK_BETA)
    print("relative beta difference:         ", (beta - TALK_BETA) / TALK_BETA)
    print("weighted error, ours after step 2:", error(prim, beta))
    print("weighted error, talk's numbers:   ", error(TALK_PRIMARIES, TALK_BETA))
    print("weighted error, Rec.709 + Bruneton:",
          error(colour.RGB_COLOURSPACES["sRGB"].primaries, np.array([5.8e-3, 13.5e-3, 33.1e-3])))
    # Where the talk's primaries sit on the spectral locus (nearest wavelength).
    for name, p in zip("LMS", TALK_PRIMARIES):
        d = [np.linalg.norm(locus_xy(l) - p) for l in WL]
        print(f"talk primary {name} ~ {WL[int(np.argmin(d))]:.0f} nm (distance to locus {min(d):.4f})")
    print()


def main():
    fit("physical (Peck & Reeder n, King factor)", beta_physical)
    fit("lambda^-4 through Bruneton 2008", beta_bruneton)


if __name__ == "__main__":
    main()
