#!/usr/bin/env python3
"""Directional albedo of the GGX specular lobe with height-correlated Smith masking and F = 1,
the reference table of crates/hikari-math/tests/brdf.rs (ALBEDO_TABLE).

Integrated with scipy's adaptive dblquad over the half vector (Walter et al. 2007, the tan form
of the GGX distribution; Heitz 2014 for the height-correlated G2), independently of the Rust
code. Run: pip install numpy scipy && python3 tools/brdf_albedo_table.py
Prints rows `(perceptual roughness, [albedo at n.v = 1.0, 0.7, 0.4, 0.2, 0.1])`.
"""
import numpy as np
from scipy import integrate

ROUGHNESS = [0.05, 0.10, 0.25, 0.50, 0.75, 1.00]
COS_VIEW = [1.0, 0.7, 0.4, 0.2, 0.1]


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


if __name__ == "__main__":
    for r in ROUGHNESS:
        row = ", ".join(f"{albedo(mu, r * r):.6f}" for mu in COS_VIEW)
        print(f"({r:.2f}, [{row}]),", flush=True)
