"""Augmentation: segmentations made noisy as people annotate, for training (`jitter`: element edges moved) and
for evaluation (`perturb`: jittered until a given share of the pixels changes label)."""

from __future__ import annotations

import numpy as np

from facaid.labels import FACADE
from facaid.metrics import scaled_label_map
from facaid.segmentation import Rect, Segmentation, flatten, flatten_array

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


ANNOTATOR_EDGE = 0.01  # every edge moves by up to this share of the image's side (uniform), as people annotate
ANNOTATOR_DROP = 0.10  # share of the elements left out
ANNOTATOR_SPURIOUS = 2  # boxes added over existing elements
# Calibrated on the CMP dev half (facades 1-189; `facaid.generator.stats.irregularity`): uniform edge noise of these
# shares of the width and height gives generated facades the spread of window edges along rows (0.0017 of the
# height) and columns (0.0043 of the width) that people's annotations have (experiments/2026-12-03-annotation-
# calibration). The evaluation's ANNOTATOR_EDGE (1 %) is three times noisier along rows than CMP's annotators.
CMP_EDGE_X = 0.006
CMP_EDGE_Y = 0.003
# Floors and bays spaced as irregularly as on the CMP dev half: the median absolute deviation of the window rows'
# (columns') pitch from their median, as a share of it, is 0.062 (0.027) there and 0.006 (0) on generated facades;
# `spacing_warp` with these shares of the height and width gives generated facades 0.063 (0.027)
# (experiments/2026-12-05-annotate-rich/spacing.py).
CMP_SPACING_X = 0.0125
CMP_SPACING_Y = 0.025
OUTLINE_CUT = 0.25  # a partial facade rectangle loses up to this share of the building's extent on each side
SPACING_KNOTS = 9  # the spacing warp's offsets are drawn at this many evenly spaced places along each side
MAX_SPACING = 0.05  # the most a spacing share may be: below half the knots' spacing, so the warp stays monotone
assert MAX_SPACING < 0.5 / (SPACING_KNOTS - 1)


def spacing_warp(seg: Segmentation, spacing: float, spacing_y: float, rng: np.random.Generator):
    """Two monotone maps (x, y) -> moved, piecewise linear: offsets uniform in +-``spacing`` of the width
    (``spacing_y`` of the height) at `SPACING_KNOTS` evenly spaced places, none at the image's edges. Elements of
    one row (column) move together: floors (bays) spaced irregularly, as buildings and rectified photos are."""
    def axis(side: int, share: float):
        knots = np.linspace(0.0, side, SPACING_KNOTS)
        moved = knots + np.concatenate([[0.0], rng.uniform(-share, share, SPACING_KNOTS - 2) * side, [0.0]])
        return lambda v: float(np.interp(v, knots, moved))
    return axis(seg.width, spacing), axis(seg.height, spacing_y)


def annotator_noise(seg: Segmentation, seed: int, *, edge: float = ANNOTATOR_EDGE, drop: float = ANNOTATOR_DROP,
                    spurious: int = ANNOTATOR_SPURIOUS, edge_y: float | None = None,
                    spacing: float = 0.0, spacing_y: float | None = None) -> Segmentation:
    """A segmentation annotated the way people annotate (`facaid evaluate-real --perturb SEED`), seeded: each
    element's four edges moved independently by up to ``edge`` of the image's width (x) or height (y; ``edge_y``
    when given), uniformly, after ``spacing`` (a share of the width, ``spacing_y`` of the height; 0 by default)
    moved whole rows and columns of them (`spacing_warp`); ``drop`` of the elements left out (rounded: one of ten
    at the default); ``spurious`` boxes added, each over an element left in, of a class drawn among
    the elements and about the size of the element it covers.
    Facade (wall) rectangles keep their place but for the spacing warp (which moves them with the elements, so
    that the building stays one): they are the building's outline, not an element. Where they are
    pieces around the elements (a partition, as a generated facade's leaves are: no wall rectangle under any
    element), the wall is taken to run under the elements, as a person draws it, so a left-out element leaves wall
    behind and not a hole. The result holds the input's layers as rectangles, not flattened."""
    edge_y = edge if edge_y is None else edge_y
    if not (0 <= edge <= 0.5 and 0 <= edge_y <= 0.5 and 0 <= drop < 1 and spurious >= 0):
        raise ValueError(f"edges must be in [0, 0.5], drop in [0, 1), spurious >= 0; got {edge}, {edge_y}, {drop}, "
                         f"{spurious}")
    spacing_y = spacing if spacing_y is None else spacing_y
    if not (0 <= spacing <= MAX_SPACING and 0 <= spacing_y <= MAX_SPACING):
        raise ValueError(f"spacing must be in [0, {MAX_SPACING}] (a share of the side), got {spacing}, {spacing_y}")
    rng = np.random.default_rng([int(seed), 20421])
    walls = [r for r in seg.rects if r.label == FACADE]
    elements = [r for r in seg.rects if r.label != FACADE]
    walls = _building_walls(seg, walls, elements)
    n_drop = int(round(drop * len(elements)))
    keep = sorted(rng.permutation(len(elements))[n_drop:].tolist()) if elements else []
    kept = [elements[i] for i in keep]
    w, h = seg.width, seg.height
    if spacing > 0 or spacing_y > 0:  # its own stream: the rest of the noise is drawn as without it
        wx, wy = spacing_warp(seg, spacing, spacing_y, np.random.default_rng([int(seed), 20422]))
        kept = [Rect(r.label, wx(r.x0), wy(r.y0), wx(r.x1), wy(r.y1)) for r in kept]
        walls = [Rect(FACADE, round(wx(r.x0)), round(wy(r.y0)), round(wx(r.x1)), round(wy(r.y1))) for r in walls]
        walls = [r for r in walls if r.x0 < r.x1 and r.y0 < r.y1]

    def moved(r: Rect) -> Rect | None:
        d = rng.uniform(-1.0, 1.0, size=4) * (edge * w, edge_y * h, edge * w, edge_y * h)
        x0, y0 = max(0, round(r.x0 + d[0])), max(0, round(r.y0 + d[1]))
        x1, y1 = min(w, round(r.x1 + d[2])), min(h, round(r.y1 + d[3]))
        return Rect(r.label, x0, y0, x1, y1) if x0 < x1 and y0 < y1 else None

    out = walls + [m for m in map(moved, kept) if m is not None]
    labels = [r.label for r in elements]
    for _ in range(spurious if kept else 0):
        under = kept[rng.integers(len(kept))]
        cw, ch = (under.x1 - under.x0) * rng.uniform(0.5, 1.5), (under.y1 - under.y0) * rng.uniform(0.5, 1.5)
        cx = (under.x0 + under.x1) / 2 + rng.uniform(-0.5, 0.5) * (under.x1 - under.x0)
        cy = (under.y0 + under.y1) / 2 + rng.uniform(-0.5, 0.5) * (under.y1 - under.y0)
        box = Rect(int(labels[rng.integers(len(labels))]), max(0, round(cx - cw / 2)), max(0, round(cy - ch / 2)),
                   min(w, round(cx + cw / 2)), min(h, round(cy + ch / 2)))
        if box.x0 < box.x1 and box.y0 < box.y1:
            out.append(box)
    return Segmentation(w, h, tuple(out))


def _building_walls(seg: Segmentation, walls: list[Rect], elements: list[Rect]) -> list[Rect]:
    """The wall rectangles as a person draws them: ``walls`` as given where some lies under an element (layered, as
    CMP's facade rectangle), else (a partition, as a generated facade's leaves: wall pieces around the elements,
    and no input built otherwise has none) the building's footprint, running under the elements too."""
    if not walls or not elements or _under(walls, elements):
        return walls
    rows = flatten_array(seg.width, seg.height, seg.to_array(), wall="footprint")
    return [Rect(FACADE, *map(int, r[1:])) for r in rows if r[0] == FACADE]


def _under(walls: list[Rect], elements: list[Rect]) -> bool:
    """Whether some wall rectangle lies (partly) under some element."""
    a = np.array([(r.x0, r.y0, r.x1, r.y1) for r in walls])[:, None, :]
    b = np.array([(r.x0, r.y0, r.x1, r.y1) for r in elements])[None, :, :]
    return bool(((np.minimum(a[..., 2], b[..., 2]) > np.maximum(a[..., 0], b[..., 0]))
                 & (np.minimum(a[..., 3], b[..., 3]) > np.maximum(a[..., 1], b[..., 1]))).any())


def cmp_annotation(seg: Segmentation, seed: int, *, drop: float = 0.0, spurious: int = 0) -> Segmentation:
    """`annotator_noise` with the edge spread calibrated on CMP's annotators (`CMP_EDGE_X`, `CMP_EDGE_Y`)."""
    return annotator_noise(seg, seed, edge=CMP_EDGE_X, edge_y=CMP_EDGE_Y, drop=drop, spurious=spurious)


def outline(seg: Segmentation, seed: int, *, missing: bool) -> Segmentation:
    """The segmentation with its facade (wall) rectangles left out (``missing``: the elements alone, as a person
    who drew no wall) or cut to a part of the building (each side of their bounding box moved in by up to
    `OUTLINE_CUT` of its extent, seeded: a wall drawn over part of it). Elements stay as they are; the wall the
    cut leaves out is background. Layered as given (partitions' walls taken as running under the elements)."""
    walls = [r for r in seg.rects if r.label == FACADE]
    elements = [r for r in seg.rects if r.label != FACADE]
    if missing or not walls:
        return Segmentation(seg.width, seg.height, tuple(elements))
    walls = _building_walls(seg, walls, elements)
    rng = np.random.default_rng([int(seed), 20423])
    x0, y0 = min(r.x0 for r in walls), min(r.y0 for r in walls)
    x1, y1 = max(r.x1 for r in walls), max(r.y1 for r in walls)
    cut = rng.uniform(0.0, OUTLINE_CUT, 4) * (x1 - x0, y1 - y0, x1 - x0, y1 - y0)
    bx0, by0, bx1, by1 = round(x0 + cut[0]), round(y0 + cut[1]), round(x1 - cut[2]), round(y1 - cut[3])
    kept = [Rect(FACADE, max(r.x0, bx0), max(r.y0, by0), min(r.x1, bx1), min(r.y1, by1)) for r in walls]
    kept = [r for r in kept if r.x0 < r.x1 and r.y0 < r.y1]
    return Segmentation(seg.width, seg.height, tuple(kept + elements))
