"""The lattice reader: a real facade's editable procedure, read top-down from its rows and columns of windows.

A person describes a facade as floors of tiles: "five floors of six windows, a shop floor below, the attic above, the
third window of the fourth floor has its blind closed". `read_lattice` reads a segmentation the same way (after
Müller et al. 2007, Riemenschneider et al. 2012 and Zhang et al. 2013), in three steps, the first in
`facaid.reading.grid`, the others in `facaid.reading.tiles`:

1. **The grid** (`read_grid`). Windows: connected window-or-blind regions of the building (the longest run of
   columns that are mostly not background: a neighbour's strip is left out), but for the strips a balcony or sill
   leaves uncovered (`facaid.reading.windows.whole_windows`); their rows and columns (`window_bands`: bands of
   centres split where the gap is over half the median window height, width; bands whose extents overlap are one;
   a column needs windows in `COLUMN_SUPPORT` of the floors). Floors: horizontal bands that each hold one row of
   windows with its companions, cut at one offset above their windows, the one whose cuts cross the most wall in
   all, whatever a cut crosses (floors as high as from a row of windows to the next, as a person measures them);
   the last rows whose bands hold doors or shops are the ground floor, its top where the wall is. A second reading
   cuts each floor where the label map is most wall, at the one offset only where the wall allows (`ALIGN`): a cut
   at the pitch may cross a balcony, and its new bay is then like no bay. Tiles: the columns within the floors,
   cut the second way; the side margins; the attic above.
2. **The typical floor and bay** (`read_floors`). The typical floor is a real one, the medoid of the floors; the
   typical bay the medoid column; the typical tile is where they cross (`facaid.reading.units`). The typical floor
   is that floor as it is: a row of typical tiles with its own cells' deltas, so that a new floor is a copy of it.
   A floor whose own typical tile (its medoid) and whose cell in the typical column both differ is a floor of its
   own tiles (the balcony floor), so that a new bay adds that cell there; the attic and the ground floor are rows
   of their own cells on the same columns, typical where the typical column's is (`_band`).
3. **Exceptions**: every other cell's deltas from what the typical floor lays out there, and the lengths of floors
   and columns off the median by more than `JITTER`. Nothing drawn is priced away.

So `floors` + 1 inserts a copy of the typical floor between the floors, and `bays` + 1 a copy of the typical
column. The result is an ordinary procedure: the pipeline sizes it (`facaid.sizing`) like any other structure.
"""

from __future__ import annotations

from collections.abc import Iterator

import numpy as np

from facaid.grammar.procedure import Procedure, ProcedureError
from facaid.labels import GLASS
from facaid.reading.grid import Grid, footprint, read_grid
from facaid.reading.tiles import read_floors
from facaid.reading.windows import whole_windows
from facaid.segmentation import Segmentation, flatten, rasterize, region_boxes


def read_lattice(seg: Segmentation, group: tuple[int, int] = (1, 1)) -> Procedure | None:
    """The editable procedure of a segmentation (see the module's docstring), or None where it has no lattice of
    windows (fewer than two rows or two columns). ``group``: (floors, bays) of the grid read as one (`grouped`)."""
    flat = flatten(seg)
    label_map = rasterize(flat)
    height, width = label_map.shape
    grid = grouped(_grid(flat, label_map), group)
    if grid is None:
        return None
    proc = Procedure(width, height, read_floors(grid), {"source": SOURCE})
    try:
        return Procedure.from_dict(proc.to_dict())
    except ProcedureError:  # a reading past the grammar's limits (more exceptions than a repeat holds): none
        return None


def readings(seg: Segmentation) -> Iterator[tuple[tuple[int, int], Procedure]]:
    """The candidate readings of a segmentation, each with its ``group``: the grid as read, and where they fit it,
    its floors read two by two (a floor with a mezzanine: two rows of windows) and its columns two by two (a bay of
    a pair of windows); each with its floors cut at their windows' pitch first, then (where they differ) where the
    wall is (`facaid.reading.grid.read_grid`): a cut at the pitch may cross a balcony whose new bay is then like no
    bay. The pipeline keeps the first whose edits pass and whose floor is the pitch, else the best of them."""
    flat = flatten(seg)
    label_map = rasterize(flat)
    windows = _windows(flat, label_map)
    grids = [read_grid(label_map, windows, pitch) for pitch in (True, False)]
    for group in GROUPS:
        seen = []
        for g in (grouped(grid, group) for grid in grids):
            if g is None or any(g.ys == other.ys and g.xs == other.xs for other in seen):
                continue
            seen.append(g)
            proc = Procedure(label_map.shape[1], label_map.shape[0], read_floors(g), {"source": SOURCE})
            try:
                yield group, Procedure.from_dict(proc.to_dict())
            except ProcedureError:
                continue


SOURCE = "facaid.reading.lattice"  # the meta of its procedures, as `facaid.reading.induce` names itself
GROUPS = ((1, 1), (2, 1), (1, 2))  # (floors, bays) read as one: the candidate readings


def grouped(grid: Grid | None, group: tuple[int, int]) -> Grid | None:
    """``grid`` with every ``group[0]`` floors one floor and every ``group[1]`` columns one bay, or None where the
    counts do not divide by them or fewer than two of either would be left."""
    if grid is None:
        return None
    (gy, gx), n, m = group, grid.rows, grid.columns
    if n % gy or m % gx or n // gy < 2 or m // gx < 2:
        return None
    return Grid(grid.label_map, grid.ys[::gy], grid.xs[::gx])


def _grid(flat: Segmentation, label_map: np.ndarray, pitch: bool = True) -> Grid | None:
    """The grid of a flattened segmentation's windows (`_windows`; ``pitch``: how the floors are cut,
    `facaid.reading.grid.read_grid`)."""
    return read_grid(label_map, _windows(flat, label_map), pitch)


def _windows(flat: Segmentation, label_map: np.ndarray) -> np.ndarray:
    """The windows of a flattened segmentation, but strips, within the main building's footprint."""
    fx0, fx1 = footprint(label_map)
    windows = whole_windows(region_boxes(flat.to_array(), GLASS))  # a strip of a window is no window of the lattice
    centres = (windows[:, 0] + windows[:, 2]) / 2
    return windows[(centres >= fx0) & (centres < fx1)]


__all__ = ["GROUPS", "grouped", "read_lattice", "readings"]
