"""Copies of a drawn type in a photo: where its examples repeat along the rows and columns they stand in.

A facade repeats its windows on a lattice (Müller et al. 2007; Musialski et al., "Tiling of ortho-rectified
facade images"), and a real photo is read best along it:

1. The photo is **contrast-normalised** (each pixel less its neighbourhood's mean, over its spread, the
   neighbourhood about the type's size): a lighting gradient, a shadow or a dark storey no longer decides what
   looks alike, the panes and frames do.
2. Each example with `CONTEXT` of its size around it is slid over the normalised photo (normalised
   cross-correlation, on a copy scaled so that the type's smaller side is `SIDE` pixels).
3. Along an example's own **row** the response peaks where the columns of its copies stand, along its own
   **column** where the rows stand (`AXIS`): the photo's self-similarity along each axis.
4. Every crossing of a row and a column is a **cell**; the best response near it (a tenth of the type's size each
   way) is its score, and a cell scoring `CELL` or more holds a copy, at the type's size.

On every 9th CMP dev facade (21 photos, one window drawn, `experiments/2026-12-06-copies`) this finds 40 % of the
other windows at IoU 0.7 with a precision of 0.73, where sliding the drawn window over the raw photo anywhere at
NCC 0.93 found 4 %; 73 % of the other windows can be hit at all by a box of the drawn one's size.
"""

from __future__ import annotations

import numpy as np

from facaid.photo.appearance import FLAT, Levels

SIDE = 24  # pixels: the photo is searched scaled so that the type's smaller side is about this long
CONTEXT = 0.25  # share of its size around each example that is matched with it (a window in its wall)
AXIS = 0.45  # response along an example's row (column) at which a column (row) of copies stands
CELL = 0.35  # response at a crossing of a row and a column at which a copy is there
SPACING = 0.7  # two rows (columns) of copies are at least this share of the type's height (width) apart
WALL = 1.0  # how much looking like the wall beside the examples takes off a cell's score
SCALES = ((1.0, 1.0),)  # (width, height) shares of the type's size a cell's copy is tried at
TEMPLATES = 4  # examples matched at most (the first drawn)
PIXELS = 250_000  # the searched copy has at most this many pixels
NOISE = 25.0  # grey levels squared added to the local variance: flat wall is not amplified into texture


def normalised(grey: np.ndarray, sigma: float) -> np.ndarray:
    """``grey`` less its local mean, over its local spread (Gaussian neighbourhoods of ``sigma`` pixels)."""
    import cv2

    g = grey.astype(np.float32)
    d = g - cv2.GaussianBlur(g, (0, 0), sigma)
    return d / np.sqrt(cv2.GaussianBlur(d * d, (0, 0), sigma) + NOISE)


def _peaks(profile: np.ndarray, spacing: int, threshold: float) -> list[int]:
    """Positions of ``profile`` at ``threshold`` or more, highest first, none within ``spacing`` of a higher one."""
    taken = np.zeros(len(profile), dtype=bool)
    out = []
    for i in np.argsort(-profile, kind="stable").tolist():
        if profile[i] < threshold:
            break
        if not taken[max(0, i - spacing): i + spacing + 1].any():
            taken[i] = True
            out.append(i)
    return out


def _beside(norm: np.ndarray, boxes: np.ndarray, cw: int, ch: int) -> list[np.ndarray]:
    """Crops of the type's size beside each example (above, below, left, right, a size away) that overlap no
    example: the wall that a copy must not look like."""
    sh, sw = norm.shape
    out = []
    for x0, y0, x1, y1 in boxes.tolist():
        cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
        for ddx, ddy in ((0, -1), (0, 1), (-1, 0), (1, 0)):
            left, top = round(cx + ddx * cw - cw / 2), round(cy + ddy * ch - ch / 2)
            if left < 0 or top < 0 or left + cw > sw or top + ch > sh:
                continue
            box = np.array([left, top, left + cw, top + ch])
            ix = np.minimum(box[2], boxes[:, 2]) - np.maximum(box[0], boxes[:, 0])
            iy = np.minimum(box[3], boxes[:, 3]) - np.maximum(box[1], boxes[:, 1])
            if ((ix > 0) & (iy > 0)).any():
                continue
            crop = norm[top: top + ch, left: left + cw]
            if crop.std() > 1e-3:
                out.append(crop)
    return out


def _lines(starts: list[int], tolerance: float) -> list[int]:
    """The distinct lines among ``starts``: one per run of starts within ``tolerance`` of its first."""
    out: list[int] = []
    for v in sorted(starts):
        if not out or v - out[-1] > tolerance:
            out.append(v)
    return out


def find_copies(levels: Levels, examples: np.ndarray, size: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    """(boxes (n, 4) of ``size`` = (width, height), their scores) of the copies of the examples ((m, 4) boxes)
    in the photo's lattice, the examples' own places included; boxes and size in the segmentation's pixels,
    whatever the levels' scale. Empty arrays where the photo says nothing (flat, too small, examples cut by the
    image's edge)."""
    import cv2

    none = np.zeros((0, 4)), np.zeros(0)
    sx, sy = levels.scale[:2]
    w, h = float(size[0]) * sx, float(size[1]) * sy  # in the levels' pixels
    if not len(examples) or w < 2 or h < 2:
        return none
    f = min(1.0, SIDE / min(w, h), float(np.sqrt(PIXELS / levels.array.size)))
    small = levels.scaled(f)
    if small.std() < FLAT:
        return none
    norm = normalised(small, max(w, h) * f)
    mx, my = CONTEXT * w * f, CONTEXT * h * f
    tw, th = round(w * f + 2 * mx), round(h * f + 2 * my)
    sh, sw = norm.shape
    if tw < 3 or th < 3 or tw >= sw or th >= sh:
        return none
    response, places, cores = None, [], []
    cw, ch = max(3, round(w * f)), max(3, round(h * f))
    for x0, y0, x1, y1 in (np.asarray(examples, dtype=float).reshape(-1, 4) * levels.scale)[:TEMPLATES].tolist():
        cx, cy = (x0 + x1) / 2 * f, (y0 + y1) / 2 * f  # the example's middle, with the type's size around it
        left, top = round(cx - tw / 2), round(cy - th / 2)
        if left < 0 or top < 0 or left + tw > sw or top + th > sh:
            continue  # its context is cut by the image's edge
        template = norm[top: top + th, left: left + tw]
        if template.std() < 1e-3:
            continue
        r = cv2.matchTemplate(norm, template, cv2.TM_CCOEFF_NORMED)
        response = r if response is None else np.maximum(response, r)
        places.append((left, top))
        cores.append(norm[round(cy - ch / 2): round(cy - ch / 2) + ch, round(cx - cw / 2): round(cx - cw / 2) + cw])
    if response is None:
        return none
    walls = _beside(norm, np.asarray(examples, dtype=float).reshape(-1, 4)[:TEMPLATES] * levels.scale * f, cw, ch)
    response = np.where(np.isfinite(response), response, -1.0)
    rh, rw = response.shape
    dx, dy = max(1, round(0.1 * w * f)), max(1, round(0.1 * h * f))
    # the response along each drawn row (column), averaged over the drawn ones: a storey whose copies differ one by
    # one (a blind closed here, a curtain there) still stands out where all the drawn columns agree
    lefts = _lines([p[0] for p in places], 0.3 * tw)
    tops = _lines([p[1] for p in places], 0.3 * th)
    along_x = np.mean([response[max(0, t - dy): t + dy + 1].max(axis=0) for t in tops], axis=0)
    along_y = np.mean([response[:, max(0, x - dx): x + dx + 1].max(axis=1) for x in lefts], axis=0)
    columns = set(_peaks(along_x, int(SPACING * w * f), AXIS)) | set(lefts)
    rows = set(_peaks(along_y, int(SPACING * h * f), AXIS)) | set(tops)
    # each cell is scored by the element alone (its context would make the wall between two copies look alike),
    # at the scales a storey's or a bay's own copies may have
    found: dict[tuple[int, int, int, int], float] = {}
    ox, oy = (tw - cw) / 2, (th - ch) / 2  # the element's place inside the template with its context
    scaled = {(kx, ky): [cv2.resize(c, (max(3, round(cw * kx)), max(3, round(ch * ky)))) for c in cores]
              for kx, ky in SCALES}
    wall_scaled = {k: [cv2.resize(c, v[0].shape[::-1]) for c in walls] for k, v in scaled.items()}
    for y in sorted(rows):
        for x in sorted(columns):
            cx, cy = x + ox + cw / 2, y + oy + ch / 2  # the cell's middle, where the context template put it
            best = (-2.0, 0, 0, 0, 0)
            for key, templates in scaled.items():
                eh, ew = templates[0].shape
                a, b = max(0, round(cy - eh / 2) - dy), max(0, round(cx - ew / 2) - dx)
                region = norm[a: min(sh, round(cy - eh / 2) + eh + dy), b: min(sw, round(cx - ew / 2) + ew + dx)]
                if region.shape[0] < eh or region.shape[1] < ew:
                    continue
                r = np.max([cv2.matchTemplate(region, t, cv2.TM_CCOEFF_NORMED) for t in templates], axis=0)
                if wall_scaled[key]:  # less how much it looks like the wall beside the examples
                    r = r - WALL * np.max([cv2.matchTemplate(region, t, cv2.TM_CCOEFF_NORMED)
                                           for t in wall_scaled[key]], axis=0).clip(0, None)
                r = np.where(np.isfinite(r), r, -1.0)
                k = np.unravel_index(int(r.argmax()), r.shape)
                if r[k] > best[0]:
                    best = (float(r[k]), b + int(k[1]), a + int(k[0]), ew, eh)
            score, bx, by, ew, eh = best
            if score >= CELL and score > found.get((bx, by, ew, eh), -2.0):
                found[(bx, by, ew, eh)] = score
    if not found:
        return none
    at = np.array(list(found), dtype=float)  # (n, 4): left, top, width, height in the searched copy
    boxes = np.stack([at[:, 0] / f / sx, at[:, 1] / f / sy, (at[:, 0] + at[:, 2]) / f / sx,
                      (at[:, 1] + at[:, 3]) / f / sy], axis=1)
    scores = np.array(list(found.values()))
    order = np.argsort(-scores, kind="stable")
    return boxes[order], scores[order]
