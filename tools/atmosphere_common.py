"""Shared spectral data for tools/atmosphere_lms_coefficients.py and tools/atmosphere_reference.py.

Ozone absorption cross-sections: Serdyuchenko et al. 2014 / Gorshelev et al. 2014 (University of
Bremen, o3spectra2011, 233 K), averaged over 10 nm bins from 360 nm, as tabulated in Bruneton's
2017 model (measured data, m^2 per molecule). Ozone number density at the tent's peak: 300 Dobson
units spread over the tent profile's 15 km integral.
"""
import warnings

warnings.filterwarnings("ignore")
import numpy as np  # noqa: E402
import colour  # noqa: E402

OZONE_NM = np.arange(360.0, 831.0, 10.0)
OZONE_CROSS_SECTION_M2 = np.array([
    1.18e-27, 2.182e-28, 2.818e-28, 6.636e-28, 1.527e-27, 2.763e-27, 5.52e-27,
    8.451e-27, 1.582e-26, 2.316e-26, 3.669e-26, 4.924e-26, 7.752e-26, 9.016e-26,
    1.48e-25, 1.602e-25, 2.139e-25, 2.755e-25, 3.091e-25, 3.5e-25, 4.266e-25,
    4.672e-25, 4.398e-25, 4.701e-25, 5.019e-25, 4.305e-25, 3.74e-25, 3.215e-25,
    2.662e-25, 2.238e-25, 1.852e-25, 1.473e-25, 1.209e-25, 9.423e-26, 7.455e-26,
    6.566e-26, 5.105e-26, 4.15e-26, 4.228e-26, 3.237e-26, 2.451e-26, 2.801e-26,
    2.534e-26, 1.624e-26, 1.465e-26, 2.078e-26, 1.383e-26, 7.105e-27])
DOBSON_PER_M2 = 2.687e20
OZONE_PEAK_PER_M3 = 300.0 * DOBSON_PER_M2 / 15000.0


def ozone_absorption_per_km(nm):
    """Ozone absorption at the tent's peak density, km^-1 (piecewise linear in the 10 nm bins)."""
    return np.interp(nm, OZONE_NM, OZONE_CROSS_SECTION_M2) * OZONE_PEAK_PER_M3 * 1000.0


def rayleigh_per_km(nm):
    """Rayleigh scattering at sea level, km^-1: the lambda^-4 law of Bruneton's 2017 model
    (1.24062e-6 m^-1 at 1 um), of which Bruneton 2008's Rec.709 values are point samples."""
    return 1.24062e-3 / (np.asarray(nm, dtype=float) / 1000.0) ** 4


# 5 nm grid over the visible range; the sun's spectrum is D65 (the white of both RGB spaces, so
# the RGB models' sun is (1, 1, 1) times its illuminance).
WL = np.arange(380.0, 781.0, 5.0)
_shape = colour.SpectralShape(380, 780, 5)
CMFS = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(_shape).values
D65 = colour.SDS_ILLUMINANTS["D65"].copy().align(_shape).values
# Spectral irradiance weights: sum(SUN * ybar) = 1, so a spectrum s(lambda) of relative
# transmittance or radiance per unit solar illuminance maps to XYZ as (CMFS.T @ (SUN * s)).
SUN = D65 / (CMFS[:, 1] @ D65)


def xyz_to_rgb_matrix(primaries):
    """Normalised primary matrix inverse for D65 white (RP 177), xy primaries as rows."""
    p = np.array([[x / y, 1.0, (1 - x - y) / y] for x, y in primaries]).T
    w = np.array([0.3127 / 0.3290, 1.0, (1 - 0.3127 - 0.3290) / 0.3290])
    s = np.linalg.solve(p, w)
    return np.linalg.inv(p * s)


REC709_PRIMARIES = [(0.64, 0.33), (0.30, 0.60), (0.15, 0.06)]
LMS_PRIMARIES = [(0.6501, 0.3495), (0.1711, 0.7959), (0.1520, 0.0218)]
XYZ_TO_REC709 = xyz_to_rgb_matrix(REC709_PRIMARIES)
XYZ_TO_LMS = xyz_to_rgb_matrix(LMS_PRIMARIES)


def spectrum_to(m, s):
    """Relative spectra s[..., wavelength] (per unit D65 sun) -> RGB through matrix m."""
    return (np.asarray(s) * SUN) @ CMFS @ m.T
