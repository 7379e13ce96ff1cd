#!/usr/bin/env python3
"""Independent references for hikari-math's BRDF (crates/hikari-math/src/brdf), written from the
papers, not from the Rust code.

1. (default) The directional albedo of the GGX specular lobe with height-correlated Smith
   masking and F = 1: the ALBEDO_TABLE of crates/hikari-math/tests/brdf.rs, integrated with
   scipy's adaptive dblquad over the half vector (Walter et al. 2007, the tan form of the GGX
   distribution; Heitz 2014 for the height-correlated G2). Prints rows
   `(perceptual roughness, [albedo at n.v = 1.0, 0.7, 0.4, 0.2, 0.1])`.

2. (--fixture) The energy-compensated model of docs/brdf.md: the single-scattering albedos
   E (F = 1) and E_w (F = (1 - v.h)^5) and their cosine-weighted averages, then, evaluated here
   in numpy from the papers' formulas (Kulla & Conty 2017; Kelemen & Szirmay-Kalos 2001), the
   multiple-scattering colour F_ms, the dielectric's specular albedo E_d and the directional
   albedo of whole materials (white and coloured, dielectric and metal). Writes
   crates/hikari-math/tests/fixtures/brdf_energy.json, which tests/brdf.rs compares with
   hikari-math's tables and with its BRDF integrated numerically.

   Quadrature: a numpy midpoint rule on 2048 x 2048 nodes of the half-vector map below (with
   u = 1 - (1 - s)^2 against GGX's heavy tail), a different rule and parameterisation from
   hikari-math's (which integrates over visible normals); averages by 48-node Gauss-Legendre in
   x = sqrt(n.v). `--check` compares a few points with scipy's dblquad.

Run: pip install numpy scipy && python3 tools/brdf_albedo_table.py [--fixture] [--check]
"""
import json
import sys
from pathlib import Path

import numpy as np
from scipy import integrate

ROUGHNESS = [0.05, 0.10, 0.25, 0.50, 0.75, 1.00]
COS_VIEW = [1.0, 0.7, 0.4, 0.2, 0.1]

FIXTURE_ROUGHNESS = [0.045, 0.1, 0.2, 0.35, 0.5, 0.7, 0.85, 1.0]
FIXTURE_COS_VIEW = [1.0, 0.8, 0.5, 0.3, 0.15, 0.1045, 0.05]
DIELECTRIC_F0 = 0.04
# Coloured materials whose whole albedo the fixture gives (linear base colour).
COLOURED = [
    ("gold metal", [1.0, 0.78, 0.34], 1.0),
    ("red dielectric", [0.8, 0.1, 0.05], 0.0),
    ("half metal", [0.9, 0.6, 0.3], 0.5),
]


def smith_lambda(mu, alpha):
    t2 = (1.0 - mu * mu) / (mu * mu)
    return 0.5 * (-1.0 + np.sqrt(1.0 + alpha * alpha * t2))


def albedo(mu, alpha):
    v = np.array([np.sqrt(1.0 - mu * mu), 0.0, mu])

    # u in [0, 1) parameterises the half-vector polar angle so that D(h) cos(theta_h) dw_h
    # becomes du dphi / (2 pi): tan(theta_h) = alpha sqrt(u / (1 - u)).
    def integrand(phi, u):
        th = np.arctan(alpha * np.sqrt(u / (1.0 - u)))
        h = np.array([np.sin(th) * np.cos(phi), np.sin(th) * np.sin(phi), np.cos(th)])
        vh = v @ h
        if vh <= 0.0:
            return 0.0
        l = 2.0 * vh * h - v
        if l[2] <= 0.0:
            return 0.0
        g2 = 1.0 / (1.0 + smith_lambda(mu, alpha) + smith_lambda(l[2], alpha))
        # f cos dw_l = D G2 / (4 n.v n.l) n.l 4 v.h dw_h, with D cos dw_h = du dphi / 2 pi.
        return g2 * vh / (mu * h[2]) / (2.0 * np.pi)

    value, _ = integrate.dblquad(integrand, 0.0, 1.0, 0.0, 2.0 * np.pi, epsabs=1e-10, epsrel=1e-9)
    return value


def albedos_numpy(mu, alpha, n=2048):
    """(E, E_w) at n.v = mu by the vectorised midpoint rule of the module docs."""
    mu = max(mu, 1e-9)
    s = (np.arange(n) + 0.5) / n
    u = 1.0 - (1.0 - s) ** 2
    w_s = 2.0 * (1.0 - s)
    phi = np.pi * (np.arange(n) + 0.5) / n  # [0, pi]: mirror symmetry about the view plane
    th = np.arctan(alpha * np.sqrt(u / (1.0 - u)))[:, None]
    hx = np.sin(th) * np.cos(phi)[None, :]
    hz = np.cos(th) * np.ones_like(phi)[None, :]
    sv = np.sqrt(1.0 - mu * mu)
    vh = sv * hx + mu * hz
    lz = 2.0 * vh * hz - mu
    ok = (vh > 0.0) & (lz > 0.0)
    lzc = np.where(ok, lz, 1.0)
    g2 = 1.0 / (1.0 + smith_lambda(mu, alpha) + smith_lambda(lzc, alpha))
    f = np.where(ok, g2 * vh / (mu * hz), 0.0) * w_s[:, None]
    weight = 1.0 / (n * n)  # du dphi / (2 pi) over [0, 1] x [0, 2 pi], halved and doubled
    e = f.sum() * weight
    e_w = (f * (1.0 - np.clip(vh, 0.0, 1.0)) ** 5).sum() * weight
    return e, e_w


def averages(alpha, nodes=48):
    """2 int_0^1 E(mu) mu dmu = 4 int_0^1 E(x^2) x^3 dx by Gauss-Legendre in x."""
    x, w = np.polynomial.legendre.leggauss(nodes)
    x = 0.5 * (x + 1.0)
    w = 0.5 * w
    e_avg = e_w_avg = 0.0
    for xi, wi in zip(x, w):
        e, e_w = albedos_numpy(xi * xi, alpha, 1024)
        e_avg += 4.0 * wi * xi**3 * e
        e_w_avg += 4.0 * wi * xi**3 * e_w
    return e_avg, e_w_avg


def f_ms(f0, e_avg):
    f_avg = f0 + (1.0 - f0) / 21.0
    return f_avg * f_avg * e_avg / (1.0 - f_avg * (1.0 - e_avg))


def model_albedo(base, metalness, e, e_w, e_avg, e_w_avg):
    """Directional albedo of the model per channel: the lobes' albedos are exact consequences
    of the formulas (the multiple-scattering lobe reflects F_ms (1 - E), the diffuse lobe
    rho (1 - E_d)), blended by metalness."""
    base = np.asarray(base, dtype=float)
    fms_d = f_ms(DIELECTRIC_F0, e_avg)
    e_d = DIELECTRIC_F0 * e + (1 - DIELECTRIC_F0) * e_w + fms_d * (1 - e)
    dielectric = e_d + base * (1.0 - e_d)
    metal = base * e + (1.0 - base) * e_w + f_ms(base, e_avg) * (1.0 - e)
    return (1.0 - metalness) * dielectric + metalness * metal


def fixture():
    out = {
        "source": "tools/brdf_albedo_table.py --fixture (numpy midpoint 2048 x 2048, averages "
        "48-node Gauss-Legendre in sqrt(n.v) on 1024 x 1024)",
        "roughness": FIXTURE_ROUGHNESS,
        "cos_view": FIXTURE_COS_VIEW,
        "e": [],
        "e_schlick": [],
        "e_avg": [],
        "e_schlick_avg": [],
        "materials": [],
    }
    for r in FIXTURE_ROUGHNESS:
        a = r * r
        row = [albedos_numpy(mu, a) for mu in FIXTURE_COS_VIEW]
        out["e"].append([x[0] for x in row])
        out["e_schlick"].append([x[1] for x in row])
        ea, ewa = averages(a)
        out["e_avg"].append(ea)
        out["e_schlick_avg"].append(ewa)
        print(f"r {r}: E {[f'{x[0]:.5f}' for x in row]} E_avg {ea:.5f} E_w_avg {ewa:.5f}", flush=True)
    for name, base, metal in COLOURED + [("white dielectric", [1, 1, 1], 0.0), ("white metal", [1, 1, 1], 1.0)]:
        albedo_rows = []
        for j, r in enumerate(FIXTURE_ROUGHNESS):
            albedo_rows.append([
                list(model_albedo(base, metal, out["e"][j][i], out["e_schlick"][j][i],
                                  out["e_avg"][j], out["e_schlick_avg"][j]))
                for i in range(len(FIXTURE_COS_VIEW))
            ])
        out["materials"].append({"name": name, "base_color": base, "metalness": metal,
                                 "albedo": albedo_rows})
    path = Path(__file__).resolve().parent.parent / "crates/hikari-math/tests/fixtures/brdf_energy.json"
    tmp = path.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(out, indent=1) + "\n")
    tmp.replace(path)
    print(f"wrote {path}")


if __name__ == "__main__":
    if "--check" in sys.argv:
        for r in [0.25, 0.5, 1.0]:
            for mu in [1.0, 0.4, 0.1]:
                print(f"r {r} mu {mu}: dblquad {albedo(mu, r * r):.6f} numpy {albedos_numpy(mu, r * r)[0]:.6f}")
    elif "--fixture" in sys.argv:
        fixture()
    else:
        for r in ROUGHNESS:
            row = ", ".join(f"{albedo(mu, r * r):.6f}" for mu in COS_VIEW)
            print(f"({r:.2f}, [{row}]),", flush=True)
