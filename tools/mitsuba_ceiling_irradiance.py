#!/usr/bin/env python3
"""One-bounce irradiance on the Cornell box's ceiling, exact and through hikari's L1 SH.

The ceiling is lit only by light bounced once (the light faces down), so its irradiance is the
GI alone. At five ceiling pixels of the 128 x 128 validation view this script, on Mitsuba 3's
ray queries (scalar variant, the scene of `mitsuba_cornell.py`), sends cosine-distributed rays,
lights each hit directly by sampling the area light (16 samples, BSDF times emitter weight),
and reports, in YCoCg luminance units per steradian (E / pi of a white surface):
- the exact estimate, the mean of the hits' radiance;
- the same rays projected onto L1 SH with hikari's weighting (uniform-hemisphere SH
  projection, weight 1 / (2 cos)) and resolved with the talk's bonus-slide formula.
docs/ray-traced-gi.md (Validation, item 5) compares them with hikari's accumulated GI.

    python3 tools/mitsuba_ceiling_irradiance.py [rays]
"""
import sys

import numpy as np
import mitsuba as mi

mi.set_variant("scalar_rgb")
sys.path.insert(0, __import__("os").path.dirname(__file__))
import mitsuba_cornell as cornell  # noqa: E402

C0, C1 = 0.28209479, 0.48860251
PIXELS = [(20, 64), (22, 64), (24, 64), (20, 40), (20, 88)]


def luma(c):
    return 0.25 * c[0] + 0.5 * c[1] + 0.25 * c[2]


def direct_radiance(scene, si, rng, samples=16):
    ctx = mi.BSDFContext()
    bsdf = si.bsdf()
    acc = 0.0
    for _ in range(samples):
        ds, weight = scene.sample_emitter_direction(si, mi.Point2f(*rng.random(2)), True)
        if ds.pdf == 0:
            continue
        f = bsdf.eval(ctx, si, si.to_local(ds.d))
        acc += luma([f[i] * weight[i] for i in range(3)])
    return acc / samples


def main():
    rays = int(sys.argv[1]) if len(sys.argv) > 1 else 3000
    scene = mi.load_dict(cornell.build_scene(mi, 128, 1, 3))
    sensor = scene.sensors()[0]
    rng = np.random.default_rng(0)
    for row, col in PIXELS:
        ray, _ = sensor.sample_ray(0.0, 0.5, mi.Point2f((col + 0.5) / 128, (row + 0.5) / 128),
                                   mi.Point2f(0.5, 0.5))
        si = scene.ray_intersect(ray)
        n = mi.Vector3f(si.n)
        if n[1] > 0:
            n = -n
        frame = mi.Frame3f(n)
        normal = np.array([n[0], n[1], n[2]])
        exact, c0, c1 = 0.0, 0.0, np.zeros(3)
        for _ in range(rays):
            d = frame.to_world(mi.warp.square_to_cosine_hemisphere(mi.Point2f(*rng.random(2))))
            hit = scene.ray_intersect(si.spawn_ray(d))
            if not hit.is_valid() or hit.shape.is_emitter():
                continue
            radiance = direct_radiance(scene, hit, rng)
            direction = np.array([d[0], d[1], d[2]])
            weight = 1.0 / (2.0 * float(direction @ normal))
            exact += radiance
            c0 += radiance * weight * C0
            c1 += radiance * weight * C1 * direction
        exact, c0, c1 = exact / rays, c0 / rays, c1 / rays
        l1 = 2.0 * ((2.0 * np.pi / 3.0) * C1 * float(c1 @ normal) + np.pi * C0 * c0)
        print(f"row {row} column {col}: exact {exact:.2f}, through L1 {l1:.2f}")


if __name__ == "__main__":
    main()
