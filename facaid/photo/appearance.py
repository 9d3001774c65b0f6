"""Appearance in a photo: how much a place looks like the examples drawn of its class.

Each box is cut out of the photo's grey levels, resized to `PATCH` x `PATCH` and normalized (zero mean, unit
length), so that its dot product with another is their normalized cross-correlation (NCC): 1 for the same
picture up to brightness and contrast, about 0 for unrelated ones. A box whose patch is flat (a flat colour, as a
label map rendered without texture is) has no appearance: its similarity is NaN, which callers read as "the
photo says nothing here".
"""

from __future__ import annotations

from typing import Any

import numpy as np
from PIL import Image

from facaid.photo.files import read_photo

PATCH = 12  # side of the patches compared: a window's panes and frame at any size, little of the noise
FLAT = 0.5  # grey levels: a patch whose spread is below this (a flat colour, a render) has no appearance


KEPT_SCALES = 2  # scaled copies of the levels a call keeps (the search's and the sharpening's: ≤ 1 + 16 MB)


class Levels:
    """A photo's grey levels with what the searches and checks of one call share: the picture PIL resizes patches
    from (a copy of the levels, made once: it was made per search, most of a call's time with many types). The
    levels may be of a smaller ``scale`` (x, y) than the segmentation whose boxes are asked about (`levels`)."""

    def __init__(self, grey_levels: np.ndarray, scale: tuple[float, float] = (1.0, 1.0)):
        self.array = grey_levels
        self.shape = grey_levels.shape
        self.scale = np.array([*scale, *scale], dtype=float)  # x, y, x, y: boxes in pixels of the segmentation
        self._image: Image.Image | None = None
        self._scaled: dict[float, np.ndarray] = {}

    @property
    def image(self) -> Image.Image:
        if self._image is None:
            self._image = Image.fromarray(self.array, "F")
        return self._image

    def scaled(self, f: float) -> np.ndarray:
        """The levels scaled by ``f`` (≤ 1; OpenCV's area average; read only). The last `KEPT_SCALES` are kept: the
        searches of most types ask for the same capped scales in turn, while a copy per scale kept for the call
        would hold up to 16 MB for each type searched."""
        import cv2

        if f >= 1:
            return self.array
        if f not in self._scaled:
            self._scaled[f] = cv2.resize(self.array, None, fx=f, fy=f, interpolation=cv2.INTER_AREA)
            while len(self._scaled) > KEPT_SCALES:
                self._scaled.pop(next(iter(self._scaled)))
        return self._scaled[f]


def _levels(grey_levels: np.ndarray | Levels) -> Levels:
    return grey_levels if isinstance(grey_levels, Levels) else Levels(grey_levels)


WORK_PIXELS = 8_000_000  # a larger photo is read at a smaller scale (`levels`): its levels and their copy ≤ 64 MB


def levels(photo: Any, width: int, height: int, max_pixels: int = WORK_PIXELS) -> Levels:
    """The grey levels of a photo (a PIL image, a path, a file, an (H, W) / (H, W, C) array, or `Levels` already,
    returned as they are) for a segmentation of ``width`` x ``height``, at most ``max_pixels`` of them: a larger one
    is read at a smaller scale, and the answers about boxes are still in the segmentation's pixels. A path or file
    is opened here and let go once it is grey (a JPEG decoded at a reduced scale already, a WebP scaled as it is
    decoded), so the call holds one full-size decoded copy at most for a moment."""
    if isinstance(photo, Levels):
        return photo
    s = min(1.0, float(np.sqrt(max_pixels / max(1, width * height))))
    tw, th = max(1, round(width * s)), max(1, round(height * s))
    if isinstance(photo, np.ndarray):
        array = photo.astype(np.float32)
        if array.ndim == 3:
            array = array[..., :3].mean(axis=2)
        if array.ndim != 2:
            raise ValueError(f"photo must be an (H, W) or (H, W, C) array, got shape {list(photo.shape)}")
        image = Image.fromarray(array, "F")
    elif isinstance(photo, Image.Image):
        image = photo.convert("L")
    else:  # upright as a viewer shows it, read at a reduced size (`read_photo`): one full-size decode at most
        image = read_photo(photo, (tw, th), "L")
    if image.size != (tw, th):
        image = image.resize((tw, th), Image.Resampling.BILINEAR)
    return Levels(np.asarray(image, dtype=np.float32), (tw / width, th / height))


def patches(grey_levels: np.ndarray | Levels, boxes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(normalized patches (n, PATCH * PATCH), flat (n,) bool) of the boxes ((n, 4) x0, y0, x1, y1 in pixels)."""
    levels = _levels(grey_levels)
    h, w = levels.shape
    image = levels.image
    out = np.zeros((len(boxes), PATCH * PATCH), dtype=np.float32)
    drawn = np.zeros(len(boxes), dtype=bool)
    for i, (x0, y0, x1, y1) in enumerate(np.asarray(boxes, dtype=float).tolist()):
        x0, y0, x1, y1 = max(0, int(x0)), max(0, int(y0)), min(w, int(round(x1))), min(h, int(round(y1)))
        if x1 - x0 < 1 or y1 - y0 < 1:
            continue
        out[i] = np.asarray(image.resize((PATCH, PATCH), Image.Resampling.BILINEAR, box=(x0, y0, x1, y1)),
                            dtype=np.float32).ravel()
        drawn[i] = True
    out -= out.mean(axis=1, keepdims=True)  # normalized all at once (one patch at a time took a third of the time)
    spread = np.sqrt((out**2).mean(axis=1))
    flat = ~drawn | (spread < FLAT)
    out[flat] = 0.0
    out[~flat] /= (spread[~flat] * np.float32(np.sqrt(PATCH * PATCH)))[:, None]
    return out, flat


def similarity(grey_levels: np.ndarray | Levels, boxes: np.ndarray, examples: np.ndarray) -> np.ndarray:
    """Each box's best NCC against the example boxes ((m, 4)), in [-1, 1]; NaN where the box or every example
    is flat, or there is no example. Boxes in the segmentation's pixels, whatever the levels' scale."""
    levels = _levels(grey_levels)
    return _similarity(levels, np.asarray(boxes, dtype=float).reshape(-1, 4) * levels.scale,
                       np.asarray(examples, dtype=float).reshape(-1, 4) * levels.scale)


def _similarity(grey_levels: Levels, boxes: np.ndarray, examples: np.ndarray) -> np.ndarray:
    sims = np.full(len(boxes), np.nan)
    theirs = _examples(grey_levels, examples)
    if not len(boxes) or not len(theirs):
        return sims
    mine, mine_flat = patches(grey_levels, boxes)
    best = (mine @ theirs.T).max(axis=1)
    sims[~mine_flat] = best[~mine_flat]
    return sims


def _examples(grey_levels: np.ndarray | Levels, examples: np.ndarray) -> np.ndarray:
    """The normalized patches of the examples that are not flat."""
    if not len(examples):
        return np.zeros((0, PATCH * PATCH), dtype=np.float32)
    theirs, flat = patches(grey_levels, examples)
    return theirs[~flat]


SHIFTS = (-0.2, -0.1, 0.0, 0.1, 0.2)  # shares of a box's width (height) that `refine` moves it by


def refine(grey_levels: np.ndarray | Levels, boxes: np.ndarray, examples: np.ndarray
           ) -> tuple[np.ndarray, np.ndarray]:
    """(boxes moved to where they look most like the examples, their NCC): see `_refine`; boxes in the
    segmentation's pixels, whatever the levels' scale."""
    levels = _levels(grey_levels)
    boxes = np.asarray(boxes, dtype=float).reshape(-1, 4)
    if (levels.scale == 1).all():
        return _refine(levels, boxes, np.asarray(examples, dtype=float).reshape(-1, 4))
    moved, sims = _refine(levels, boxes * levels.scale,
                          np.asarray(examples, dtype=float).reshape(-1, 4) * levels.scale)
    shift = np.round(moved[:, :2] / levels.scale[:2] - boxes[:, :2])  # each box moved, its size kept
    return np.where(~np.isnan(sims)[:, None], boxes + np.concatenate([shift, shift], axis=1), boxes), sims


def _refine(grey_levels: Levels, boxes: np.ndarray, examples: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(boxes moved to where they look most like the examples, their NCC): each box is tried at `SHIFTS` of its
    size along x and y (25 places) and kept where its best NCC against the examples is highest; NaN and the box
    unmoved where the photo says nothing."""
    boxes = np.asarray(boxes, dtype=float).reshape(-1, 4)
    sims = np.full(len(boxes), np.nan)
    theirs = _examples(grey_levels, examples)
    if not len(boxes) or not len(theirs):
        return boxes, sims
    h, w = grey_levels.shape
    size = boxes[:, 2:] - boxes[:, :2]  # (n, 2)
    steps = np.array([(sx, sy) for sy in SHIFTS for sx in SHIFTS])  # (25, 2)
    offsets = steps[None, :, :] * size[:, None, :]  # (n, 25, 2)
    lo = np.clip(boxes[:, None, :2] + offsets, 0, None)
    lo = np.minimum(lo, np.array([w, h]) - size[:, None, :])  # moved boxes stay whole inside the image
    tried = np.concatenate([lo, lo + size[:, None, :]], axis=2).reshape(-1, 4)  # (n * 25, 4)
    mine, flat = patches(grey_levels, np.round(tried))
    best = np.where(flat, -np.inf, (mine @ theirs.T).max(axis=1)).reshape(len(boxes), len(steps))
    pick = best.argmax(axis=1)
    found = np.isfinite(best[np.arange(len(boxes)), pick])
    moved = tried.reshape(len(boxes), len(steps), 4)[np.arange(len(boxes)), pick]
    boxes = np.where(found[:, None], np.round(moved), boxes)
    sims[found] = best[np.arange(len(boxes)), pick][found]
    return boxes, sims


SEARCH_SIDE = 16  # pixels: the photo is searched scaled so that the examples' smaller side is about this long
SEARCH_TEMPLATES = 4  # examples matched at most per search (the first drawn)
SEARCH_PIXELS = 250_000  # the searched copy has at most this many pixels (a big photo is scaled down to it) ...
SEARCH_SMALLEST = 4  # ... and elements whose smaller side is shorter than this in it are not searched for
SHARPEN = 4  # the places found are put right on a copy this many times finer than the one searched (or the photo)
CONTEXT = 0.25  # share of its size around each example that is matched with it (a window in its wall)


def search(grey_levels: np.ndarray | Levels, examples: np.ndarray, size: tuple[float, float], threshold: float,
           limit: int = 200) -> tuple[np.ndarray, np.ndarray]:
    """(boxes of ``size``, their NCC) where the photo looks like the examples: see `_search`; boxes and size in the
    segmentation's pixels, whatever the levels' scale."""
    levels = _levels(grey_levels)
    if (levels.scale == 1).all():
        return _search(levels, np.asarray(examples, dtype=float).reshape(-1, 4), size, threshold, limit)
    sx, sy = levels.scale[:2]
    boxes, sims = _search(levels, np.asarray(examples, dtype=float).reshape(-1, 4) * levels.scale,
                          (size[0] * sx, size[1] * sy), threshold, limit)
    if len(boxes):  # the found places at the size asked for, around their middles
        mx, my = (boxes[:, 0] + boxes[:, 2]) / (2 * sx), (boxes[:, 1] + boxes[:, 3]) / (2 * sy)
        boxes = np.stack([mx - size[0] / 2, my - size[1] / 2, mx + size[0] / 2, my + size[1] / 2], axis=1)
    return boxes, sims


def _search(levels: Levels, examples: np.ndarray, size: tuple[float, float], threshold: float,
            limit: int = 200) -> tuple[np.ndarray, np.ndarray]:
    """(boxes (n, 4) of ``size`` = (width, height), their NCC) where the photo looks like the examples ((m, 4)
    boxes) at ``threshold`` or more, anywhere in it. Each example with `CONTEXT` of its size around it (what is
    beside a window tells it from a pane of a shop's glass), scaled to ``size``, is slid over the photo (OpenCV's
    normalized cross-correlation, on a copy scaled so that the size's smaller side is `SEARCH_SIDE` pixels, or
    less to keep the copy within `SEARCH_PIXELS`; a size whose smaller side is then under `SEARCH_SMALLEST` is not
    searched for); the peaks of the best response, each the best within an element's size, are kept, the highest
    first, at most ``limit``. Flat places and flat examples have no say; none found: empty arrays."""
    import cv2

    none = np.zeros((0, 4)), np.zeros(0)
    w, h = float(size[0]), float(size[1])
    if not len(examples) or w < 2 or h < 2:
        return none
    f = min(1.0, SEARCH_SIDE / min(w, h), float(np.sqrt(SEARCH_PIXELS / levels.array.size)))
    if min(w, h) * f < SEARCH_SMALLEST:
        return none
    small = levels.scaled(f)
    mx, my = CONTEXT * w, CONTEXT * h
    tw, th = max(3, round((w + 2 * mx) * f)), max(3, round((h + 2 * my) * f))
    if tw >= small.shape[1] or th >= small.shape[0]:
        return none
    image = levels.image
    gh, gw = levels.shape
    f2 = min(1.0, SHARPEN * f)  # the scale the places found are then put right at
    tw2, th2 = max(3, round((w + 2 * mx) * f2)), max(3, round((h + 2 * my) * f2))
    response, fine = None, []
    for x0, y0, x1, y1 in np.asarray(examples, dtype=float)[:SEARCH_TEMPLATES].tolist():
        cx, cy = (x0 + x1) / 2, (y0 + y1) / 2  # the example's middle, with the searched size and context around
        box = (cx - w / 2 - mx, cy - h / 2 - my, cx + w / 2 + mx, cy + h / 2 + my)
        if box[0] < 0 or box[1] < 0 or box[2] > gw or box[3] > gh:
            continue  # its context is cut by the image's edge
        template = np.asarray(image.resize((tw, th), Image.Resampling.BILINEAR, box=box), dtype=np.float32)
        if template.std() < FLAT:
            continue
        r = cv2.matchTemplate(small, template, cv2.TM_CCOEFF_NORMED)
        response = r if response is None else np.maximum(response, r)
        if not fine:  # the first example's, for putting the places found right (one template: 4x cheaper, as good)
            fine.append(np.asarray(image.resize((tw2, th2), Image.Resampling.BILINEAR, box=box), dtype=np.float32))
    if response is None:
        return none
    rh, rw = response.shape
    mean = cv2.blur(small, (tw, th), anchor=(0, 0))[:rh, :rw]
    square = cv2.blur(small * small, (tw, th), anchor=(0, 0))[:rh, :rw]
    flat = np.sqrt(np.maximum(square - mean * mean, 0)) < FLAT  # places of the photo with no appearance
    response = np.where(flat | ~np.isfinite(response), -1.0, response)
    ew, eh = max(1, round(w * f)), max(1, round(h * f))  # an element's size in the searched copy
    peak = cv2.dilate(response, np.ones((2 * eh - 1, 2 * ew - 1), np.uint8))  # no two kept places overlap
    ys, xs = np.nonzero((response >= peak) & (response >= threshold))
    if not len(xs):
        return none
    sims = response[ys, xs]
    order = np.argsort(-sims, kind="stable")[:limit]
    x, y = xs[order] / f, ys[order] / f  # the top-left corners of the places with their context, in pixels
    if f2 > f:
        x, y = _sharpen(levels, fine, f2, x, y, slack=1 / f)
    x, y = x + mx, y + my
    return np.stack([x, y, x + w, y + h], axis=1), sims[order].astype(float)


def _sharpen(levels: Levels, templates: list[np.ndarray], f: float, x: np.ndarray, y: np.ndarray,
             slack: float) -> tuple[np.ndarray, np.ndarray]:
    """The places (top-left corners ``x``, ``y`` in pixels) moved, each within ``slack`` pixels, to where the
    ``templates`` (at scale ``f``) match best on a copy of the photo at that scale."""
    import cv2

    copy = levels.scaled(f)
    ch, cw = copy.shape
    th, tw = templates[0].shape
    r = int(np.ceil(slack * f)) + 1
    x, y = x.copy(), y.copy()
    for i in range(len(x)):
        ax, ay = int(round(x[i] * f)) - r, int(round(y[i] * f)) - r
        lo_x, lo_y = max(0, ax), max(0, ay)
        region = copy[lo_y : min(ch, ay + th + 2 * r), lo_x : min(cw, ax + tw + 2 * r)]
        if region.shape[0] < th or region.shape[1] < tw:
            continue  # at the image's edge: left where it was found
        best = np.max([cv2.matchTemplate(region, t, cv2.TM_CCOEFF_NORMED) for t in templates], axis=0)
        if not np.isfinite(best).any():
            continue
        dy, dx = np.unravel_index(int(np.nanargmax(np.where(np.isfinite(best), best, -2))), best.shape)
        x[i], y[i] = (lo_x + dx) / f, (lo_y + dy) / f
    return x, y
