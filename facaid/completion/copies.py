"""Find copies: where a drawn unit (a window with its sill, blind, hood, balcony) repeats in the photo.

A person selects one unit and asks for its copies (the editor's "Find copies", ``unit`` in the API's completion,
``facaid complete --unit``). The photo's repeats (`facaid.photo.repeats.unit_copies`) carry the unit along the shifts
that it and the other drawn elements vote for; a copy is proposed where the unit's largest element looks like itself
(normalised cross-correlation on the contrast-normalised photo, at least `facaid.photo.repeats.MATCH`), with the rest of
the unit around it. Each proposal has the ``score`` of its copy (that NCC: 1 is the same picture), the ``copy`` it
belongs to (its unit's elements share it) and the reason ``copy of the unit``. The checks of completion apply:
nothing outside the drawn facade, over a drawn element of its class or near a rejected box.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from facaid.completion.proposals import proposals_for
from facaid.defaults import DEFAULT_MIN_COPY
from facaid.labels import BACKGROUND, FACADE, LABELS
from facaid.photo import appearance, repeats
from facaid.segmentation import Segmentation


class UnitError(ValueError):
    """A unit that names no elements of the segmentation."""


MAX_UNIT = 50  # rectangles a unit holds at most


def find_copies(segmentation: Segmentation | dict, photo: Any, unit: list[int], *,
                rejected: list[dict] | None = None, min_score: float = DEFAULT_MIN_COPY) -> list[dict]:
    """Proposals for the copies of the unit (indices into the segmentation's rectangles) in the photo, best copy
    first (see the module's docstring). Raises `UnitError` (a ValueError) naming the problem for a bad unit (not a
    list of distinct indices of rectangles, empty, more than `MAX_UNIT`, the wall) and as `facaid.completion.complete`
    does for the rest."""
    seg, props = proposals_for(segmentation, rejected, min_score)
    if not isinstance(unit, list) or not unit:
        raise UnitError("unit must be a non-empty list of rectangle indices")
    if len(unit) > MAX_UNIT:
        raise UnitError(f"a unit holds at most {MAX_UNIT} rectangles, got {len(unit)}")
    n = len(seg.rects)
    if any(isinstance(i, bool) or not isinstance(i, int) or not 0 <= i < n for i in unit) or len(set(unit)) < len(unit):
        raise UnitError(f"unit must list distinct rectangle indices from 0 to {n - 1}, got {unit}")
    rows = seg.to_array()
    mine = rows[unit]
    if np.isin(mine[:, 0], (FACADE, BACKGROUND)).any():
        raise UnitError("a unit is elements (a window and what is drawn around it), not the wall or background")
    levels = appearance.levels(photo, seg.width, seg.height)
    out: list[dict] = []
    others = np.delete(rows, unit, axis=0)  # the unit votes once, the other drawn elements beside it
    for score, parts in sorted(repeats.unit_copies(levels, others, mine), key=lambda f: -f[0]):
        if score < min_score:
            break
        copy = len({p["copy"] for p in out})
        for k, (label, box) in enumerate(parts):
            if not props.add(label, box, score, "copy of the unit"):
                if k == 0:
                    break  # the unit's main element is there already, drawn or proposed: no copy here
                continue
            b = props.boxes[len(props.items) - 1]
            out.append({"label": LABELS[label], "x0": int(b[0]), "y0": int(b[1]), "x1": int(b[2]), "y1": int(b[3]),
                        "score": round(float(score), 3), "reason": "copy of the unit", "copy": copy})
    return out
