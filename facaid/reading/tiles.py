"""Steps 2 and 3 of the lattice reader (`facaid.reading.lattice`): the typical floor and bay of a grid, real ones,
and every other cell's deltas from them.

The typical floor is the medoid of the floors, the typical bay the medoid column; the typical tile is where they
cross (`facaid.reading.units`). The typical floor is that floor as it is: a row of typical tiles with its own cells'
deltas, so that a new floor is a copy of it. A floor whose own typical tile and whose cell in the typical column both
differ is a floor of its own tiles (the balcony floor); the attic and the ground floor are rows of their own cells on
the same columns (`_band`). Every other cell is its deltas from what the typical floor lays out there, and the
lengths of floors and columns off the median by more than `JITTER` are their own. Nothing drawn is priced away.
"""

from __future__ import annotations

import numpy as np

from facaid.grammar.nodes import Node, Override, Size
from facaid.labels import LABEL_ID
from facaid.reading.grid import Grid
from facaid.reading.units import Delta, Deltas, Unit, exact_tree, medoid, resample

JITTER = 0.08  # a floor or column length off the median by more than this share is its own
DOOR = LABEL_ID["door"]


def read_floors(grid: Grid) -> Node:
    """The building as attic, the floors repeat with its exceptions,
    and the ground floor."""
    label_map = grid.label_map
    height, width = label_map.shape
    ys, xs, n_rows, n_cols = grid.ys, grid.xs, grid.rows, grid.columns
    deltas = Deltas(height * width)
    th, tw = int(round(np.median(grid.heights))), int(round(np.median(grid.widths)))
    same = [[resample(grid.cell(i, j), th, tw) for j in range(n_cols)] for i in range(n_rows)]
    floor = medoid(same)  # the typical floor: a real one
    bay = medoid([[same[i][j] for i in range(n_rows)] for j in range(n_cols)])  # the typical column
    th, tw = int(grid.heights[floor]), int(grid.widths[bay])  # a new floor (bay) is as high (wide) as the typical
    tile = Unit(grid.cell(floor, bay), th, tw)
    # the typical floor as it is: typical tiles, and its own cells' deltas (on its row of tiles, so that a new floor
    # has them too); what it lays out in each column is what the other floors' deltas are read against
    own = [deltas.of(tile, grid.cell(floor, j), relabel=False) for j in range(n_cols)]
    row = _row(tile, own, grid.widths, bay)
    laid = [Unit(grid.cell(floor, j), *grid.cell(floor, j).shape) if own[j] else tile for j in range(n_cols)]
    margins = [Unit(label_map[ys[floor] : ys[floor + 1], a:b], th, b - a) if b > a else None
               for a, b in ((0, xs[0]), (xs[-1], width))]
    items: list[tuple[Size, Node]] = []
    if margins[0] is not None:
        items.append((Size("abs", float(xs[0])), margins[0].tree))
    bay_index = len(items)
    items.append((Size("flt", float(xs[-1] - xs[0])), row))
    if margins[1] is not None:
        items.append((Size("abs", float(width - xs[-1])), margins[1].tree))
    typical = Node.split("x", items, role="floor") if len(items) > 1 else _role(row, "floor")
    inside = (0, bay_index) if len(items) > 1 else (0,)
    floors = Node.repeat("y", n_rows, [(Size("flt", float(th)), typical)], role="floors")
    for i in range(n_rows):
        if i == floor:
            continue
        mine = medoid([[cell] for cell in same[i]])  # the floor's own typical tile
        if all(any(node is not None for _, _, node in deltas.of(tile, grid.cell(i, j))) for j in {bay, mine}):
            # its tiles differ alike (the balcony floor), in the typical column too: a floor of its own tiles, the
            # typical column's its typical one, so that a new bay adds that column's cell to it
            unit = Unit(grid.cell(i, bay), th, tw)
            variant = _row(unit, [deltas.of(unit, grid.cell(i, j)) for j in range(n_cols)], grid.widths, bay)
            floors.exceptions.append(Override(i, inside, node=variant))
        else:
            floors.exceptions += [Override(i, (*inside, j, *path), size, node) for j in range(n_cols)
                                  for path, size, node in deltas.of(laid[j], grid.cell(i, j))]
        for m, (unit, (a, b)) in enumerate(zip(margins, ((0, xs[0]), (xs[-1], width)), strict=True)):
            if unit is not None:
                where = (0, 0 if m == 0 else len(items) - 1)
                floors.exceptions += [Override(i, (*where, *path), size, node)
                                      for path, size, node in deltas.of(unit, label_map[ys[i] : ys[i + 1], a:b])]
    floors.exceptions += [Override(i, (0,), size=Size("flt", float(h))) for i, h in enumerate(grid.heights)
                          if abs(h / th - 1) > JITTER]
    floors.exceptions = _merge_paths(floors.exceptions)
    parts: list[tuple[Size, Node]] = []
    if ys[0] > 0:
        parts.append((Size("abs", float(ys[0])), _band(label_map[: ys[0]], xs, bay, grid.widths, "attic", deltas)))
    parts.append((Size("flt", float(ys[-1] - ys[0])), floors))
    if ys[-1] < height:
        parts.append((Size("abs", float(height - ys[-1])),
                      _band(label_map[ys[-1] :], xs, bay, grid.widths, "ground", deltas)))
    return Node.split("y", parts, role="facade") if len(parts) > 1 else floors


def _row(unit: Unit, cells: list[list[Delta]], widths: np.ndarray, bay: int) -> Node:
    """A row of tiles: a repeat of ``unit`` as wide as the typical column ``bay``, with each cell's deltas from it
    and the columns' own widths where they are off that by more than `JITTER`."""
    row = Node.repeat("x", len(cells), [(Size("flt", float(widths[bay])), _role(unit.tree.copy(), "tile"))],
                      role="bay")
    for j, cell in enumerate(cells):
        row.exceptions += [Override(j, (0, *path), size, node) for path, size, node in cell]
    own = [Override(j, (0,), size=Size("flt", float(w))) for j, w in enumerate(widths)
           if abs(w / widths[bay] - 1) > JITTER]
    row.exceptions = _merge_paths(row.exceptions + own)
    return row


def _band(label_map: np.ndarray, xs: list[int], bay: int, tile_w: np.ndarray, role: str, deltas: Deltas) -> Node:
    """The attic or the ground floor on the floors' columns: its margins exact, and between them a row of its own
    cells, the typical column's as its typical tile and each other cell its deltas from it, so that a bay more adds
    the typical column's cell here too and the shops and doors stay over their columns."""
    height, width = label_map.shape
    if height < 2:
        return _role(exact_tree(label_map), role)
    cells = [label_map[:, xs[j] : xs[j + 1]] for j in range(len(xs) - 1)]
    unit = Unit(cells[_typical_cell(cells, bay, int(tile_w[bay]))], height, int(tile_w[bay]))
    row = _row(unit, [deltas.of(unit, cell) for cell in cells], tile_w, bay)
    items: list[tuple[Size, Node]] = []
    if xs[0] > 0:
        items.append((Size("abs", float(xs[0])), exact_tree(label_map[:, : xs[0]])))
    items.append((Size("flt", float(xs[-1] - xs[0])), row))
    if xs[-1] < width:
        items.append((Size("abs", float(width - xs[-1])), exact_tree(label_map[:, xs[-1] :])))
    return Node.split("x", items, role=role) if len(items) > 1 else _role(row, role)


def _typical_cell(cells: list[np.ndarray], bay: int, width: int) -> int:
    """The cell of a band that a new bay repeats: the typical column's, but where it holds a door and others do
    not, the medoid of those without (a new bay beside the entrance is another shop, not a second door)."""
    plain = [j for j, cell in enumerate(cells) if not (cell == DOOR).any()]
    if not plain or len(plain) == len(cells) or bay in plain:
        return bay
    return plain[medoid([[resample(cells[j], cells[j].shape[0], width)] for j in plain])]


def _merge_paths(deltas: list[Override]) -> list[Override]:
    """One override per (copy, path): a size and a node at the same place become one."""
    out: dict[tuple, Override] = {}
    for o in deltas:
        key = (o.copy, o.path)
        if key in out:
            prev = out[key]
            o = Override(o.copy, o.path, o.size or prev.size, o.node or prev.node)
        out[key] = o
    return list(out.values())


def _role(node: Node, role: str) -> Node:
    """``node`` with ``role``; a leaf keeps its own (a role on a leaf names it), so it goes on a one-child split."""
    if node.rule == "leaf":
        return Node.split("y", [(Size("flt", 1.0), node)], role=role)
    node.role = role
    return node


__all__ = ["JITTER", "read_floors"]
