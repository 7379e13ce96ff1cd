#!/usr/bin/env python3
"""Reference for hikari's area lights: the classic Cornell box rendered by Mitsuba 3 with
DIRECT lighting only (integrator `path`, max_depth = 2: the emitter seen, and one bounce to it),
from the same published data as hikari's `cornell_data` (crates/hikari-scene/src/builtin.rs),
with the same camera, light and albedos.

    pip install mitsuba numpy
    python3 tools/mitsuba_cornell.py [--size 64] [--spp 4096] \
        [-o crates/hikari-render/tests/fixtures/mitsuba_cornell_direct_64.pfm]
    # direct light plus ONE diffuse bounce (path, max_depth 3), for the ray-traced GI (65536
    # spp, about 15 CPU minutes; two 4096-spp renders differ by FLIP 0.013):
    python3 tools/mitsuba_cornell.py --size 128 --spp 65536 --max-depth 3 --seed 3 \
        -o crates/hikari-render/tests/fixtures/mitsuba_cornell_one_bounce_128.pfm
    # ray-traced AO with hikari's ao_max_distance_m (50 m): Mitsuba's own path tracer under a
    # uniform sky (see the note above `build_scene`; 65536 spp, about 8 CPU minutes, seed 3):
    python3 tools/mitsuba_cornell.py --size 128 --spp 65536 --ao-distance 50 --seed 3 \
        -o crates/hikari-render/tests/fixtures/mitsuba_cornell_ao50_128.pfm
    # the reference's own noise: the same at two seeds, compared with each other
    python3 tools/mitsuba_cornell.py --size 128 --spp 1024 --ao-distance 50 --seed 1 -o /tmp/a.pfm

Output: a PFM (portable float map: "PF", width height, -1.0 for little-endian, then RGB f32
rows from the bottom up), linear Rec.709 radiance in nits (Mitsuba's `rgb` variant with the
radiance given in nits). The geometry, light and camera below are typed in from the published
Cornell box data (Program of Computer Graphics, Cornell University), not taken from hikari.
"""

import argparse
import os
import tempfile

import numpy as np

FLOOR = [[552.8, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 559.2], [549.6, 0.0, 559.2]]
CEILING = [[556.0, 548.8, 0.0], [556.0, 548.8, 559.2], [0.0, 548.8, 559.2], [0.0, 548.8, 0.0]]
BACK = [[549.6, 0.0, 559.2], [0.0, 0.0, 559.2], [0.0, 548.8, 559.2], [556.0, 548.8, 559.2]]
RIGHT_GREEN = [[0.0, 0.0, 559.2], [0.0, 0.0, 0.0], [0.0, 548.8, 0.0], [0.0, 548.8, 559.2]]
LEFT_RED = [[552.8, 0.0, 0.0], [549.6, 0.0, 559.2], [556.0, 548.8, 559.2], [556.0, 548.8, 0.0]]
LIGHT = [[343.0, 548.8, 227.0], [343.0, 548.8, 332.0], [213.0, 548.8, 332.0], [213.0, 548.8, 227.0]]
SHORT_BLOCK = [
    [[130.0, 165.0, 65.0], [82.0, 165.0, 225.0], [240.0, 165.0, 272.0], [290.0, 165.0, 114.0]],
    [[290.0, 0.0, 114.0], [290.0, 165.0, 114.0], [240.0, 165.0, 272.0], [240.0, 0.0, 272.0]],
    [[130.0, 0.0, 65.0], [130.0, 165.0, 65.0], [290.0, 165.0, 114.0], [290.0, 0.0, 114.0]],
    [[82.0, 0.0, 225.0], [82.0, 165.0, 225.0], [130.0, 165.0, 65.0], [130.0, 0.0, 65.0]],
    [[240.0, 0.0, 272.0], [240.0, 165.0, 272.0], [82.0, 165.0, 225.0], [82.0, 0.0, 225.0]],
]
TALL_BLOCK = [
    [[423.0, 330.0, 247.0], [265.0, 330.0, 296.0], [314.0, 330.0, 456.0], [472.0, 330.0, 406.0]],
    [[423.0, 0.0, 247.0], [423.0, 330.0, 247.0], [472.0, 330.0, 406.0], [472.0, 0.0, 406.0]],
    [[472.0, 0.0, 406.0], [472.0, 330.0, 406.0], [314.0, 330.0, 456.0], [314.0, 0.0, 456.0]],
    [[314.0, 0.0, 456.0], [314.0, 330.0, 456.0], [265.0, 330.0, 296.0], [265.0, 0.0, 296.0]],
    [[265.0, 0.0, 296.0], [265.0, 330.0, 296.0], [423.0, 330.0, 247.0], [423.0, 0.0, 247.0]],
]
CAMERA = [278.0, 273.0, -800.0]
# The distance between the box's two farthest corners (metres, rounded up): every occluder a
# surface point can see lies within it.
SCENE_DIAMETER_M = 0.97
FOCAL_MM, FILM_MM = 35.0, 25.0

# Linear Rec.709 albedos commonly derived from the published reflectance spectra, and the
# commonly used emission colour, scaled to a luminance of 5000 nits (hikari's CORNELL_LIGHT_NITS).
WHITE, RED, GREEN = [0.725, 0.71, 0.68], [0.63, 0.065, 0.05], [0.14, 0.45, 0.091]
EMISSION = np.array([17.0, 12.0, 4.0])
LIGHT_NITS = 5000.0


def quad_facing(q, facing):
    """Metres, wound so that (p1 - p0) x (p2 - p0) points along `facing`."""
    p = np.array(q) * 1e-3
    n = np.cross(p[1] - p[0], p[2] - p[0]) + np.cross(p[2] - p[0], p[3] - p[0])
    if np.dot(n, facing) < 0:
        p = p[::-1]
    return p


def write_ply(path, quads):
    verts = np.concatenate(quads)
    with open(path, "w") as f:
        f.write("ply\nformat ascii 1.0\n")
        f.write(f"element vertex {len(verts)}\nproperty float x\nproperty float y\nproperty float z\n")
        f.write(f"element face {2 * len(quads)}\nproperty list uchar int vertex_indices\nend_header\n")
        for v in verts:
            f.write(f"{v[0]:.9g} {v[1]:.9g} {v[2]:.9g}\n")
        for i in range(len(quads)):
            b = 4 * i
            f.write(f"3 {b} {b + 1} {b + 2}\n3 {b} {b + 2} {b + 3}\n")


# AO from Mitsuba's own path tracer (`build_scene(..., ao_sky=True)`): with every surface a
# white Lambertian (albedo 1), no emitter but a uniform sky of radiance 1, and max_depth 2 (the
# surface seen, then one bounce to the sky), a pixel's radiance is (1/pi) times the integral
# of V(w) cos(w) over the hemisphere: cosine-weighted AO with no distance bound. Camera rays
# that miss see the sky, 1, as hikari writes AO 1 on sky pixels; `twosided` turns each face
# to the side it is seen from, as hikari does. The box is closed but for its front, so no
# occluder lies farther from a surface than its diameter (`SCENE_DIAMETER_M`), and for any
# `--ao-distance` at least that long this is the bounded AO too. It runs Mitsuba's
# multithreaded C++ (with MIS) where `render_ao` calls Python for every sample: 65536 spp in
# minutes. At 1024 spp the two agree in the mean (0.3234 both) and in 8 x 8 block means
# (RMS 0.002: the two renders' noise).


def build_scene(mi, size, spp, max_depth, seed=0, ao_sky=False):
    """The Cornell box as a Mitsuba scene dict: `path` integrator with `max_depth` (2: direct
    light only, 3: direct plus one diffuse bounce), box-filtered film of `size` pixels, the
    sampler seeded with `seed`. With `ao_sky`, the scene that turns Mitsuba's own path tracer
    into an AO integrator (the note above)."""
    centre = np.array([0.278, 0.274, 0.280])
    inward = lambda q: centre - np.mean(np.array(q) * 1e-3, axis=0)
    tmp = tempfile.mkdtemp()
    walls = [quad_facing(q, inward(q)) for q in (FLOOR, CEILING, BACK)]
    blocks = []
    for block in (SHORT_BLOCK, TALL_BLOCK):
        c = np.mean(np.array(block).reshape(-1, 3) * 1e-3, axis=0)
        c[1] = 0.0
        for q in block:
            qc = np.mean(np.array(q) * 1e-3, axis=0)
            out = np.array([0, 1.0, 0]) if all(p[1] == q[0][1] for p in q) else qc - np.array([c[0], qc[1], c[2]])
            blocks.append(quad_facing(q, out))
    light = quad_facing([[x, y - 0.5, z] for x, y, z in LIGHT], np.array([0, -1.0, 0]))
    parts = {
        "white": (walls, WHITE),
        "red": ([quad_facing(LEFT_RED, inward(LEFT_RED))], RED),
        "green": ([quad_facing(RIGHT_GREEN, inward(RIGHT_GREEN))], GREEN),
        "blocks": (blocks, WHITE),
    }
    if ao_sky:
        # Every surface a white Lambertian, the light an occluder like any other, and a uniform
        # sky of radiance 1: see the note above `build_scene`. The emitter is left out below.
        parts = {name: (quads, [1.0, 1.0, 1.0]) for name, (quads, _) in parts.items()}
        parts["light"] = ([light], [1.0, 1.0, 1.0])
        max_depth = 2
    scene = {"type": "scene", "integrator": {"type": "path", "max_depth": max_depth}}
    if ao_sky:
        scene["sky"] = {"type": "constant", "radiance": {"type": "rgb", "value": [1.0, 1.0, 1.0]}}
    for name, (quads, albedo) in parts.items():
        path = os.path.join(tmp, name + ".ply")
        write_ply(path, quads)
        scene[name] = {
            "type": "ply",
            "filename": path,
            "face_normals": True,
            "bsdf": {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": albedo}}},
        }
    if not ao_sky:
        lum = float(EMISSION @ np.array([0.2126, 0.7152, 0.0722]))
        path = os.path.join(tmp, "light.ply")
        write_ply(path, [light])
        scene["light"] = {
            "type": "ply",
            "filename": path,
            "face_normals": True,
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0.0, 0.0, 0.0]}},
            "emitter": {"type": "area", "radiance": {"type": "rgb", "value": list(EMISSION * LIGHT_NITS / lum)}},
        }
    cam = np.array(CAMERA) * 1e-3
    fov = np.degrees(2 * np.arctan(0.5 * FILM_MM / FOCAL_MM))
    scene["sensor"] = {
        "type": "perspective",
        "fov": fov,
        "fov_axis": "y",
        "near_clip": 0.01,
        "to_world": mi.ScalarTransform4f().look_at(origin=list(cam), target=list(cam + [0, 0, 1.0]), up=[0, 1.0, 0]),
        "sampler": {"type": "independent", "sample_count": spp, "seed": seed},
        "film": {
            "type": "hdrfilm",
            "width": size,
            "height": size,
            "rfilter": {"type": "box"},
            "pixel_format": "rgb",
        },
    }
    return scene


def render_ao(mi, scene, size, spp, distance, seed=7):
    """Ray-traced ambient occlusion, as Mitsuba 3 has no AO integrator: written here on its
    ray-intersection API (`Sensor.sample_ray`, `Scene.ray_intersect`, `Scene.ray_test`,
    `Interaction.spawn_ray`, `warp.square_to_cosine_hemisphere`), scalar variant.
    Each sample is a camera ray through a uniform point of the pixel (a box filter, as the
    film above); at its first hit, a cosine-distributed direction about the geometric normal
    turned towards the camera; the sample counts 1 when nothing lies within `distance` metres
    along it. Camera rays that hit nothing count 1 (hikari writes AO 1 on sky pixels)."""
    sensor = scene.sensors()[0]
    rng = np.random.default_rng(seed)
    ao = np.zeros((size, size), dtype=np.float64)
    for y in range(size):
        u = rng.random((size, spp, 4))
        for x in range(size):
            acc = 0.0
            for k in range(spp):
                film = mi.Point2f((x + u[x, k, 0]) / size, (y + u[x, k, 1]) / size)
                ray, _ = sensor.sample_ray(0.0, 0.5, film, mi.Point2f(0.5, 0.5))
                si = scene.ray_intersect(ray)
                if not si.is_valid():
                    acc += 1.0
                    continue
                nrm = mi.Vector3f(si.n)
                if float(nrm[0] * ray.d[0] + nrm[1] * ray.d[1] + nrm[2] * ray.d[2]) > 0:
                    nrm = -nrm
                local = mi.warp.square_to_cosine_hemisphere(mi.Point2f(u[x, k, 2], u[x, k, 3]))
                probe = si.spawn_ray(mi.Frame3f(nrm).to_world(local))
                probe.maxt = distance
                acc += 0.0 if scene.ray_test(probe) else 1.0
            ao[y, x] = acc / spp
    return np.repeat(ao.astype(np.float32)[:, :, None], 3, axis=2)


def write_pfm(path, img):
    """RGB PFM, rows from the bottom, written to a temporary file and renamed."""
    os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
    h, w = img.shape[:2]
    tmp_out = path + ".tmp"
    with open(tmp_out, "wb") as f:
        f.write(f"PF\n{w} {h}\n-1.0\n".encode())
        f.write(np.ascontiguousarray(img[::-1]).astype("<f4").tobytes())
    os.replace(tmp_out, path)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--size", type=int, default=64)
    ap.add_argument("--spp", type=int, default=4096)
    ap.add_argument(
        "--max-depth", type=int, default=2, help="path length: 2 direct light only, 3 direct plus one diffuse bounce"
    )
    ap.add_argument(
        "--ao-distance",
        type=float,
        default=None,
        help="render ray-traced AO with this maximum distance in metres instead of radiance",
    )
    ap.add_argument("--seed", type=int, default=0, help="the sampler's seed (two seeds measure the reference's own noise)")
    ap.add_argument("--variant", default="scalar_rgb", help="Mitsuba variant (llvm_ad_rgb fails to compile on some AVX-512 hosts)")
    ap.add_argument("-o", default="crates/hikari-render/tests/fixtures/mitsuba_cornell_direct_64.pfm")
    args = ap.parse_args()

    import mitsuba as mi

    mi.set_variant(args.variant)
    if args.ao_distance is not None and args.ao_distance >= SCENE_DIAMETER_M:
        # Nothing lies farther than the box's diameter from any surface, so this AO is the
        # unbounded one: Mitsuba's own path tracer under a uniform sky (the note above build_scene).
        scene = mi.load_dict(build_scene(mi, args.size, args.spp, 2, args.seed, ao_sky=True))
        img = np.array(mi.render(scene), dtype=np.float32)[:, :, :3]
    elif args.ao_distance is not None:
        scene = mi.load_dict(build_scene(mi, args.size, args.spp, 2, args.seed))
        img = render_ao(mi, scene, args.size, args.spp, args.ao_distance, seed=args.seed)
    else:
        scene = mi.load_dict(build_scene(mi, args.size, args.spp, args.max_depth, args.seed))
        img = np.array(mi.render(scene), dtype=np.float32)[:, :, :3]
    write_pfm(args.o, img)
    print(f"wrote {args.o}: mean {img.mean(axis=(0, 1))}")


if __name__ == "__main__":
    main()
