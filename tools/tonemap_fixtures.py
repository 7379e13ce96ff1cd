#!/usr/bin/env python3
"""Reference data for the tonemap technique (crates/hikari-render/tests/tonemap.rs), made by
tools no one here wrote: colour-science for the colour spaces, Bradford adaptation and the
.cube writer, numpy for the Purkinje shift written out from the talk's equations.

How to run (from the repository root):

    pip install colour-science numpy scipy
    python3 tools/tonemap_fixtures.py

Writes crates/hikari-render/tests/fixtures/tonemap.json and
crates/hikari-render/tests/fixtures/colour_science_{9,domain}.cube.

Nothing here is a value computed by hikari.
"""
import json
import sys
import warnings
from pathlib import Path

warnings.filterwarnings("ignore")
import numpy as np  # noqa: E402
import colour  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
FIX = ROOT / "crates/hikari-render/tests/fixtures"
sys.path.insert(0, str(ROOT / "tools"))
# The Smits basis and M = ∫ E_i D65 R_j, solved independently of hikari-math with scipy
# (the same script makes hikari-math's fixtures).
from make_math_fixtures import smits_and_purkinje  # noqa: E402


def rows(m):
    return [[float(v) for v in r] for r in np.asarray(m)]


# --- Purkinje shift, the talk's equations step by step (Patry 2021, after Cao et al. 2008) ---
M_MAX = np.array([0.63721, 0.39242, 1.6064])
K_ROD = np.array([0.2, 0.2, 0.29])
K, S, K3, RW, P = 45.0, 10.0, 0.6, 0.139, 0.6189
A = np.array([[-1, 1, 0], [-1, -1, 1], [1, 1, 0]], dtype=float)
B = np.array([[-(K3 + RW), 1 + K3 * RW, 0], [P * K3, (1 - P) * K3, 1], [P * S, (1 - P) * S, 0]])


def purkinje(c, m):
    q = m @ c  # LMSR
    g = (1.0 + 0.33 / M_MAX * (q[:3] + K_ROD * q[3])) ** -0.5
    delta_o = K / S * B @ np.diag(K_ROD) @ np.diag(1.0 / M_MAX) @ g * q[3]
    return c + np.linalg.inv(m[:3]) @ np.linalg.inv(A) @ delta_o


# Diffuse albedos (linear Rec.709): greys, the Rec.709 primaries and secondaries at 50 %,
# foliage, skin, sky blue, brick.
ALBEDOS = [
    [0.18, 0.18, 0.18], [0.9, 0.9, 0.9], [0.04, 0.04, 0.04],
    [0.5, 0.05, 0.05], [0.05, 0.5, 0.05], [0.05, 0.05, 0.5],
    [0.5, 0.5, 0.05], [0.05, 0.5, 0.5], [0.5, 0.05, 0.5],
    [0.08, 0.15, 0.04], [0.45, 0.3, 0.22], [0.2, 0.35, 0.6], [0.3, 0.09, 0.05],
]


def purkinje_cases():
    m = np.array(smits_and_purkinje()["lmsr_from_rec709_M"])
    out = []
    for lux in (0.05, 100000.0):
        for a in ALBEDOS:
            nits = np.array(a) * lux / np.pi  # a Lambertian albedo under `lux`
            out.append({"lux": lux, "albedo": a, "nits": [float(v) for v in nits],
                        "shifted_nits": [float(v) for v in purkinje(nits, m)]})
    return out


# --- Rec.709 -> tonemapping space, with white balance (von Kries in Bradford LMS) ---
def spaces():
    srgb = colour.RGB_COLOURSPACES["sRGB"]
    acescg = colour.RGB_COLOURSPACES["ACEScg"]
    prim = np.array(acescg.primaries, dtype=float).copy()
    assert abs(prim[0, 0] - 0.713) < 1e-12
    prim[0, 0] = 0.75
    rec709 = colour.RGB_Colourspace("rec709", srgb.primaries, srgb.whitepoint,
                                    use_derived_matrix_RGB_to_XYZ=True, use_derived_matrix_XYZ_to_RGB=True)
    tm = colour.RGB_Colourspace("tonemap", prim, acescg.whitepoint,
                                use_derived_matrix_RGB_to_XYZ=True, use_derived_matrix_XYZ_to_RGB=True)
    return rec709, tm


def white_balance_cases():
    rec709, tm = spaces()
    to_tm = colour.matrix_RGB_to_RGB(rec709, tm, chromatic_adaptation_transform="Bradford")
    out = []
    for white in ([1.0, 1.0, 1.0], [1.0, 0.85, 0.6], [0.7, 0.85, 1.2], [2.0, 2.0, 2.0]):
        xyz_src = rec709.matrix_RGB_to_XYZ @ np.ones(3)
        xyz_dst = rec709.matrix_RGB_to_XYZ @ np.array(white)
        cat = colour.adaptation.matrix_chromatic_adaptation_VonKries(xyz_src, xyz_dst, transform="Bradford")
        wb = rec709.matrix_XYZ_to_RGB @ cat @ rec709.matrix_RGB_to_XYZ
        out.append({"white": white, "tonemap_from_rec709": rows(to_tm @ wb)})
    return out


# --- .cube files written by colour-science, and trilinear samples of them by colour-science ---
def grade(rgb):
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    return np.stack([np.clip(0.9 * r + 0.1 * b, 0, 1) ** 0.8, g * g, 0.1 + 0.8 * b], axis=-1)


def cube_cases():
    rng = np.random.default_rng(19)
    out = []
    for name, size, domain in (("colour_science_9.cube", 9, [[0, 0, 0], [1, 1, 1]]),
                               ("colour_science_domain.cube", 5, [[0.0, 0.1, 0.0], [1.0, 0.9, 0.5]])):
        domain = np.array(domain, dtype=float)
        table = colour.LUT3D.linear_table(size, domain)
        unit = (table - domain[0]) / (domain[1] - domain[0])
        lut = colour.LUT3D(grade(unit), f"hikari test {name}", domain,
                           comments=["made by tools/tonemap_fixtures.py", "grade: see grade()"])
        colour.io.write_LUT(lut, str(FIX / name), decimals=7, method="Iridas Cube")
        back = colour.io.read_LUT(str(FIX / name))
        inputs = rng.uniform(domain[0] - 0.05, domain[1] + 0.05, size=(32, 3))
        clipped = np.clip(inputs, domain[0], domain[1])
        samples = back.apply(clipped, interpolator=colour.algebra.table_interpolation_trilinear)
        out.append({"file": name, "size": size, "domain": rows(domain),
                    "inputs": rows(inputs), "trilinear": rows(samples),
                    "entry_rgb_1_2_3": [float(v) for v in back.table[1, 2, 3]] if size > 3 else None})
    return out


def main():
    FIX.mkdir(parents=True, exist_ok=True)
    data = {
        "purkinje": purkinje_cases(),
        "white_balance": white_balance_cases(),
        "cube": cube_cases(),
        "sources": {
            "purkinje": "numpy, the talk's equations (g, Δo, Δc) with M from an independent Smits basis (scipy SLSQP) and colour-science spectra",
            "white_balance": "colour-science matrix_RGB_to_RGB (Bradford) and matrix_chromatic_adaptation_VonKries (Bradford)",
            "cube": "colour-science LUT3D, write_LUT (Iridas/Adobe .cube), table_interpolation_trilinear",
        },
    }
    (FIX / "tonemap.json").write_text(json.dumps(data, indent=1))


if __name__ == "__main__":
    main()
