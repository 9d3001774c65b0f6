"""A segmentation as a person annotates it, for the annotation formats (COCO, LabelMe, CVAT): one box per element.

The rectangles a procedure draws (`facaid.grammar.execute.to_segmentation`) tile the image: the wall in pieces
around every element, and an element that spans several tiles (a cornice along a floor, a molding) in one piece per
tile. Annotation tools and the people who read their files expect what an annotator draws (`as_annotated`):

- **each element one box**: pieces of one label that touch along a whole edge are merged, again and again, until
  none do (`merge_pieces`); pieces that do not make a rectangle together (an L-shaped cornice) stay as few boxes
  as that finds;
- **the wall under its elements** (`as_drawn`): one rectangle per block of the building, what is not background
  in the fewest rectangles a row-by-row merge finds (a stepped outline: one per step).

Both keep the label map: the elements paint over the wall (`facaid.labels.PRIORITY`).
"""

from __future__ import annotations

from collections import defaultdict

import numpy as np

from facaid.labels import LABEL_ID
from facaid.segmentation import Rect, Segmentation, rasterize


def merge_pieces(rects: list[Rect]) -> list[Rect]:
    """``rects`` with every two of one label that touch along a whole edge (the same top and bottom, one's right
    edge the other's left; or the same across) merged, until no two do."""
    out = list(rects)
    changed = True
    while changed:
        changed = False
        for along_x in (True, False):
            lines: dict[tuple, list[Rect]] = defaultdict(list)
            for r in out:
                lines[(r.label, r.y0, r.y1) if along_x else (r.label, r.x0, r.x1)].append(r)
            merged: list[Rect] = []
            for line in lines.values():
                line.sort(key=lambda r: r.x0 if along_x else r.y0)
                run = line[0]
                for r in line[1:]:
                    if along_x and r.x0 == run.x1:
                        run, changed = Rect(run.label, run.x0, run.y0, r.x1, run.y1), True
                    elif not along_x and r.y0 == run.y1:
                        run, changed = Rect(run.label, run.x0, run.y0, run.x1, r.y1), True
                    else:
                        merged.append(run)
                        run = r
                merged.append(run)
            out = merged
    return sorted(out, key=lambda r: (r.y0, r.x0, r.label))


def as_drawn(seg: Segmentation) -> Segmentation:
    """The segmentation as a person draws it: the wall as one rectangle per block of the building (what is not
    background, in the fewest rectangles a row-by-row merge finds) under its elements, where a flattened
    segmentation (a generated facade's) has it in pieces around each element. Its label map is the same."""
    built = rasterize(seg) != LABEL_ID["background"]
    walls: list[Rect] = []
    open_runs: dict[tuple[int, int], int] = {}  # (x0, x1) of a run of building pixels -> the row its block began
    for y in range(seg.height + 1):
        runs = set()
        if y < seg.height:
            row = np.concatenate([[False], built[y], [False]])
            edges = np.flatnonzero(row[1:] != row[:-1])
            runs = {(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2], strict=True)}
        for run in [r for r in open_runs if r not in runs]:
            walls.append(Rect(LABEL_ID["facade"], run[0], open_runs.pop(run), run[1], y))
        for run in runs - open_runs.keys():
            open_runs[run] = y
    elements = tuple(r for r in seg.rects if r.label != LABEL_ID["facade"])
    return Segmentation(seg.width, seg.height, (*walls, *elements))


def as_annotated(seg: Segmentation) -> Segmentation:
    """The segmentation as an annotator draws it (see the module's docstring): the same label map in the fewest boxes
    the merges find, the wall under its elements."""
    drawn = as_drawn(seg)
    walls = [r for r in drawn.rects if r.label == LABEL_ID["facade"]]
    elements = merge_pieces([r for r in drawn.rects if r.label != LABEL_ID["facade"]])
    return Segmentation(seg.width, seg.height, (*walls, *elements))


def written_as(seg: Segmentation, fmt: str) -> Segmentation:
    """A procedure's rectangles as a file of ``fmt`` holds them: an annotation tool's (COCO, LabelMe, CVAT) one box
    per element (`as_annotated`), our own contract (``"segmentation"``) the exact pieces."""
    return seg if fmt == "segmentation" else as_annotated(seg)
