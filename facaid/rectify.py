"""Rectification of a photo: four corners of a facade -> a fronto-parallel image (a homography)."""

from __future__ import annotations

import math

import numpy as np
from PIL import Image

MAX_SIDE = 8192


def _check_corners(corners) -> np.ndarray:
    try:
        pts = np.asarray(corners, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError("corners must be four [x, y] points") from None
    if pts.shape != (4, 2):
        raise ValueError(f"corners must be four [x, y] points, got shape {list(pts.shape)}")
    if not np.isfinite(pts).all():
        raise ValueError("corners must be finite numbers")
    # a convex quadrilateral in order (top-left, top-right, bottom-right, bottom-left): the cross products of
    # consecutive edges all have the same sign and none is ~0
    edges = np.roll(pts, -1, axis=0) - pts
    cross = edges[:, 0] * np.roll(edges, -1, axis=0)[:, 1] - edges[:, 1] * np.roll(edges, -1, axis=0)[:, 0]
    if not (np.all(cross > 1e-6) or np.all(cross < -1e-6)):
        raise ValueError("corners must form a convex quadrilateral, in order top-left, top-right, "
                         "bottom-right, bottom-left")
    return pts


def output_size(corners, max_pixels: int | None = None) -> tuple[int, int]:
    """Width and height of the rectified image: the mean lengths of opposite edges, shrunk to at most
    `MAX_SIDE` a side and ``max_pixels`` in all."""
    p = _check_corners(corners)
    w = (np.linalg.norm(p[1] - p[0]) + np.linalg.norm(p[2] - p[3])) / 2
    h = (np.linalg.norm(p[3] - p[0]) + np.linalg.norm(p[2] - p[1])) / 2
    scale = min(1.0, MAX_SIDE / max(w, h))
    if max_pixels is not None and w * h * scale * scale > max_pixels:
        scale = math.sqrt(max_pixels / (w * h))
        return max(1, math.floor(w * scale)), max(1, math.floor(h * scale))
    return max(1, round(w * scale)), max(1, round(h * scale))


def homography(src, dst) -> np.ndarray:
    """The 3x3 matrix H with H @ [x, y, 1] ~ [u, v, 1] for four point pairs (x, y) -> (u, v)."""
    a, b = [], []
    for (x, y), (u, v) in zip(np.asarray(src, float), np.asarray(dst, float), strict=True):
        a.append([x, y, 1, 0, 0, 0, -u * x, -u * y])
        a.append([0, 0, 0, x, y, 1, -v * x, -v * y])
        b.extend([u, v])
    h = np.linalg.solve(np.array(a), np.array(b))
    return np.append(h, 1.0).reshape(3, 3)


def rectify(image: Image.Image, corners, size: tuple[int, int] | None = None,
            max_pixels: int | None = None) -> Image.Image:
    """Warp the quadrilateral ``corners`` (TL, TR, BR, BL, in image pixels) of ``image`` to a rectangle of
    ``size`` (by default `output_size`, at most ``max_pixels``)."""
    p = _check_corners(corners)
    w, h = size or output_size(p, max_pixels)
    if not (0 < w <= MAX_SIDE and 0 < h <= MAX_SIDE):
        raise ValueError(f"the rectified size must be within 1..{MAX_SIDE} pixels a side, got {w}x{h}")
    target = [(0, 0), (w, 0), (w, h), (0, h)]
    inverse = homography(target, p)  # PIL maps output pixels back into the source
    coeffs = (inverse / inverse[2, 2]).flatten()[:8]
    if not all(math.isfinite(c) for c in coeffs):
        raise ValueError("corners do not define a usable homography")
    if image.mode not in ("RGB", "L"):
        image = image.convert("RGB")  # (a transparent photo would be premultiplied, a full-size copy, anyway)
    out = image.transform((w, h), Image.Transform.PERSPECTIVE, tuple(coeffs), Image.Resampling.BICUBIC)
    return out if out.mode == "RGB" else out.convert("RGB")


def rectify_file(fp, corners, max_pixels: int | None = None) -> Image.Image:
    """`rectify` of the image in an open file, holding one full-size copy of its pixels at a time: a photo with
    transparency or a palette is converted to RGB and the decoded original let go before the warp."""
    image = Image.open(fp)
    _check_corners(corners)  # before anything is decoded
    image.load()
    if image.mode not in ("RGB", "L"):
        image = image.convert("RGB")
    return rectify(image, corners, max_pixels=max_pixels)
