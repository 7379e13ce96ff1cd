#!/usr/bin/env python3
"""Writes crates/hikari-render/tests/fixtures/bilateral_128x64.bin: a 128x64 log2-luminance
test image and its brute-force bilateral filter by scikit-image's `denoise_bilateral` (a
library no one here wrote), for tests/local_tonemap.rs to hold the bilateral grid against.

The filter runs at the grid's effective sigmas for this size and the default settings
(`local_tonemap::reference::effective_sigmas`; the test checks that they agree):
  spatial: a cell is 128/64 = 2 px; the fill's box (variance 1/12 cell^2), the blur
    (sigma 1 cell) and the lookup's tent (1/6) give sigma_s = 2 * sqrt(1 + 1/4) px;
  range: a slice is 24/64 = 0.375 EV; the fill's tent (1/6 slice^2), the blur (sigma
    1 slice) and the lookup's tent (1/6) give sigma_r = 0.375 * sqrt(1 + 1/3) EV.
Outside the image counts as absent, as in the grid (zero padding of homogeneous values): the
image is shifted to be positive and far from the padding value 0, so the padding's range
weight underflows to 0.

Layout, little-endian: u32 width, u32 height, f32 sigma_s (px), f32 sigma_r (EV), then
width*height f32 of the image (exposed log2 luminance, rows top down), then as many of the
filtered image. Needs numpy and scikit-image (pip install scikit-image).
"""
import math
import pathlib
import struct

import numpy as np
from skimage.restoration import denoise_bilateral

W, H = 128, 64
SIGMA_S = 2.0 * math.sqrt(1.0 + 0.25)
SIGMA_R = 0.375 * math.sqrt(1.0 + 1.0 / 3.0)
SHIFT = 40.0


def image() -> np.ndarray:
    """An interior looking out: a dim room with a smooth falloff, a window 7 EV brighter
    with a soft sky gradient, a lamp's disk, and fine texture everywhere."""
    rng = np.random.default_rng(19)
    y, x = np.mgrid[0:H, 0:W].astype(np.float64)
    room = -5.0 + 1.5 * np.exp(-((x - 30) ** 2 + (y - 40) ** 2) / (2 * 25.0 ** 2))
    window = (x > 70) & (x < 115) & (y > 10) & (y < 45)
    sky = 2.0 - 0.03 * (y - 10) + 0.01 * (x - 70)
    img = np.where(window, sky, room)
    lamp = (x - 25) ** 2 + (y - 20) ** 2 < 16
    img = np.where(lamp, 3.5, img)
    img = img + 0.25 * rng.standard_normal((H, W))
    # Quantised as the renderer's f16 radiance will hold 2^img, so both filter the same image.
    return np.log2(np.float16(np.exp2(img)).astype(np.float64))


def main() -> None:
    img = image()
    out = denoise_bilateral(
        img + SHIFT,
        sigma_color=SIGMA_R,
        sigma_spatial=SIGMA_S,
        mode="constant",
        cval=0.0,
        bins=100000,
    ) - SHIFT
    path = pathlib.Path(__file__).resolve().parent.parent / (
        "crates/hikari-render/tests/fixtures/bilateral_128x64.bin"
    )
    data = struct.pack("<IIff", W, H, SIGMA_S, SIGMA_R)
    data += img.astype("<f4").tobytes() + out.astype("<f4").tobytes()
    tmp = path.with_suffix(".tmp")
    tmp.write_bytes(data)
    tmp.replace(path)
    print(f"{path}: image {img.min():.2f}..{img.max():.2f} EV, "
          f"mean |filtered - image| {np.abs(out - img).mean():.3f} EV")


if __name__ == "__main__":
    main()
