"""Comparing label maps: pixel accuracy, per-class IoU, and cheap low-resolution rasterization."""

from __future__ import annotations

import numpy as np

from facaid.grammar.execute import execute
from facaid.grammar.procedure import Procedure
from facaid.labels import LABELS, PRIORITY
from facaid.segmentation import Segmentation


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
    w, h = max(1, round(width * scale)), max(1, round(height * scale))
    out = np.zeros((h, w), dtype=np.uint8)
    for lab, x0, y0, x1, y1 in sorted(rows, key=lambda r: PRIORITY[r[0]]):
        a, b = round(x0 * scale), round(x1 * scale)
        c, d = round(y0 * scale), round(y1 * scale)
        if a < b and c < d:
            out[c:d, a:b] = lab
    return out


def scaled_label_map(seg: Segmentation, scale: float) -> np.ndarray:
    """The segmentation's label map at ``scale`` (e.g. 0.25), painted in the paint order."""
    return _paint(list(seg.rects), seg.width, seg.height, scale)


def scaled_procedure_map(proc: Procedure, scale: float) -> np.ndarray:
    """The executed procedure's label map at ``scale``."""
    return _paint(execute(proc), round(proc.width), round(proc.height), scale)
