"""The proposals of one completion call, and the checks every one must pass: inside the drawn facade, not cut by the
image's edge, not over a drawn element of its class nor mostly under one that paints over it, not near a rejected
box; at the place of another proposal of its class, the better scored stays (`Proposals.add`)."""

from __future__ import annotations

import numpy as np

from facaid.labels import BACKGROUND, FACADE, PRIORITY
from facaid.segmentation import Segmentation, parse_segmentation

MAX_DRAWN = 2_000  # more drawn rectangles than this are refused (a CMP facade has at most a few hundred)
MAX_PROPOSALS = 2_000  # proposals gathered at most in one call
SAME_PLACE = 0.5  # IoU at which two proposals are the same element
OVERLAP = 0.2  # a proposal whose area lies this much over drawn elements of its class is not made
REJECTED_PLACE = 0.3  # IoU at which a proposal repeats a rejected one


class RejectedError(ValueError):
    """A rejected rectangle that breaks the segmentation contract; the message names it (``rejected[i]``)."""


def overlap(box: np.ndarray, boxes: np.ndarray) -> np.ndarray:
    """The area ``box`` shares with each of ``boxes`` ((n, 4) x0, y0, x1, y1)."""
    ix = np.clip(np.minimum(box[2], boxes[:, 2]) - np.maximum(box[0], boxes[:, 0]), 0, None)
    iy = np.clip(np.minimum(box[3], boxes[:, 3]) - np.maximum(box[1], boxes[:, 1]), 0, None)
    return ix * iy


def area(boxes: np.ndarray) -> np.ndarray:
    return (boxes[..., 2] - boxes[..., 0]) * (boxes[..., 3] - boxes[..., 1])


def iou(box: np.ndarray, boxes: np.ndarray) -> np.ndarray:
    inter = overlap(box, boxes)
    return inter / np.maximum(area(box) + area(boxes) - inter, 1e-9)


class Proposals:
    """Proposals gathered with the checks every one must pass."""

    def __init__(self, seg: Segmentation, rows: np.ndarray, rejected: np.ndarray):
        self.width, self.height = seg.width, seg.height
        walls = rows[rows[:, 0] == FACADE, 1:].astype(float)
        self.walls = walls if len(walls) else np.array([[0.0, 0.0, seg.width, seg.height]])
        self.drawn = rows[(rows[:, 0] != FACADE) & (rows[:, 0] != BACKGROUND)]
        self.rejected = rejected
        self.items: list[tuple[int, np.ndarray, float, str]] = []  # label, box, score, reason
        self.boxes = np.zeros((MAX_PROPOSALS, 4))  # the items' boxes and labels, for comparing in one go
        self.labels = np.full(MAX_PROPOSALS, -1)
        self.cache: dict[int, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
        self.photo: dict[int, float] = {}  # item: the similarity the photo found it at (its repeats)

    @property
    def full(self) -> bool:
        return len(self.items) >= MAX_PROPOSALS

    def inside(self, box: np.ndarray) -> bool:
        """Within the bounds of the drawn facade rectangles (2 px of slack), or the image when none is drawn: a
        wall drawn as one rectangle or, as flattened segmentations have it, as pieces around the elements."""
        slack, w = 2.0, self.walls
        return bool(w[:, 0].min() - slack <= box[0] and w[:, 1].min() - slack <= box[1]
                    and box[2] <= w[:, 2].max() + slack and box[3] <= w[:, 3].max() + slack)

    def against(self, label: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(drawn boxes of the class, drawn boxes of classes painted over it, rejected boxes of the class)."""
        if label not in self.cache:
            drawn = self.drawn
            above = np.array([PRIORITY[k] > PRIORITY[label] for k in drawn[:, 0].tolist()], dtype=bool)
            rej = self.rejected[self.rejected[:, 0] == label, 1:] if len(self.rejected) else np.zeros((0, 4))
            self.cache[label] = (drawn[drawn[:, 0] == label, 1:].astype(float),
                                 drawn[above, 1:].astype(float).reshape(-1, 4), rej.astype(float))
        return self.cache[label]

    def add(self, label: int, box: np.ndarray, score: float, reason: str, photo: float | None = None) -> bool:
        """Propose ``box`` unless a check refuses it (False); at the place of a proposal made already, the better
        scored of the two stays. ``photo``: the similarity the photo found it at, kept with it."""
        box = np.round(np.asarray(box, dtype=float))
        if (self.full or box[2] - box[0] < 1 or box[3] - box[1] < 1 or box[0] < 0 or box[1] < 0
                or box[2] > self.width or box[3] > self.height or not self.inside(box)):
            return False  # a place cut by the image's edge is no element
        same, above, rej = self.against(label)
        shared = overlap(box, same)  # over a drawn element of its class, even in part: drawn already
        if shared.sum() > OVERLAP * area(box) or (shared / np.maximum(area(same), 1e-9) > 0.5).any():
            return False
        if overlap(box, above).sum() > 0.6 * area(box):  # mostly under a drawn element that paints over it
            return False
        if (iou(box, rej) >= REJECTED_PLACE).any():
            return False
        n = len(self.items)
        mine = np.flatnonzero(self.labels[:n] == label)
        hit = mine[iou(box, self.boxes[mine]) >= SAME_PLACE]
        if len(hit):
            i = int(hit[0])
            if score > self.items[i][2]:
                self.items[i] = (label, box, score, reason)
                self.boxes[i] = box
                self._photo(i, photo)
            return False
        self.items.append((label, box, score, reason))
        self.boxes[n], self.labels[n] = box, label
        self._photo(n, photo)
        return True

    def _photo(self, i: int, photo: float | None) -> None:
        if photo is None:
            self.photo.pop(i, None)
        else:
            self.photo[i] = round(float(photo), 3)


def proposals_for(segmentation: Segmentation | dict, rejected: list[dict] | None, min_score: float
                  ) -> tuple[Segmentation, Proposals]:
    """The segmentation and an empty `Proposals` for it, the arguments checked as `complete` says."""
    seg = segmentation if isinstance(segmentation, Segmentation) else parse_segmentation(segmentation)
    rows = seg.to_array()
    if len(rows) > MAX_DRAWN:
        raise ValueError(f"too many rectangles for completion: {len(rows)} (at most {MAX_DRAWN})")
    if not 0 <= min_score <= 1:  # NaN too
        raise ValueError(f"min_score must be in [0, 1], got {min_score}")
    if rejected is not None and not isinstance(rejected, list):
        raise ValueError("rejected must be a list of rectangles")
    rej = np.zeros((0, 5))
    if rejected:  # the contract's rectangles, checked as a segmentation of the same size would be
        try:
            rej = parse_segmentation({"width": seg.width, "height": seg.height, "rects": rejected}).to_array()
        except ValueError as exc:
            raise RejectedError(str(exc).replace("rects", "rejected")) from None
    return seg, Proposals(seg, rows, rej)


__all__ = ["MAX_DRAWN", "MAX_PROPOSALS", "Proposals", "RejectedError", "area", "iou", "overlap", "proposals_for"]
