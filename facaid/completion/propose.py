"""One completion call: the structure's proposals, then the photo's where one is given, checked and ranked
(`explained`; `complete` returns the proposals alone). See `facaid.completion`."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from facaid.completion import looks, structure
from facaid.completion.kinds import kinds, tried
from facaid.completion.proposals import proposals_for
from facaid.defaults import DEFAULT_MIN_SCORE
from facaid.labels import LABELS
from facaid.photo import appearance
from facaid.segmentation import Segmentation

REPEATS = True  # the photo's repeats carry the drawn elements (off: to measure what they add)
DIM_SCORE = 0.3  # places scored this or more, under ``min_score``, are returned dimmed: the person may take them
MAX_DIMMED = 60


def complete(segmentation: Segmentation | dict, photo: Any = None, *, rejected: list[dict] | None = None,
             min_score: float = DEFAULT_MIN_SCORE) -> list[dict]:
    """Proposed missing elements for a partly drawn segmentation (a `Segmentation` or its JSON object): dicts
    ``{label, x0, y0, x1, y1, score}`` in the segmentation contract, best first, none repeating a drawn element;
    ``rejected`` boxes (the same contract) are not proposed again. See `facaid.completion`. Raises
    `SegmentationError` (a ValueError) naming the field for a bad segmentation, `RejectedError` (a ValueError)
    for a bad rejected box, ValueError for more than `MAX_DRAWN` rectangles or ``min_score`` outside [0, 1]."""
    return explained(segmentation, photo, rejected=rejected, min_score=min_score).proposals


@dataclass
class Completion:
    """What `explained` found: the ``proposals`` (as `complete` returns them), the places scored under
    ``min_score`` but at least `DIM_SCORE` (``dimmed``: the structure proposes them and the photo does not confirm
    them, shown for the person to take), and in words what was ``tried`` where nothing is proposed."""

    proposals: list[dict]
    dimmed: list[dict]
    tried: list[str]


def explained(segmentation: Segmentation | dict, photo: Any = None, *, rejected: list[dict] | None = None,
              min_score: float = DEFAULT_MIN_SCORE) -> Completion:
    """`complete`, with the places under ``min_score`` and what was tried (a `Completion`)."""
    seg, props = proposals_for(segmentation, rejected, min_score)
    types = kinds(props.drawn)
    for t in types:
        structure.floors(t, props)
    for t in types:
        structure.lattice(t, props)
    structure.companions(types, props)
    seen = {}
    if photo is not None:
        levels = appearance.levels(photo, seg.width, seg.height)
        looks.search(levels, types, props)
        if REPEATS:
            looks.carried(levels, props)
        seen = looks.checked(levels, props)
    out = []
    for i, (label, b, score, reason) in enumerate(props.items):
        p = {"label": LABELS[label], "x0": int(b[0]), "y0": int(b[1]), "x1": int(b[2]), "y1": int(b[3]),
             "score": round(float(score), 3), "reason": reason}
        if i in seen:
            p["score"], p["photo"], box = seen[i]
            p.update(x0=int(box[0]), y0=int(box[1]), x1=int(box[2]), y1=int(box[3]))
        elif i in props.photo:
            p["photo"] = props.photo[i]
        out.append(p)
    out.sort(key=lambda p: (-p["score"], p["y0"], p["x0"]))
    kept = [p for p in out if p["score"] >= min_score]
    dimmed = [p for p in out if DIM_SCORE <= p["score"] < min_score][:MAX_DIMMED]
    return Completion(kept, dimmed, [] if kept else tried(types, bool(dimmed)))


__all__ = ["DIM_SCORE", "MAX_DIMMED", "REPEATS", "Completion", "complete", "explained"]
