"""Pictures of procedures and segmentations for the site (PNG bytes), drawn at the size they are sent at: label
maps, overlays on the photo, two versions' difference. A procedure's own pictures are kept in storage once drawn
(`picture_store`).

A request's cost is bounded by what is drawn, not by what a procedure declares: the rectangles are scaled to the
picture (at most `MAX_RENDER_SIDE` a side) and painted there, so a 16,384 px facade costs what a 2,048 px one
does. Photos are read at the picture's size (`facaid.photo.files.read_photo`).
`bench/bench_render_memory.py` measures the peak memory of each picture request."""

from __future__ import annotations

import io

import numpy as np
from PIL import Image

from facaid.formats.render import colorize
from facaid.grammar import Procedure as Tree
from facaid.labels import PRIORITY
from facaid.metrics import scaled_procedure_map
from facaid.photo.files import read_photo
from facaid.segmentation import Segmentation as SegmentationData

MAX_RENDER_SIDE = 2048
COMPARE_SIDE = 1024  # the pictures of two versions compared: the page shows them side by side
DIFFERENT = (255, 0, 255)  # magenta, in no class's colour: the pixels whose label differs
_PRIORITY = np.asarray(PRIORITY)


def _png(image: Image.Image) -> bytes:
    out = io.BytesIO()
    image.save(out, "PNG")
    return out.getvalue()


def fitted_size(width: int, height: int, max_side: int) -> tuple[int, int]:
    """The size of a ``width`` x ``height`` picture shrunk (never enlarged) to at most ``max_side`` a side."""
    scale = min(1.0, max_side / max(width, height))
    return max(1, round(width * scale)), max(1, round(height * scale))


def label_map(seg: SegmentationData, max_side: int = MAX_RENDER_SIDE) -> np.ndarray:
    """The segmentation's (h, w) label map at most ``max_side`` a side, painted at that size: each output pixel
    takes the label at its centre in the full-size map (what nearest-neighbour shrinking gives)."""
    w, h = fitted_size(seg.width, seg.height, max_side)
    out = np.zeros((h, w), dtype=np.uint8)
    arr = seg.to_array()
    if len(arr) == 0:
        return out
    arr = arr[np.argsort(_PRIORITY[arr[:, 0]], kind="stable")]  # the paint order
    # output pixel i covers the source pixel at (i + 0.5) / scale: [x0, x1) covers i for ceil(x0 * s - 0.5) <= i
    sx, sy = w / seg.width, h / seg.height
    x0 = np.clip(np.ceil(arr[:, 1] * sx - 0.5), 0, w).astype(np.int64)
    x1 = np.clip(np.ceil(arr[:, 3] * sx - 0.5), 0, w).astype(np.int64)
    y0 = np.clip(np.ceil(arr[:, 2] * sy - 0.5), 0, h).astype(np.int64)
    y1 = np.clip(np.ceil(arr[:, 4] * sy - 0.5), 0, h).astype(np.int64)
    keep = (x0 < x1) & (y0 < y1)
    for lab, a, b, c, d in zip(arr[keep, 0].tolist(), y0[keep].tolist(), y1[keep].tolist(), x0[keep].tolist(),
                               x1[keep].tolist(), strict=True):
        out[a:b, c:d] = lab
    return out


def label_map_png(seg: SegmentationData, max_side: int = MAX_RENDER_SIDE) -> bytes:
    return _png(colorize(label_map(seg, max_side)))


def overlay_png(seg: SegmentationData, photo, alpha: float = 0.5, max_side: int = MAX_RENDER_SIDE) -> bytes:
    """The label map over the photo (a path or an open file; stretched to the segmentation's size), ``alpha``
    opaque. The photo is read at the picture's size (`facaid.photo.files.read_photo`: a JPEG at its nearest larger
    DCT scale, the rest shrunk strip by strip in RGB), so no full-size RGB copy is made."""
    if not 0.0 <= alpha <= 1.0:
        raise ValueError(f"alpha must be between 0 and 1, got {alpha!r}")
    labels = label_map(seg, max_side)
    size = (labels.shape[1], labels.shape[0])
    return _png(Image.blend(read_photo(photo, size, "RGB"), colorize(labels), alpha))


def common_maps(a: Tree, b: Tree, max_side: int = COMPARE_SIDE) -> tuple[np.ndarray, np.ndarray]:
    """The two executed procedures' label maps on one canvas (the larger width and height, shrunk to at most
    ``max_side`` a side), both from its top-left corner in the same pixels: where one tree does not reach is
    background, so a resized version differs by the area it gained or lost."""
    width, height = max(a.width, b.width), max(a.height, b.height)
    scale = min(1.0, max_side / max(width, height))
    w, h = max(1, round(width * scale)), max(1, round(height * scale))
    out = []
    for tree in (a, b):
        canvas = np.zeros((h, w), dtype=np.uint8)
        painted = scaled_procedure_map(tree, scale)[:h, :w]
        canvas[: painted.shape[0], : painted.shape[1]] = painted
        out.append(canvas)
    return out[0], out[1]


def difference_png(a: Tree, b: Tree, max_side: int = COMPARE_SIDE) -> tuple[bytes, int, int]:
    """``b``'s label map, paled, with the pixels whose label differs from ``a``'s in `DIFFERENT`; and the count of
    those pixels and of all the picture's."""
    first, second = common_maps(a, b, max_side)
    differ = first != second
    picture = (0.35 * np.asarray(colorize(second), dtype=np.float32) + 0.65 * 255).astype(np.uint8)
    picture[differ] = DIFFERENT
    return _png(Image.fromarray(picture, "RGB")), int(differ.sum()), int(differ.size)
