"""Augmentation: segmentations made noisy as people annotate, for training (`jitter`: element edges moved) and
for evaluation (`perturb`: jittered until a given share of the pixels changes label)."""

from __future__ import annotations

import numpy as np

from facaid.labels import FACADE
from facaid.metrics import scaled_label_map
from facaid.segmentation import Rect, Segmentation, flatten

_SCALE = 0.25


def _jitter(seg: Segmentation, sigma: float, rng: np.random.Generator) -> Segmentation:
    side = max(seg.width, seg.height)
    rects = []
    noise = rng.normal(0.0, 1.0, size=(len(seg.rects), 4))
    for r, n in zip(seg.rects, noise, strict=True):
        if r.label == FACADE:
            rects.append(r)
            continue
        x0 = min(max(0, round(r.x0 + n[0] * sigma * side)), seg.width - 1)
        y0 = min(max(0, round(r.y0 + n[1] * sigma * side)), seg.height - 1)
        x1 = min(max(x0 + 1, round(r.x1 + n[2] * sigma * side)), seg.width)
        y1 = min(max(y0 + 1, round(r.y1 + n[3] * sigma * side)), seg.height)
        rects.append(Rect(r.label, x0, y0, x1, y1))
    return Segmentation(seg.width, seg.height, tuple(rects))


def jitter(seg: Segmentation, sigma: float, rng: np.random.Generator) -> Segmentation:
    """The flattened segmentation with its element edges moved by N(0, sigma * long side) each."""
    return flatten(_jitter(flatten(seg, wall="footprint"), sigma, rng), wall="footprint")


def changed_fraction(a: Segmentation, b: Segmentation) -> float:
    return float((scaled_label_map(a, _SCALE) != scaled_label_map(b, _SCALE)).mean())


def perturb(seg: Segmentation, level: float, seed: int = 0, iterations: int = 12) -> tuple[Segmentation, float]:
    """A copy of ``seg`` whose element edges are moved at random so that about ``level`` (0 to 1) of the
    pixels change label; returns (noisy flattened segmentation, the share actually changed)."""
    if not 0.0 <= level <= 1.0:
        raise ValueError(f"noise level must be between 0 and 1, got {level}")
    base = flatten(seg, wall="footprint")
    if level == 0.0:
        return base, 0.0
    lo, hi = 0.0, 0.1
    best = (base, 0.0)
    for _ in range(iterations):  # bisection on the jitter's standard deviation (fraction of the long side)
        sigma = (lo + hi) / 2
        noisy = flatten(_jitter(base, sigma, np.random.default_rng(seed)), wall="footprint")
        frac = changed_fraction(base, noisy)
        if abs(frac - level) < abs(best[1] - level):
            best = (noisy, frac)
        if frac < level:
            lo = sigma
        else:
            hi = sigma
    return best
