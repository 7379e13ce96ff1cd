#!/usr/bin/env python3
"""Reference irradiance at probe positions from Mitsuba 3, for hikari-bake's sky-visibility
plus one-bounce test (crates/hikari-bake/tests/mitsuba_irradiance.rs).

Scene: axis-aligned boxes (a ground slab, a wall, an overhanging roof slab, a pillar), each
a Lambertian `diffuse` BSDF (one-sided; boxes are closed, so no back face is ever seen) with
an RGB albedo, lit only by a `constant` environment emitter of radiance 1 in every direction
(a uniform white sky that also shines from below the horizon, as the bake's escaping rays
count). Irradiance E(n) = integral of L cos over the hemisphere around n is measured with
Mitsuba's `irradiancemeter` sensor on a 1 cm square facing n at each probe position.

Integrator: `path` with max_depth = 2 (Mitsuba counts path vertices: 1 sees emitters only,
2 adds light reflected once), so the reference holds exactly what the bake holds: the sky seen
directly plus sky light reflected once by a surface. rr_depth is set above max_depth: no
Russian roulette noise.

Usage: pip install mitsuba==3.9.1; python3 tools/mitsuba_probe_irradiance.py
Writes crates/hikari-bake/tests/fixtures/mitsuba_irradiance.json.
"""

import json
import os

import mitsuba as mi
import numpy as np

mi.set_variant("scalar_rgb")

# (name, lo, hi, albedo): metres, y up.
BOXES = [
    ("ground", [-40.0, -0.5, -40.0], [40.0, 0.0, 40.0], [0.5, 0.5, 0.5]),
    ("wall", [-5.0, 0.0, 2.0], [5.0, 4.0, 2.3], [0.8, 0.4, 0.2]),
    ("roof", [-5.0, 4.0, -1.5], [5.0, 4.2, 2.3], [0.3, 0.6, 0.3]),
    ("pillar", [-5.0, 0.0, -1.5], [-4.7, 4.0, -1.2], [0.9, 0.9, 0.9]),
]

# (position, normal): probes under the overhang, in the open, beside the wall, above the roof.
PROBES = [
    ([0.0, 1.5, 0.5], [0.0, 1.0, 0.0]),
    ([0.0, 1.5, 0.5], [0.0, 0.0, 1.0]),
    ([0.0, 1.5, 0.5], [0.0, 0.0, -1.0]),
    ([0.0, 1.5, 0.5], [0.0, -1.0, 0.0]),
    ([-3.5, 2.0, -0.5], [-1.0, 0.0, 0.0]),
    ([2.0, 1.0, -4.0], [0.0, 0.0, 1.0]),
    ([2.0, 1.0, -4.0], [0.0, 1.0, 0.0]),
    ([7.0, 1.5, 1.0], [-1.0, 0.0, 0.0]),
    ([0.0, 6.0, 0.0], [0.0, -1.0, 0.0]),
    ([0.0, 6.0, 0.0], [0.0, 1.0, 0.0]),
    ([0.0, 0.3, 1.5], [0.0, 0.0, 1.0]),
    ([0.0, 0.3, 1.5], [0.0, -1.0, 0.0]),
]

SPP = 1 << 18


def box_shape(lo, hi, albedo):
    centre = [(a + b) / 2 for a, b in zip(lo, hi)]
    half = [(b - a) / 2 for a, b in zip(lo, hi)]
    return {
        "type": "cube",
        "to_world": mi.ScalarTransform4f().translate(centre).scale(half),
        "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": albedo}},
    }


def irradiance(position, normal, boxes=BOXES):
    p = mi.ScalarPoint3f(position)
    n = mi.ScalarVector3f(normal)
    up = [0.0, 0.0, 1.0] if abs(normal[1]) > 0.5 else [0.0, 1.0, 0.0]
    # look_at points the rectangle's +z (its normal) from p towards p + n.
    to_world = mi.ScalarTransform4f().look_at(origin=p, target=p + n, up=up).scale(0.005)
    scene = {"type": "scene", "integrator": {"type": "path", "max_depth": 2, "rr_depth": 100}}
    scene["sky"] = {"type": "constant", "radiance": {"type": "rgb", "value": 1.0}}
    for name, lo, hi, albedo in boxes:
        scene[name] = box_shape(lo, hi, albedo)
    scene["meter"] = {
        "type": "rectangle",
        "to_world": to_world,
        "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": 0.0}},
        "sensor": {
            "type": "irradiancemeter",
            "film": {"type": "hdrfilm", "width": 1, "height": 1, "rfilter": {"type": "box"},
                     "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": SPP},
        },
    }
    s = mi.load_dict(scene)
    img = mi.render(s, spp=SPP)
    a = np.array(img).reshape(-1)
    return [float(a[c]) for c in range(3)]


def main():
    out = {
        "generator": "tools/mitsuba_probe_irradiance.py",
        "mitsuba": mi.__version__,
        "variant": "scalar_rgb",
        "integrator": "path, max_depth 2 (sky seen directly + one bounce), rr_depth 100",
        "emitter": "constant, radiance 1",
        "samples_per_probe": SPP,
        "boxes": [{"name": n, "lo": lo, "hi": hi, "albedo": a} for n, lo, hi, a in BOXES],
        "probes": [],
    }
    # The meter itself: with nothing but the sky, E = pi for any normal.
    open_sky = irradiance([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], boxes=[])
    assert all(abs(e - np.pi) < 1e-2 for e in open_sky), open_sky
    for position, normal in PROBES:
        e = irradiance(position, normal)
        print(position, normal, e)
        out["probes"].append({"position": position, "normal": normal, "irradiance": e})
    path = os.path.join(os.path.dirname(__file__), "..", "crates", "hikari-bake", "tests",
                        "fixtures", "mitsuba_irradiance.json")
    with open(path, "w") as f:
        json.dump(out, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    main()
