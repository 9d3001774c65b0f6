"""Whether a procedure can be edited as a person means (`facaid evaluate-real`).

Two measures of `floors` + 1 and `bays` + 1. Issue 55's counts the windows (`facaid.reading.windows`): one more row
(column) of window centres, the same columns (rows). Issue 67's looks at the picture (`facaid.editing.check`): the
old facade with one band like its others put in between two, every other pixel where it was. A facade is
*eligible* when its annotation has at least two rows and two columns of windows. And what the procedure keeps of
what was drawn (`kept_elements`).
"""

from __future__ import annotations

import numpy as np

from facaid.editing.check import check_edits
from facaid.editing.parameters import named_parameters, set_parameter
from facaid.grammar.execute import flat_rows
from facaid.grammar.procedure import Procedure
from facaid.labels import FACADE
from facaid.metrics import appears
from facaid.reading.windows import lattice
from facaid.segmentation import region_boxes

KEPT = 0.5  # an element is kept when the procedure paints at least this share of its pixels with its label


def kept_elements(rows: np.ndarray, target: np.ndarray, pred: np.ndarray) -> tuple[int, int]:
    """(elements drawn, elements kept): the connected regions of each label but wall in a flattened annotation's
    ``rows`` whose label map is ``target``, and of those the ones ``pred`` paints with their label on at least `KEPT`
    of their area, where they were drawn or off by up to half their thinner side (a 3 px sill drawn 2 px lower is
    still there)."""
    drawn = kept = 0
    for label in sorted({int(v) for v in rows[:, 0]} - {FACADE}):
        for box in region_boxes(rows, (label,)):
            x0, y0, x1, y1 = box
            area = int((target[y0:y1, x0:x1] == label).sum())
            if not area:
                continue
            drawn += 1
            kept += appears(pred, label, tuple(box), area, KEPT)
    return drawn, kept


def editability(proc: Procedure, annotation: tuple[int, int] | None = None) -> dict:
    """What a person gets editing ``proc`` by its named parameters: whether ``floors`` and ``bays`` exist; whether
    + 1 of each adds exactly one row (column) of windows and keeps the columns (rows) (``*_plus_one``), and whether
    it is clean as a person looks at it (``*_clean``, with the reason where it is not). ``annotation``: the lattice
    of the annotation it reconstructs, for ``eligible``."""
    names = {p.name: p for p in named_parameters(proc)}
    rows, cols = lattice(flat_rows(proc))
    out = {"rows": rows, "columns": cols, "floors": "floors" in names, "bays": "bays" in names,
           "floors_plus_one": False, "bays_plus_one": False, "floors_clean": False, "bays_clean": False}
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
    for key, verdict in check_edits(proc).items():
        name, change = key[:-2], key[-2:]
        if change == "+1":
            out[f"{name}_clean"] = verdict.clean
            out[f"{name}_why"] = verdict.reason
        else:
            out[f"{name}_minus_clean"] = verdict.clean
    return out


def generated_edits(seeds: range) -> tuple[int, list[int], dict[int, dict]]:
    """`floors` + 1 and `bays` + 1 on the generated facades of ``seeds`` that have a lattice of windows (two rows
    and two columns at least, as a CMP facade is eligible), judged by `check_edits`: (how many had one, the seeds
    where both were clean, and for the others their verdicts by edit, None for an edit they cannot make)."""
    from facaid.editing.check import MORE
    from facaid.generator import generate_procedure

    eligible, clean, others = 0, [], {}
    for seed in seeds:
        proc = generate_procedure(seed)
        rows, columns = lattice(flat_rows(proc))
        if rows < 2 or columns < 2:
            continue
        eligible += 1
        verdicts = check_edits(proc, MORE)
        if len(verdicts) == 2 and all(v.clean for v in verdicts.values()):
            clean.append(seed)
        else:
            others[seed] = {f"{name}+1": verdicts.get(f"{name}+1") for name in ("floors", "bays")}
    return eligible, clean, others


__all__ = ["KEPT", "editability", "generated_edits", "kept_elements"]
