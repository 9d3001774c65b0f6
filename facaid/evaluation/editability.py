"""Whether a procedure can be edited as a person means: its windows' rows and columns, and what ``floors`` + 1 and
``bays`` + 1 do to them (issue 55's figures, `facaid evaluate-real`).

A window is a connected region of window-or-blind pixels of the label map (a window cut into pieces by its blind
or sill counts once). Window rows are the bands of window centres along y, split where the gap between neighbouring
centres exceeds half the median window height; columns the same along x with the width. A facade is *eligible*
when its annotation has at least two rows and two columns.
"""

from __future__ import annotations

import numpy as np

from facaid.grammar.execute import flat_rows
from facaid.grammar.procedure import Procedure
from facaid.labels import GLASS
from facaid.parameters import named_parameters, set_parameter
from facaid.segmentation import Segmentation, flatten_array, region_boxes


def window_boxes(rows: np.ndarray) -> np.ndarray:
    """The windows of a flattened segmentation's rows (N, 5: label, x0, y0, x1, y1; a partition of the label map):
    the bounding boxes (M, 4) of the connected regions of its window and blind pieces."""
    return region_boxes(rows, GLASS)


def _bands(centres: np.ndarray, sizes: np.ndarray) -> int:
    if len(centres) == 0:
        return 0
    c = np.sort(centres)
    return int(1 + np.sum(np.diff(c) > 0.5 * np.median(sizes)))


def lattice(rows: np.ndarray) -> tuple[int, int]:
    """(window rows, window columns) of a flattened segmentation's rows."""
    w = window_boxes(rows)
    if len(w) == 0:
        return 0, 0
    return (_bands((w[:, 1] + w[:, 3]) / 2, w[:, 3] - w[:, 1]), _bands((w[:, 0] + w[:, 2]) / 2, w[:, 2] - w[:, 0]))


def segmentation_lattice(seg: Segmentation) -> tuple[int, int]:
    return lattice(flatten_array(seg.width, seg.height, seg.to_array()))


def editability(proc: Procedure, annotation: tuple[int, int] | None = None) -> dict:
    """What a person gets editing ``proc`` by its named parameters: whether ``floors`` and ``bays`` exist, and
    whether + 1 of each adds exactly one row (column) of windows and keeps the columns (rows). ``annotation``: the
    lattice of the annotation it reconstructs, for ``eligible``."""
    names = {p.name: p for p in named_parameters(proc)}
    rows, cols = lattice(flat_rows(proc))
    out = {"rows": rows, "columns": cols, "floors": "floors" in names, "bays": "bays" in names,
           "floors_plus_one": False, "bays_plus_one": False}
    if annotation is not None:
        out["eligible"] = annotation[0] >= 2 and annotation[1] >= 2
    for name, key, grows, keeps in (("floors", "floors_plus_one", 0, 1), ("bays", "bays_plus_one", 1, 0)):
        p = names.get(name)
        if p is None or p.value + 1 > p.max:
            continue
        try:
            edited = set_parameter(proc, name, p.value + 1)
        except ValueError:
            continue
        after = lattice(flat_rows(edited))
        before = (rows, cols)
        out[key] = after[grows] == before[grows] + 1 and after[keeps] == before[keeps]
    return out
