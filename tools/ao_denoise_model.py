#!/usr/bin/env python3
"""How well can any spatial filter do with 16 one-ray frames of AO on the Cornell box?

A model, not hikari: the truth is Mitsuba's 50 m AO (the validation fixture); each frame draws
one Bernoulli ray a pixel with that probability of being open; 16 frames are averaged (what
hikari's accumulation holds at frame 16); then a Gaussian blur of each width, or a local
linear regression (a plane fitted in each window), is applied to the whole image and the RMS
error is measured on a patch of the back wall (rows 20 to 43, columns 30 to 99, no edges
inside). It also prints the FLIP that Gaussian noise and blur cost on the reference itself
(needs `pip install flip-evaluator`). docs/ray-traced-gi.md, Validation, quotes the output.

    python3 tools/ao_denoise_model.py
"""
import pathlib

import numpy as np
from scipy.ndimage import gaussian_filter, uniform_filter

FIXTURE = (pathlib.Path(__file__).resolve().parent.parent
           / "crates/hikari-render/tests/fixtures/mitsuba_cornell_ao50_128.pfm")
PATCH = (slice(20, 44), slice(30, 100))
FRAMES = 16
SEEDS = 4


def read_pfm(path):
    with open(path, "rb") as f:
        f.readline()
        w, h = map(int, f.readline().split())
        f.readline()
        return np.frombuffer(f.read(), dtype="<f4").reshape(h, w, 3)[::-1, :, 0].copy()


def accumulated(truth, seed):
    rng = np.random.default_rng(seed)
    acc = np.zeros_like(truth)
    for t in range(1, FRAMES + 1):
        acc += ((rng.random(truth.shape) < truth).astype(np.float64) - acc) / t
    return acc


def regression(img, window):
    """A plane a + b x + c y fitted by least squares in each window, evaluated at its centre."""
    h, w = img.shape
    y, x = np.mgrid[0:h, 0:w].astype(np.float64)
    m = lambda v: uniform_filter(v, window, mode="nearest")
    mx, my, ma = m(x), m(y), m(img)
    cxx, cyy, cxy = m(x * x) - mx * mx, m(y * y) - my * my, m(x * y) - mx * my
    cxa, cya = m(x * img) - mx * ma, m(y * img) - my * ma
    det = cxx * cyy - cxy ** 2
    b = (cxa * cyy - cya * cxy) / det
    c = (cya * cxx - cxa * cxy) / det
    return ma + b * (x - mx) + c * (y - my)


def rms(filtered, truth):
    e = (filtered - truth)[PATCH]
    return float(np.sqrt((e ** 2).mean()))


def main():
    truth = read_pfm(FIXTURE).astype(np.float64)
    samples = [accumulated(truth, s) for s in range(SEEDS)]
    print(f"patch AO from {truth[PATCH].min():.3f} to {truth[PATCH].max():.3f}")
    print(f"undenoised, {FRAMES} frames: RMS {np.mean([rms(a, truth) for a in samples]):.4f}")
    for sigma in [0.5, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0]:
        e = np.mean([rms(gaussian_filter(a, sigma), truth) for a in samples])
        bias = rms(gaussian_filter(truth, sigma), truth)
        print(f"gaussian sigma {sigma:3.1f} px: RMS {e:.4f} (of which bias {bias:.4f})")
    for window in [3, 5, 7, 9, 13, 17]:
        e = np.mean([rms(regression(a, window), truth) for a in samples])
        bias = rms(regression(truth, window), truth)
        print(f"linear regression {window:2d} px: RMS {e:.4f} (of which bias {bias:.4f})")
    try:
        import flip_evaluator as flip
    except ImportError:
        return
    grey = lambda v: np.repeat((np.round(np.clip(v, 0, 1) * 255) / 255)[..., None], 3, 2)
    ref = grey(truth).astype(np.float32)
    rng = np.random.default_rng(1)
    for s in [0.01, 0.02, 0.03, 0.05]:
        noisy = grey(truth + rng.normal(0, s, truth.shape)).astype(np.float32)
        print(f"FLIP of the reference with noise sigma {s}: {flip.evaluate(ref, noisy, 'LDR')[1]:.4f}")
    for b in [0.5, 1.0, 2.0]:
        blurred = grey(gaussian_filter(truth, b)).astype(np.float32)
        print(f"FLIP of the reference blurred by {b} px: {flip.evaluate(ref, blurred, 'LDR')[1]:.4f}")


if __name__ == "__main__":
    main()
