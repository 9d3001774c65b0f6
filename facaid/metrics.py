"""Comparing label maps: pixel accuracy, per-class IoU, and cheap low-resolution rasterization."""

from __future__ import annotations

import math

import numpy as np

from facaid.grammar.execute import execute, to_segmentation
from facaid.grammar.procedure import Procedure
from facaid.labels import LABELS, PRIORITY
from facaid.segmentation import Segmentation, rasterize


def pixel_accuracy(a: np.ndarray, b: np.ndarray) -> float:
    if a.shape != b.shape:
        raise ValueError(f"label maps differ in shape: {a.shape} vs {b.shape}")
    return float((a == b).mean())


def class_iou(a: np.ndarray, b: np.ndarray) -> dict[str, float]:
    """IoU per label present in either map."""
    out = {}
    for i, name in enumerate(LABELS):
        pa, pb = a == i, b == i
        union = int((pa | pb).sum())
        if union:
            out[name] = float((pa & pb).sum() / union)
    return out


def _paint(rows: list[tuple[int, float, float, float, float]], width: int, height: int, scale: float) -> np.ndarray:
    """Point-sample the label map at the centres of a (height*scale, width*scale) grid: a cell takes the label
    of the full-size pixel under its centre, so any scale samples the same picture consistently."""
    w, h = max(1, round(width * scale)), max(1, round(height * scale))
    sx, sy = w / width, h / height
    out = np.zeros((h, w), dtype=np.uint8)
    for lab, x0, y0, x1, y1 in sorted(rows, key=lambda r: PRIORITY[r[0]]):
        # cells j with x0 <= (j + 0.5) / s < x1
        a, b = math.ceil(x0 * sx - 0.5), math.ceil(x1 * sx - 0.5)
        c, d = math.ceil(y0 * sy - 0.5), math.ceil(y1 * sy - 0.5)
        if a < b and c < d:
            out[max(c, 0) : d, max(a, 0) : b] = lab
    return out


def scaled_label_map(seg: Segmentation, scale: float) -> np.ndarray:
    """The segmentation's label map at ``scale`` (e.g. 0.25), painted in the paint order."""
    return _paint(list(seg.rects), seg.width, seg.height, scale)


def scaled_procedure_map(proc: Procedure, scale: float) -> np.ndarray:
    """The executed procedure's label map at ``scale``."""
    return _paint(execute(proc), round(proc.width), round(proc.height), scale)


def procedure_accuracy(proc: Procedure, target: Segmentation) -> float:
    """Exact pixel accuracy at full resolution of the executed procedure against a segmentation."""
    return pixel_accuracy(rasterize(to_segmentation(proc)), rasterize(target))


def procedure_iou(proc: Procedure, target: Segmentation) -> dict[str, float]:
    return class_iou(rasterize(to_segmentation(proc)), rasterize(target))
