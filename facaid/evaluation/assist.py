"""A simulated annotator for completion (`facaid.completion.complete`): how much drawing it saves.

The annotator draws the true elements of a facade one by one in reading order (top to bottom, then left to
right; the facade rectangles first where they start highest), and after every ``every``-th one asks for
completion. Each proposal that matches a true element not drawn yet (same class, IoU >= ``match``) is accepted
as proposed at no cost and that element counts as drawn; each other proposal costs one action (rejecting it)
and is passed back as rejected, so it is not proposed again. The annotator stops once the drawing reproduces
``stop`` of the image's pixels (or everything is drawn). Effort = actions / true elements: 1.0 is drawing all
of them by hand.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from facaid.completion import complete
from facaid.formats.annotation import as_drawn  # noqa: F401  (the benches and tests read it here)
from facaid.labels import LABEL_ID
from facaid.metrics import pixel_accuracy
from facaid.segmentation import Rect, Segmentation, rasterize


@dataclass
class Session:
    elements: int  # true elements (rectangles) of the facade
    drawn: int  # drawn by hand
    accepted: int  # proposals accepted
    rejected: int  # proposals rejected (one action each)
    calls: int  # completion calls
    accuracy: float  # pixel accuracy of the final drawing against the facade

    @property
    def effort(self) -> float:
        return (self.drawn + self.rejected) / max(1, self.elements)


def _iou(a: Rect, b: Rect) -> float:
    ix = max(0, min(a.x1, b.x1) - max(a.x0, b.x0))
    iy = max(0, min(a.y1, b.y1) - max(a.y0, b.y0))
    inter = ix * iy
    return inter / (a.area + b.area - inter) if inter else 0.0


def simulate(seg: Segmentation, propose: Callable[..., list[dict]] = complete, *, every: int = 3,
             match: float = 0.7, stop: float = 0.95) -> Session:
    """Annotate ``seg`` as the module's docstring says, with ``propose(segmentation, rejected=[...])`` (by
    default `facaid.completion.complete`) asked for proposals."""
    if not (0 < match <= 1 and 0 < stop <= 1 and every >= 1):
        raise ValueError(f"match and stop must be in (0, 1] and every >= 1, got {match}, {stop}, {every}")
    target = rasterize(seg)
    todo = sorted(seg.rects, key=lambda r: (r.y0, r.x0, r.y1, r.x1, r.label))
    drawing: list[Rect] = []
    rejected: list[dict] = []
    drawn = calls = 0
    accuracy = pixel_accuracy(rasterize(Segmentation(seg.width, seg.height, ())), target)
    while todo and accuracy < stop:
        drawing.append(todo.pop(0))
        drawn += 1
        if drawn % every == 0:
            calls += 1
            _review(propose(Segmentation(seg.width, seg.height, tuple(drawing)), rejected=rejected), todo, drawing,
                    rejected, match)
        accuracy = pixel_accuracy(rasterize(Segmentation(seg.width, seg.height, tuple(drawing))), target)
    accepted = len(drawing) - drawn
    return Session(len(seg.rects), drawn, accepted, len(rejected), calls, accuracy)


def _review(proposals: list[dict], todo: list[Rect], drawing: list[Rect], rejected: list[dict], match: float) -> None:
    """The annotator's look at one call's proposals: each matching a true element not drawn yet is drawn as
    proposed (and that element is done), each other one rejected."""
    for p in proposals:
        box = Rect(LABEL_ID[p["label"]], p["x0"], p["y0"], p["x1"], p["y1"])
        best = max(((_iou(box, r), i) for i, r in enumerate(todo) if r.label == box.label), default=(0.0, -1))
        if best[0] >= match:
            todo.pop(best[1])
            drawing.append(box)
        else:
            rejected.append({k: p[k] for k in ("label", "x0", "y0", "x1", "y1")})


def summary(sessions: list[Session]) -> dict:
    """Median and mean effort, and the totals, of a group of sessions."""
    if not sessions:
        return {"facades": 0}
    effort = [s.effort for s in sessions]
    return {"facades": len(sessions), "effort_median": float(np.median(effort)), "effort_mean": float(np.mean(effort)),
            "drawn": sum(s.drawn for s in sessions), "accepted": sum(s.accepted for s in sessions),
            "rejected": sum(s.rejected for s in sessions), "elements": sum(s.elements for s in sessions)}

