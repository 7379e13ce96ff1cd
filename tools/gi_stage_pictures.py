#!/usr/bin/env python3
"""Pictures of each stage of ray-traced GI for docs/ray-traced-gi.md, from `hikari render`'s
`--dump` EXRs (read with Mitsuba 3's Bitmap, which reads OpenEXR).

    hikari render --scene cornell --no-sun --no-sky --width 128 --height 128 \\
        --set ray_traced_gi.enabled=true --frames 16 -o /tmp/gi/final.png --dump-dir /tmp/gi \\
        --dump ray_traced_gi.raw_y --dump ray_traced_gi.raw_cocg_ao --dump ray_traced_gi.gi_y \\
        --dump ray_traced_gi.gi_cocg --dump gi_denoiser.pass1_y --dump gi_denoiser.pass1_cocg \\
        --dump gi_denoiser.pass2_y --dump gi_denoiser.pass2_cocg --dump ray_traced_gi.ao \\
        --dump gi_denoiser.ao
    python3 tools/gi_stage_pictures.py /tmp/gi docs/images

GI stages are shown as colour: the SH's c0 / C0 (the mean luminance over the hemisphere's
samples) with the chroma, YCoCg to RGB as `hikari::sh` decodes it, under one fixed exposure
(the accumulated image's median at 0.18) and Reinhard's x / (1 + x), sRGB-encoded. AO is shown
as is (0 black, 1 white). Output: 8-bit PNGs, each written to a temporary name and renamed.
"""

import os
import sys

import numpy as np

C0 = 0.28209479177387814


def load(d, name):
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    return np.array(mi.Bitmap(os.path.join(d, name + ".exr")), dtype=np.float64)


def colour(y, cocg):
    lum, co, cg = y[..., 0] / C0, cocg[..., 0], cocg[..., 1]
    t = lum - cg * 0.5
    g = cg + t
    b = t - co * 0.5
    return np.maximum(np.stack([b + co, g, b], axis=-1), 0.0)


def srgb(v):
    v = np.clip(v, 0.0, 1.0)
    return np.where(v <= 0.0031308, 12.92 * v, 1.055 * v ** (1 / 2.4) - 0.055)


def save(path, rgb):
    from PIL import Image

    img = Image.fromarray((255 * rgb + 0.5).astype(np.uint8), "RGB")
    tmp = path + ".tmp.png"
    img.save(tmp)
    os.replace(tmp, path)


def main():
    src, out = sys.argv[1], sys.argv[2]
    os.makedirs(out, exist_ok=True)
    accumulated = colour(load(src, "ray_traced_gi.gi_y"), load(src, "ray_traced_gi.gi_cocg"))
    lum = accumulated @ np.array([0.2126, 0.7152, 0.0722])
    k = 0.18 / max(np.median(lum[lum > 0]), 1e-6)
    raw_cocg_ao = load(src, "ray_traced_gi.raw_cocg_ao")
    stages = {
        "rtgi_1_raw": colour(load(src, "ray_traced_gi.raw_y"), raw_cocg_ao[..., :2]),
        "rtgi_2_accumulated": accumulated,
        "rtgi_3_denoiser_pass1": colour(load(src, "gi_denoiser.pass1_y"), load(src, "gi_denoiser.pass1_cocg")),
        "rtgi_4_denoiser_pass2": colour(load(src, "gi_denoiser.pass2_y"), load(src, "gi_denoiser.pass2_cocg")),
    }
    for name, rgb in stages.items():
        save(os.path.join(out, name + ".png"), srgb(k * rgb / (1 + k * rgb)))
    for name, dump in (("rtgi_5_ao_accumulated", "ray_traced_gi.ao"), ("rtgi_6_ao_denoised", "gi_denoiser.ao")):
        ao = load(src, dump)[..., 0]
        save(os.path.join(out, name + ".png"), np.repeat(np.clip(ao, 0, 1)[..., None], 3, axis=-1))
    print(f"wrote {len(stages) + 2} pictures to {out} (exposure {k:.3e})")


if __name__ == "__main__":
    main()
