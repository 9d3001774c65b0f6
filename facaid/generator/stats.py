"""Per-class statistics of segmentations: do generated facades look like the CMP annotations?

Both sides are measured the same way: each segmentation is flattened (footprint plus element layers) and
rasterized; we report per class the mean number of rectangles per facade, the share of facades that have
the class at all, and the mean fraction of the image area it covers.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from facaid.labels import LABELS
from facaid.segmentation import Segmentation, aligned_lines, class_areas, flatten, rasterize


@dataclass
class ClassStats:
    facades: int
    rects: np.ndarray  # (12,) mean rectangles per facade
    present: np.ndarray  # (12,) share of facades with the class
    area: np.ndarray  # (12,) mean area fraction
    rects_total: float  # mean element rectangles per facade (facade and background excluded)

    def to_dict(self) -> dict:
        return {
            "facades": self.facades,
            "rects_per_facade": float(self.rects_total),
            "classes": {
                name: {"rects": float(self.rects[i]), "present": float(self.present[i]), "area": float(self.area[i])}
                for i, name in enumerate(LABELS)
            },
        }


def class_stats(segs: list[Segmentation]) -> ClassStats:
    n = len(segs)
    if n == 0:
        raise ValueError("no segmentations to measure")
    rects = np.zeros(len(LABELS))
    present = np.zeros(len(LABELS))
    area = np.zeros(len(LABELS))
    for seg in segs:
        flat = flatten(seg, wall="footprint")
        counts = np.bincount([r.label for r in flat.rects], minlength=len(LABELS))[: len(LABELS)]
        rects += counts
        present += counts > 0
        area += class_areas(rasterize(flat)) / (seg.width * seg.height)
    rects /= n
    return ClassStats(n, rects, present / n, area / n, float(rects[2:].sum()))


def load_cmp(path: str | Path) -> list[Segmentation]:
    """The CMP annotations (one JSON object per line); for evaluation and comparison only."""
    with open(path, encoding="utf-8") as f:
        return [Segmentation.from_dict(json.loads(line)) for line in f if line.strip()]


def distance(a: ClassStats, b: ClassStats) -> float:
    """Total variation distance between the mean area distributions over the 12 classes (0 = identical)."""
    pa, pb = a.area / a.area.sum(), b.area / b.area.sum()
    return float(0.5 * np.abs(pa - pb).sum())


def format_table(generated: ClassStats, real: ClassStats) -> str:
    lines = [
        f"{'class':<11} {'rects/facade':>21} {'present':>17} {'area %':>17}",
        f"{'':<11} {'generated':>10} {'CMP':>10} {'generated':>8} {'CMP':>8} {'generated':>8} {'CMP':>8}",
    ]
    for i, name in enumerate(LABELS):
        lines.append(
            f"{name:<11} {generated.rects[i]:>10.1f} {real.rects[i]:>10.1f} {generated.present[i]:>8.0%} "
            f"{real.present[i]:>8.0%} {100 * generated.area[i]:>8.1f} {100 * real.area[i]:>8.1f}"
        )
    lines.append(f"{'elements':<11} {generated.rects_total:>10.1f} {real.rects_total:>10.1f}")
    lines.append(f"area distribution distance (total variation): {distance(generated, real):.3f}")
    return "\n".join(lines)


# --- irregularity: how far the rows and columns of windows are from a grid ------------------------------------

WINDOW = LABELS.index("window")


def irregularity(segs: list[Segmentation], min_members: int = 3) -> dict[str, float]:
    """How regular the windows' rows and columns are, as medians over every row (column) of at least
    ``min_members`` windows of every facade: the spread of their top (left) edges and of their bottom (right) edges
    as a share of the image's height (width), and their heights' (widths') coefficient of variation. Windows are
    the window rectangles of the flattened footprint form (pieces where a blind or sill cuts one), measured the
    same way on generated facades and CMP annotations. A generated facade's rows are exact (0); people's are not.
    """
    spreads: dict[str, list[float]] = {"row_top": [], "row_bottom": [], "row_height_cv": [],
                                       "column_left": [], "column_right": [], "column_width_cv": []}
    for seg in segs:
        rows = flatten(seg, wall="footprint").to_array()
        win = rows[rows[:, 0] == WINDOW].astype(float)
        if len(win) < min_members:
            continue
        for lo_col, hi_col, side, names in ((2, 4, seg.height, ("row_top", "row_bottom", "row_height_cv")),
                                            (1, 3, seg.width, ("column_left", "column_right", "column_width_cv"))):
            lo, hi = win[:, lo_col], win[:, hi_col]
            for members in aligned_lines(lo, hi):
                if len(members) < min_members:
                    continue
                extent = hi[members] - lo[members]
                spreads[names[0]].append(float(np.std(lo[members]) / side))
                spreads[names[1]].append(float(np.std(hi[members]) / side))
                spreads[names[2]].append(float(np.std(extent) / np.mean(extent)))
    out = {name: float(np.median(v)) if v else 0.0 for name, v in spreads.items()}
    out["rows"] = float(len(spreads["row_top"]))
    out["columns"] = float(len(spreads["column_left"]))
    return out
