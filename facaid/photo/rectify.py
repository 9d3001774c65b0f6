"""Rectification of a photo: four corners of a facade -> a fronto-parallel image (a homography). The corners are
proposed from the photo's lines by `facaid.photo.corners`."""

from __future__ import annotations

import math

import numpy as np
from PIL import Image

MAX_SIDE = 8192


def check_corners(corners) -> np.ndarray:
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
    p = check_corners(corners)
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


def _inverse(p: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """The homography that maps the rectified image's pixel indices back into the photo's (pixel centres at whole
    coordinates, as OpenCV samples; the corners are in continuous coordinates, a pixel's centre at +0.5)."""
    w, h = size
    inverse = homography([(0, 0), (w, 0), (w, h), (0, h)], p)
    if not np.isfinite(inverse).all():
        raise ValueError("corners do not define a usable homography")
    centre = np.array([[1.0, 0.0, 0.5], [0.0, 1.0, 0.5], [0.0, 0.0, 1.0]])
    return np.linalg.inv(centre) @ inverse @ centre


def _warp(pixels: np.ndarray, p: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """``pixels`` (h, w[, c] uint8) warped so that the quadrilateral ``p`` fills a ``size`` image (black outside the
    photo), in OpenCV: bicubic where the rectified image has more pixels than the quadrilateral (enlarged), bilinear
    where it has fewer (a 16 MP warp: 0.17 s, bicubic 0.32 s, Pillow's bicubic 0.85 s)."""
    import cv2

    w, h = size
    if not (0 < w <= MAX_SIDE and 0 < h <= MAX_SIDE):
        raise ValueError(f"the rectified size must be within 1..{MAX_SIDE} pixels a side, got {w}x{h}")
    interpolation = cv2.INTER_LINEAR if _area(p) >= w * h else cv2.INTER_CUBIC
    return cv2.warpPerspective(pixels, _inverse(p, size), (w, h), flags=interpolation | cv2.WARP_INVERSE_MAP,
                               borderMode=cv2.BORDER_CONSTANT, borderValue=0)


def rectify(image: Image.Image, corners, size: tuple[int, int] | None = None,
            max_pixels: int | None = None) -> Image.Image:
    """Warp the quadrilateral ``corners`` (TL, TR, BR, BL, in image pixels) of ``image`` to an RGB rectangle of
    ``size`` (by default `output_size`, at most ``max_pixels``)."""
    p = check_corners(corners)
    if image.mode not in ("RGB", "L"):
        image = image.convert("RGB")  # (a transparent photo would be premultiplied, a full-size copy, anyway)
    out = Image.fromarray(_warp(np.asarray(image), p, size or output_size(p, max_pixels)))
    return out if out.mode == "RGB" else out.convert("RGB")


REDUCED = {2: "IMREAD_REDUCED_COLOR_2", 4: "IMREAD_REDUCED_COLOR_4", 8: "IMREAD_REDUCED_COLOR_8"}


def _area(p: np.ndarray) -> float:
    x, y = p[:, 0], p[:, 1]
    return abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))) / 2


def rectify_file(fp, corners, max_pixels: int | None = None) -> Image.Image:
    """`rectify` of the image in an open file (an upright photo, as the site stores them), holding one decoded copy
    of its pixels: a JPEG is decoded at the smallest scale (1/2, 1/4, 1/8) that still gives every pixel of the
    rectified image a pixel and a half of the photo's, the others whole, by OpenCV, straight from the file's bytes
    (a 40 MP photo: 120 MB, where Pillow's decode and conversion held two copies)."""
    import cv2

    p = check_corners(corners)  # before anything is decoded
    head = Image.open(fp)
    fmt = head.format
    size = output_size(p, max_pixels)
    factor = 1
    if fmt == "JPEG":
        need = min(1.0, 1.5 * math.sqrt(size[0] * size[1] / max(_area(p), 1.0)))
        factor = next((f for f in (8, 4, 2) if 1 / f >= need), 1)
    fp.seek(0)
    raw = np.frombuffer(fp.read(), dtype=np.uint8)
    flag = getattr(cv2, REDUCED[factor]) if factor > 1 else cv2.IMREAD_COLOR
    pixels = cv2.imdecode(raw, flag | cv2.IMREAD_IGNORE_ORIENTATION)
    del raw
    if pixels is None:  # a format OpenCV does not read: Pillow's way
        fp.seek(0)
        image = Image.open(fp)
        image.load()
        return rectify(image, p, size)
    cv2.cvtColor(pixels, cv2.COLOR_BGR2RGB, dst=pixels)
    return Image.fromarray(_warp(pixels, p / factor, size))  # reduced pixel k covers the photo's [k f, (k + 1) f)


# --- proposing the four corners from the photo ------------------------------------------------------------------
