#!/usr/bin/env python3
"""Reference data for crates/hikari-math, produced by colour-science (an independent tool).

How to run (from the repository root):

    pip install colour-science numpy scipy
    python3 tools/make_math_fixtures.py            # writes crates/hikari-math/tests/fixtures/*.json
    python3 tools/make_math_fixtures.py --rust     # also regenerates the generated Rust tables:
                                                   # crates/hikari-math/src/color/spectral_data.rs
                                                   # crates/hikari-math/src/sampling/sobol_data.rs

The JSON files are committed; the Rust tests compare the crate against them.  The Rust
spectral tables are generated from the same colour-science datasets once and committed, so
the crate has no Python dependency; a test checks the committed tables against the fixture.

Everything is computed by colour-science from primaries / white points / datasets; nothing in
this file is a value computed by hikari-math.
"""
import json
import sys
import warnings
from pathlib import Path

warnings.filterwarnings("ignore")
import numpy as np  # noqa: E402
import colour  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
FIX = ROOT / "crates/hikari-math/tests/fixtures"
RUST_TABLES = ROOT / "crates/hikari-math/src/color/spectral_data.rs"
RUST_SOBOL = ROOT / "crates/hikari-math/src/sampling/sobol_data.rs"
SOBOL_DIMS = 64

D65_XY = np.array([0.3127, 0.3290])


def rows(m):
    return [[float(v) for v in r] for r in np.asarray(m)]


def space(name, primaries, white):
    return colour.RGB_Colourspace(name, np.array(primaries, dtype=float), np.array(white, dtype=float),
                                  use_derived_matrix_RGB_to_XYZ=True, use_derived_matrix_XYZ_to_RGB=True)


def colour_spaces():
    cs = colour.RGB_COLOURSPACES
    acescg = cs["ACEScg"]
    tone_prim = np.array(acescg.primaries, dtype=float).copy()
    assert abs(tone_prim[0, 0] - 0.713) < 1e-12
    tone_prim[0, 0] = 0.75  # the Ghost of Tsushima tonemapping space: ACEScg with red x 0.713 -> 0.75
    return {
        "rec709": space("rec709", cs["sRGB"].primaries, cs["sRGB"].whitepoint),
        "acescg": space("acescg", acescg.primaries, acescg.whitepoint),
        "aces2065_1": space("aces2065_1", cs["ACES2065-1"].primaries, cs["ACES2065-1"].whitepoint),
        "rec2020": space("rec2020", cs["ITU-R BT.2020"].primaries, cs["ITU-R BT.2020"].whitepoint),
        "display_p3": space("display_p3", cs["Display P3"].primaries, cs["Display P3"].whitepoint),
        "tonemap": space("tonemap", tone_prim, acescg.whitepoint),
        # The LMS Rayleigh space of the talk: its primaries, D65 white.
        "lms_rayleigh": space("lms_rayleigh", [[0.6501, 0.3495], [0.1711, 0.7959], [0.1520, 0.0218]], D65_XY),
    }


def matrices():
    spaces = colour_spaces()
    out = {"spaces": {}}
    for name, s in spaces.items():
        out["spaces"][name] = {
            "primaries": rows(s.primaries),
            "white": [float(v) for v in s.whitepoint],
            "rgb_to_xyz": rows(colour.normalised_primary_matrix(s.primaries, s.whitepoint)),
            "xyz_to_rgb": rows(np.linalg.inv(colour.normalised_primary_matrix(s.primaries, s.whitepoint))),
        }
    r709 = spaces["rec709"]
    out["rec709_to_tonemap_bradford"] = rows(colour.matrix_RGB_to_RGB(r709, spaces["tonemap"], "Bradford"))
    out["tonemap_to_rec709_bradford"] = rows(colour.matrix_RGB_to_RGB(spaces["tonemap"], r709, "Bradford"))
    out["rec709_to_lms_rayleigh"] = rows(colour.matrix_RGB_to_RGB(r709, spaces["lms_rayleigh"], None))
    out["rec709_to_acescg_bradford"] = rows(colour.matrix_RGB_to_RGB(r709, spaces["acescg"], "Bradford"))
    out["bradford"] = rows(colour.adaptation.CAT_BRADFORD)

    m = colour.normalised_primary_matrix(r709.primaries, r709.whitepoint)
    m_inv = np.linalg.inv(m)
    wb = []
    for target in ([1.0, 0.9, 0.8], [0.7, 0.85, 1.0], [0.5, 0.5, 0.5], [1.2, 1.0, 0.6]):
        xyz_src = m @ np.ones(3)
        xyz_dst = m @ np.array(target)
        cat = colour.adaptation.matrix_chromatic_adaptation_VonKries(xyz_src, xyz_dst, transform="Bradford")
        wb.append({"target_rec709": target, "white_balance_rec709": rows(m_inv @ cat @ m)})
    out["white_balance"] = wb

    xs = [0.0, 0.001, 0.0031308, 0.01, 0.04045, 0.18, 0.5, 0.9, 1.0]
    out["srgb_encode"] = [[x, float(colour.cctf_encoding(x, function="sRGB"))] for x in xs]
    out["srgb_decode"] = [[x, float(colour.cctf_decoding(x, function="sRGB"))] for x in xs]
    return out


GRID = np.arange(390, 781, 5, dtype=float)  # common grid: Stockman & Sharpe starts at 390 nm


def spectral():
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    lms = colour.MSDS_CMFS["Stockman & Sharpe 2 Degree Cone Fundamentals"]
    rod = colour.SDS_LEFS["CIE 1951 Scotopic Standard Observer"]
    d65 = colour.SDS_ILLUMINANTS["D65"]
    for sd in (cmfs, lms, rod, d65):
        for w in GRID:  # only tabulated points, never interpolated values
            assert w in sd.wavelengths, (sd.name, w)
    out = {
        "wavelengths_nm": GRID.tolist(),
        "cie1931_xyz": rows(cmfs[GRID]),
        "d65": [float(v) for v in d65[GRID]],
        "stockman_sharpe_lms": rows(lms[GRID]),
        "scotopic_v": [float(v) for v in rod[GRID]],
        "sources": {
            "cie1931_xyz": "colour-science MSDS_CMFS['CIE 1931 2 Degree Standard Observer'] (CIE 018:2019 / CIE 1931 2 degree)",
            "d65": "colour-science SDS_ILLUMINANTS['D65'] (CIE S 014-2 / ISO 11664-2 relative spectral power)",
            "stockman_sharpe_lms": "colour-science MSDS_CMFS['Stockman & Sharpe 2 Degree Cone Fundamentals'] (CVRL, linear energy, peak 1)",
            "scotopic_v": "colour-science SDS_LEFS['CIE 1951 Scotopic Standard Observer'] (CVRL, V'(lambda))",
        },
    }
    from colour.recovery import SDS_SMITS1999
    smits = {k: [float(v) for v in SDS_SMITS1999[k].values] for k in
             ("white", "cyan", "magenta", "yellow", "red", "green", "blue")}
    out["smits1999"] = {"wavelengths_nm": [float(v) for v in SDS_SMITS1999["white"].wavelengths], **smits}
    # D65 white of the tabulated data, for the spectral consistency test.
    xyz = np.array(rows(cmfs[GRID])).T @ np.array(d65[GRID])
    out["d65_xy_from_tables"] = [float(xyz[0] / xyz.sum()), float(xyz[1] / xyz.sum())]
    # Spectral locus chromaticities (for the LMS Rayleigh primaries).
    locus = colour.XYZ_to_xy(cmfs[GRID])
    out["spectral_locus_xy"] = rows(locus)
    return out


SMITS_GRID = np.arange(390, 781, 10, dtype=float)
PURKINJE = dict(m=[0.63721, 0.39242, 1.6064], k=[0.2, 0.2, 0.29], K=45.0, S=10.0, k3=0.6, rw=0.139, p=0.6189)


def smits_and_purkinje():
    """Independent solution of the Smits basis problem (as specified in
    crates/hikari-math/src/color/smits.rs docs) with scipy's SLSQP, and the Purkinje matrices of
    the talk computed from it with numpy."""
    from scipy.optimize import minimize

    grid = SMITS_GRID
    n = len(grid)
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"][grid]
    d65 = colour.SDS_ILLUMINANTS["D65"][grid]
    d = d65 / (cmfs[:, 1] @ d65)
    srgb = colour.RGB_COLOURSPACES["sRGB"]
    t = np.linalg.inv(colour.normalised_primary_matrix(srgb.primaries, srgb.whitepoint)) @ (cmfs * d[:, None]).T
    t = t / t.sum(axis=1, keepdims=True)  # spectral Rec.709: D65 table -> (1, 1, 1)
    dm = np.diff(np.eye(n), axis=0)
    q = np.kron(np.eye(3), 2.0 * dm.T @ dm)

    cons = [{"type": "eq", "fun": lambda x: np.concatenate([t @ x[:n] - [1, 0, 0], t @ x[n:2 * n] - [0, 1, 0]]),
             "jac": lambda x: np.block([[t, np.zeros((3, 2 * n))], [np.zeros((3, n)), t, np.zeros((3, n))]])},
            {"type": "eq", "fun": lambda x: x[:n] + x[n:2 * n] + x[2 * n:] - 1.0,
             "jac": lambda x: np.hstack([np.eye(n)] * 3)}]
    res = minimize(lambda x: 0.5 * x @ q @ x, np.full(3 * n, 1 / 3), jac=lambda x: q @ x, method="SLSQP",
                   constraints=cons, bounds=[(0.0, 1.0)] * (3 * n), options={"ftol": 1e-15, "maxiter": 2000})
    assert res.success, res.message
    basis = res.x.reshape(3, n)

    lms = colour.MSDS_CMFS["Stockman & Sharpe 2 Degree Cone Fundamentals"][grid]
    rod = colour.SDS_LEFS["CIE 1951 Scotopic Standard Observer"][grid]
    e = np.column_stack([lms, rod])  # n x 4
    m = (e * d[:, None]).T @ basis.T  # 4 x 3
    pk = PURKINJE
    b = np.array([[-(pk["k3"] + pk["rw"]), 1 + pk["k3"] * pk["rw"], 0],
                  [pk["p"] * pk["k3"], (1 - pk["p"]) * pk["k3"], 1],
                  [pk["p"] * pk["S"], (1 - pk["p"]) * pk["S"], 0]])
    a = np.array([[-1, 1, 0], [-1, -1, 1], [1, 1, 0]], dtype=float)
    mm, kk = np.array(pk["m"]), np.array(pk["k"])
    rod_inc = pk["K"] / pk["S"] * b @ np.diag(kk / mm)
    rgb_from_gain = np.linalg.inv(m[:3]) @ np.linalg.inv(a) @ rod_inc
    lmsr = m.copy()
    lmsr[:3] = (0.33 / mm)[:, None] * (m[:3] + kk[:, None] * m[3][None, :])
    return {
        "wavelengths_nm": grid.tolist(),
        "smits_basis_rgb": rows(basis),
        "smits_objective": float(res.fun),
        "lmsr_from_rec709_M": rows(m),
        "lmsr_from_rec709": rows(lmsr),
        "rgb_from_lms_gain": rows(rgb_from_gain),
    }


def fmt_arr(vals):
    return ", ".join(repr(float(v)) for v in vals)


def write_rust(spec):
    n = len(spec["wavelengths_nm"])
    s = spec["smits1999"]
    lines = [
        "// @generated by tools/make_math_fixtures.py --rust from colour-science datasets. Do not edit.",
        "//! Tabulated spectral data, 390..=780 nm every 5 nm (only tabulated points, no interpolation).",
        "",
        f"/// Number of samples in the 5 nm tables.",
        f"pub const LEN: usize = {n};",
        "/// First wavelength of the tables, nm.",
        "pub const START_NM: f64 = 390.0;",
        "/// Wavelength spacing of the tables, nm.",
        "pub const STEP_NM: f64 = 5.0;",
        "",
        "/// CIE 1931 2 degree colour matching functions x̄, ȳ, z̄ (CIE 018:2019; via colour-science",
        "/// `MSDS_CMFS['CIE 1931 2 Degree Standard Observer']`).",
        f"pub const CIE1931_XYZ: [[f64; 3]; LEN] = [",
    ]
    lines += [f"    [{fmt_arr(r)}]," for r in spec["cie1931_xyz"]]
    lines += ["];", "",
              "/// CIE standard illuminant D65, relative spectral power (CIE S 014-2; via colour-science",
              "/// `SDS_ILLUMINANTS['D65']`).",
              f"pub const D65: [f64; LEN] = [{fmt_arr(spec['d65'])}];", "",
              "/// Stockman & Sharpe (2000) 2 degree cone fundamentals L, M, S, linear energy units, peak 1",
              "/// (CVRL; via colour-science `MSDS_CMFS['Stockman & Sharpe 2 Degree Cone Fundamentals']`).",
              f"pub const STOCKMAN_SHARPE_LMS: [[f64; 3]; LEN] = ["]
    lines += [f"    [{fmt_arr(r)}]," for r in spec["stockman_sharpe_lms"]]
    lines += ["];", "",
              "/// CIE 1951 scotopic luminous efficiency V'(λ), peak 1 (CVRL; via colour-science",
              "/// `SDS_LEFS['CIE 1951 Scotopic Standard Observer']`).",
              f"pub const SCOTOPIC_V: [f64; LEN] = [{fmt_arr(spec['scotopic_v'])}];", "",
              "/// Wavelengths of Smits' table, nm: 10 bins spanning 380..=720 nm.",
              f"pub const SMITS1999_NM: [f64; 10] = [{fmt_arr(s['wavelengths_nm'])}];",
              "/// Smits (1999) \"An RGB-to-spectrum conversion for reflectances\", table of reflectance",
              "/// spectra, rows: white, cyan, magenta, yellow, red, green, blue (via colour-science",
              "/// `colour.recovery.SDS_SMITS1999`).",
              "pub const SMITS1999: [[f64; 10]; 7] = ["]
    for k in ("white", "cyan", "magenta", "yellow", "red", "green", "blue"):
        lines.append(f"    [{fmt_arr(s[k])}],")
    lines += ["];", ""]
    RUST_TABLES.write_text("\n".join(lines))


def sobol_tables():
    """Joe & Kuo (2008) direction numbers (new-joe-kuo-6.21201) as shipped by scipy."""
    import os
    import scipy.stats
    d = np.load(os.path.join(os.path.dirname(scipy.stats.__file__), "_sobol_direction_numbers.npz"))
    return d["poly"][:SOBOL_DIMS], d["vinit"][:SOBOL_DIMS]


def sobol_fixture():
    from scipy.stats import qmc
    pts = qmc.Sobol(d=16, scramble=False).random(256)
    return {"source": "scipy.stats.qmc.Sobol(d=16, scramble=False).random(256)", "dims": 16,
            "points": [[float(v) for v in r] for r in pts]}


def write_sobol_rust():
    poly, vinit = sobol_tables()
    lines = [
        "// @generated by tools/make_math_fixtures.py --rust from scipy's copy of the Joe & Kuo (2008)",
        "// direction numbers (new-joe-kuo-6.21201, https://web.maths.unsw.edu.au/~fkuo/sobol/). Do not edit.",
        "//! Sobol direction-number initialisation for the first dimensions.",
        "",
        "/// Number of dimensions tabulated.",
        f"pub const DIMS: usize = {SOBOL_DIMS};",
        "/// Primitive polynomial of each dimension, bits `1 a_1 ... a_(s-1) 1` (degree s = bit length - 1);",
        "/// dimension 0 (value 1) is the van der Corput sequence.",
        f"pub const POLY: [u32; DIMS] = [{', '.join(str(int(v)) for v in poly)}];",
        "/// Initial direction numbers m_1..m_s of each dimension (zero-padded).",
        f"pub const VINIT: [[u32; {vinit.shape[1]}]; DIMS] = [",
    ]
    lines += ["    [" + ", ".join(str(int(v)) for v in r) + "]," for r in vinit]
    lines += ["];", ""]
    RUST_SOBOL.write_text("\n".join(lines))


def main():
    FIX.mkdir(parents=True, exist_ok=True)
    (FIX / "color_matrices.json").write_text(json.dumps(matrices(), indent=1))
    spec = spectral()
    (FIX / "spectral.json").write_text(json.dumps(spec, indent=1))
    (FIX / "smits_purkinje.json").write_text(json.dumps(smits_and_purkinje(), indent=1))
    (FIX / "sobol.json").write_text(json.dumps(sobol_fixture()))
    if "--rust" in sys.argv:
        write_rust(spec)
        write_sobol_rust()
    print("wrote", FIX)


if __name__ == "__main__":
    main()
