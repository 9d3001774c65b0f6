"""Named parameters: the few figures a person thinks of a facade in, read off the tree's roles and set back into it.

A procedure's raw parameters are every size of every node (hundreds on a real facade). The named ones are: the
number of upper floors, the floor height, the ground floor and attic heights, the tiles (bays) per floor, the tile
width, the window width and height, the side margin (the wall between a row of tiles and the facade's edge), and the
facade's width and height. Each is found from the nodes' roles (`facaid.grammar.procedure.ROLES`)
and names the node paths it stands for, so that a page can link a parameter to its part of the picture.

Setting one edits the tree consistently: the tree is first *normalised* (every size becomes the length it lays out
to, so floating sizes hold their real pixel lengths; execution is unchanged), then the edited lengths or counts
change and every enclosing node and the image grow by what their contents grew, so that the other parts keep their
size: six floors of 80 px become seven, the facade is 80 px (and a floor's molding) taller, the ground floor stays.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field

from facaid.editing.floors import as_floors_repeat, plain_floor, unrepeated_floors
from facaid.editing.growth import grow
from facaid.editing.instances import Instances
from facaid.editing.resizing import copy_lengths, copy_procedure, repeat_unit, resize
from facaid.editing.rows import (
    aligned_rows,
    building_of,
    holds_door,
    open_wall,
    opening,
    step_cells,
    unmirrored,
    wall_rows,
)
from facaid.grammar.execute import first_boxes, parameter_lengths
from facaid.grammar.limits import MAX_COUNT, MAX_EXTENT
from facaid.grammar.nodes import Node, Size
from facaid.grammar.procedure import Procedure, ProcedureError, validate
from facaid.grammar.repeats import copies_moved, copies_where, most_typical, recount

__all__ = ["AXES", "NAMES", "Parameter", "named_parameters", "normalised", "set_parameter", "set_parameters"]

# name: (label, role, axis): the length (px) of the nodes of that role along the axis their parent splits
_LENGTHS = {
    "floor_height": ("floor height", "floor", "y"),
    "ground_height": ("ground floor height", "ground", "y"),
    "attic_height": ("attic height", "attic", "y"),
    "tile_width": ("tile (bay) width", "tile", "x"),
}
# name: (label, axis): the window units' (role window) width or height, whichever way their parent splits
_WINDOW = {"window_width": ("window width", "x"), "window_height": ("window height", "y")}
NAMES = ("floors", "floor_height", "ground_height", "attic_height", "bays", "tile_width", "window_width",
         "window_height", "margin", "width", "height")
# the axis each length is measured along (the counts have none)
AXES = {**{n: a for n, (_, _, a) in _LENGTHS.items()}, **{n: a for n, (_, a) in _WINDOW.items()}, "margin": "x",
        "width": "x", "height": "y"}


@dataclass
class Parameter:
    name: str
    label: str
    value: float
    unit: str  # "px" or "count"
    integer: bool
    min: float
    max: float
    nodes: list[str] = field(default_factory=list)  # the paths of the nodes it stands for

    def to_dict(self) -> dict:
        return asdict(self)


def _nodes(proc: Procedure) -> dict[str, Node]:
    return dict(proc.nodes())


def normalised(proc: Procedure) -> Procedure:
    """The same facade with every size set to the length it lays out to in the node's first instance (``rel``
    becomes ``abs``; ``flt`` keeps its mode with its real length as weight). Execution does not change."""
    out = Procedure(proc.width, proc.height, proc.root.copy(), dict(proc.meta))
    lengths = iter(parameter_lengths(out))

    def real(size: Size, fill: bool) -> Size:
        length = next(lengths)
        if fill or length is None:  # a fill repeat counts with its nominal sizes; an unused size stays
            return size
        return Size("flt" if size.mode == "flt" else "abs", round(length, 4))

    for _, node in out.nodes():  # in `Procedure.parameters` order: a node's sizes, then its exceptions'
        fill = node.count == "fill"
        node.sizes = [real(s, fill) for s in node.sizes]
        node.exceptions = [o._replace(size=real(o.size, False)) if o.size is not None else o
                           for o in node.exceptions]
    return out


def _floor_repeats(proc: Procedure, inst: Instances, role: str, axis: str) -> list[tuple[str, Node]]:
    """The repeats with a count along ``axis`` that lay out the outermost nodes of ``role`` (for each, the nearest
    such repeat above it), largest count first."""
    nodes = _nodes(proc)
    found: dict[str, Node] = {}
    for path, node in nodes.items():
        if node.role != role or not inst.outer.get(id(node)):
            continue
        parts = path.split("/")
        for k in range(len(parts) - 1, 0, -1):
            above = nodes["/".join(parts[:k])]
            if above.rule == "repeat" and above.axis == axis and above.count != "fill":
                found["/".join(parts[:k])] = above
                break
    return sorted(found.items(), key=lambda pn: -pn[1].count)


def _count_of(inst: Instances, proc: Procedure, role: str) -> tuple[int, list[str]]:
    nodes = [(p, n) for p, n in proc.nodes() if n.role == role and inst.outer.get(id(n))]
    return sum(inst.count[id(n)] for _, n in nodes), [p for p, _ in nodes]


def _bays(proc: Procedure, inst: Instances) -> tuple[int, list[str]] | None:
    """How many tiles the first floor that has any holds as laid out without exceptions (a copy that an exception
    replaces is still a tile of its row), and the paths of its outermost tile nodes."""
    for _, floor in proc.nodes():
        if floor.role not in ("floor", "ground") or not inst.outer.get(id(floor)):
            continue
        tiles = [(p, n) for p, n in floor.walk(inst.path[id(floor)])
                 if n.role == "tile" and "!" not in p[len(inst.path[id(floor)]):] and _outer_tile(floor, n)]
        if tiles:
            return _typical_tiles(floor), [p for p, _ in tiles]
    return None


def _outer_tile(floor: Node, tile: Node) -> bool:
    """Whether ``tile`` lies in no other tile of ``floor``'s typical copy."""
    def inside(node: Node, within: bool) -> bool | None:
        if node is tile:
            return not within
        for c in node.children:
            found = inside(c, within or node.role == "tile")
            if found is not None:
                return found
        return None
    return bool(inside(floor, False))


def _typical_tiles(node: Node) -> int:
    """The tiles under ``node`` as its typical copies lay them out: each repeat's count times its pattern's."""
    if node.role == "tile":
        return 1
    if node.rule == "leaf":
        return 0
    inner = [_typical_tiles(c) for c in node.children]
    if node.rule == "repeat":
        return sum(inner) * (node.count if node.count != "fill" else 1) + sum(inner[: node.tail])
    if node.rule == "mirror":
        return 2 * sum(inner) - (inner[-1] if node.center else 0)
    return sum(inner)


def _margins(proc: Procedure, inst: Instances) -> list[tuple[str, Node]]:
    """The side margins: the wall leaves that begin or end a split along x holding tiles (a row of bays between the
    facade's edges), outermost rows only, with their paths."""
    out = []
    for path, node in proc.nodes():
        if node.rule != "split" or node.axis != "x" or len(node.children) < 3 or not inst.outer.get(id(node)):
            continue
        inner = node.children[1:-1]
        if not any(n.role == "tile" for c in inner for _, n in c.walk()):
            continue
        for i in (0, len(node.children) - 1):
            c = node.children[i]
            if c.rule == "leaf" and c.label == "facade" and c.role is None and id(c) in inst.extent:
                out.append((f"{path}/{i}", c))
    return out


def _most_laid_out(inst: Instances, nodes: list[tuple[str, Node]]) -> Node:
    """Of these nodes, the one laid out most often (the first of those): whose size a parameter shows."""
    return max(nodes, key=lambda pn: inst.count[id(pn[1])])[1]


def named_parameters(proc: Procedure) -> list[Parameter]:
    """The named parameters this procedure has (those whose roles it holds), in `NAMES` order."""
    inst = Instances(proc)
    out: list[Parameter] = []
    floors, paths = _count_of(inst, proc, "floor")
    if floors:
        editable = bool(_floor_repeats(proc, inst, "floor", "y")) or unrepeated_floors(proc, inst) is not None
        out.append(Parameter("floors", "upper floors", floors, "count", True, floors if not editable else 1,
                             floors if not editable else MAX_COUNT, paths))
    for name, (label, role, axis) in _LENGTHS.items():
        nodes = [(p, n) for p, n in proc.nodes() if n.role == role and inst.outer.get(id(n))
                 and inst.parent_axis[id(n)] == axis]
        if nodes:  # the size of the most repeated (a floor's tile, not the attic's)
            w, h = inst.typical(id(_most_laid_out(inst, nodes)))
            out.append(Parameter(name, label, round(w if axis == "x" else h, 2), "px", False, 1.0, MAX_EXTENT,
                                 [p for p, _ in nodes]))
        if name == "ground_height" and (bays := _bays(proc, inst)):
            out.append(Parameter("bays", "tiles per floor", bays[0], "count", True, 1, MAX_COUNT, bays[1]))
    windows = [(p, n) for p, n in proc.nodes() if n.role == "window" and inst.outer.get(id(n))]
    for name, (label, axis) in _WINDOW.items():
        if windows:
            w, h = inst.extent[id(windows[0][1])]
            out.append(Parameter(name, label, round(w if axis == "x" else h, 2), "px", False, 1.0, MAX_EXTENT,
                                 [p for p, _ in windows]))
    if margins := _margins(proc, inst):
        out.append(Parameter("margin", "side margin", round(inst.extent[id(margins[0][1])][0], 2), "px", False, 0.0,
                             MAX_EXTENT, [p for p, _ in margins]))
    out.append(Parameter("width", "facade width", float(proc.width), "px", False, 8.0, MAX_EXTENT, ["root"]))
    out.append(Parameter("height", "facade height", float(proc.height), "px", False, 8.0, MAX_EXTENT, ["root"]))
    order = {n: i for i, n in enumerate(NAMES)}
    return sorted(out, key=lambda p: order[p.name])


def _along(nodes: dict[str, Node], path: str, axis: str) -> Node:
    """The node at ``path`` (in ``nodes``, a tree's nodes by path), or its nearest ancestor whose parent lays its
    children out along ``axis``: the part whose length along that axis is the node's."""
    while "/" in path and nodes[path.rsplit("/", 1)[0]].axis != axis:
        path = path.rsplit("/", 1)[0]
    return nodes[path]


def set_parameter(proc: Procedure, name: str, value: float) -> Procedure:
    """A new procedure with one named parameter set (see the module's docstring); raises `ValueError` naming the
    problem for an unknown name, a value out of range or a parameter this procedure cannot change."""
    params = {p.name: p for p in named_parameters(proc)}
    if name not in NAMES:
        raise ValueError(f"unknown parameter {name!r}; the named parameters are {', '.join(NAMES)}")
    if name not in params:
        have = ", ".join(params)
        raise ValueError(f"this procedure has no {name!r} (no node with its role); it has {have}")
    p = params[name]
    if not isinstance(value, int | float) or isinstance(value, bool) or value != value:
        raise ValueError(f"{name} must be a number, got {value!r}")
    if p.min == p.max and value != p.value:
        raise ValueError(f"{name} cannot change here: no repeat lays out them (edit the tree instead)")
    if p.integer and value != int(value):
        raise ValueError(f"{name} is a count: a whole number, got {value!r}")
    if not p.min <= value <= p.max:
        raise ValueError(f"{name} must be from {p.min:g} to {p.max:g}, got {value:g}")
    if value == p.value:  # set to what it is: the same tree (a save of it makes no version)
        return copy_procedure(proc)
    if name in ("width", "height"):
        return resize(proc, value if name == "width" else proc.width, value if name == "height" else proc.height)
    out = normalised(proc)
    if name == "bays":  # a row mirrored around its centre bay as the repeat it draws, so that it takes one bay
        out = unmirrored(out)
    inst = Instances(out)
    nodes = _nodes(out)
    if name in _LENGTHS or name in _WINDOW or name == "margin":
        axis = AXES[name]
        if name in _WINDOW:  # windows of other sizes (the ground floor's, a dormer) change by as much, each
            # through the part that holds it along the axis (a window in a column split along y: the column), so
            # that a narrower window makes a narrower column, not a column as wide as its widest part
            grow(out, axis, {id(_along(nodes, path, axis)): value - p.value for path in p.nodes})
        else:
            side = 0 if axis == "x" else 1
            grow(out, axis, {id(n): value - inst.typical(id(n))[side] for n in (nodes[path] for path in p.nodes)
                              if id(n) in inst.extent})  # a node an exception replaces everywhere has no length
    else:
        role, axis = ("floor", "y") if name == "floors" else ("tile", "x")
        if name == "bays":  # every row of tiles, scaled in proportion
            repeats = [(pth, n) for pth, n in out.nodes() if n.rule == "repeat" and n.axis == "x"
                       and n.count != "fill" and any(c.role == "tile" for c in n.children)]
        else:
            if not _floor_repeats(out, inst, role, axis) and (run := unrepeated_floors(out, inst)) is not None:
                as_floors_repeat(*run, inst)  # floors laid out one by one: the repeat they are, to take one more
                inst = Instances(out)
            repeats = _floor_repeats(out, inst, role, axis)[:1]
        if not repeats and int(value) != int(p.value):
            raise ValueError(f"{name} cannot change here: no repeat lays out the {role}s (edit the tree instead)")
        own: dict[int, float] = {}
        change = int(value) - int(p.value)
        # the building whose bays the parameter counts (a wing keeps its own)
        building = building_of(out, p.nodes[0]) if name == "bays" and p.nodes else "root/"
        repeats = [(pth, n) for pth, n in repeats if f"{pth}/".startswith(building)]
        # rows of tiles of one count stay in step: their new tiles go where the most laid-out row's go
        main = max((n for _, n in repeats if id(n) in inst.extent), key=lambda n: inst.count[id(n)], default=None)
        main_node, boxes = main, first_boxes(out)
        source, before = None, False
        if name == "floors" and repeats and id(repeats[0][1]) in inst.extent:  # a floor more repeats, a floor
            # fewer takes, of the floors the door reaches into none of (`plain_floor`)
            source = plain_floor(out, repeats[0][1], inst, fewer=change < 0)
        ground = {id(n) for _, g in out.nodes() if g.role == "ground" for _, n in g.walk()}
        aligned: list[tuple[Node, int]] = []
        gap = None
        if main is not None:  # as it is before any row changes; a new bay repeats its most typical column
            if name == "bays":
                # a row of as many copies as long under the bays (the ground floor's shops) keeps in step too
                width = inst.extent[id(main)][0]
                repeats += [(pth, n) for pth, n in out.nodes() if n.rule == "repeat" and n.axis == "x"
                            and n.count == main.count and f"{pth}/".startswith(building) and "!" not in pth
                            and id(n) in inst.extent and abs(inst.extent[id(n)][0] - width) <= 2.0
                            and all(n is not m for _, m in repeats)]
                stepped = tuple(n for _, n in repeats if n.count == main.count)
                doors = copies_where(out.root, main, stepped, lambda n: holds_door([n]))
                source = most_typical(out.root, main, stepped, doors)
                # a new bay beside the door's column goes on the side the door does not reach into
                before = source is not None and source in doors and source + 1 in doors
                aligned = aligned_rows(out, inst.extent, boxes, main, building)
            main = Node("repeat", count=main.count, children=list(main.children), exceptions=list(main.exceptions))
            if name == "bays" and 1 <= main.count + change <= MAX_COUNT and id(main_node) in boxes:
                step = copies_moved(main, main.count + change, source, before)
                gap = opening(main_node, inst.extent[id(main_node)][0], boxes[id(main_node)][0], step)
        if name == "bays" and not p.value:
            raise ValueError("bays cannot change here: no floor holds its tiles (edit the tree instead)")
        for _, node in repeats:
            if id(node) not in inst.extent:  # a row an exception replaces wherever it would be laid out
                continue
            delta = change
            if name == "bays":  # rows of other tiles change in proportion (3 attic tiles over 7 bays: +1 bay is
                # +0.43 of theirs, so none: they widen with the facade, as they would with a tile of their own)
                delta = round(change * node.count / p.value)
                if delta == 0:
                    continue
            new = node.count + delta
            if not 1 <= new <= MAX_COUNT:
                raise ValueError(f"{name} {value:g} needs a repeat of {new} copies (1 to {MAX_COUNT})")
            length = inst.extent[id(node)][0 if axis == "x" else 1]
            in_step = main is not None and main.count == node.count and name == "bays"
            moved = (copies_moved(main, new, source, before) if in_step
                     else copies_moved(node, new, source) if name == "floors" else copies_moved(node, new))
            # every row's new tile is the source column's cell, the ground floor's its typical shop; a new floor
            # is a copy of the source floor. The facade grows by the new copies, each as long as what it copies, or
            # shrinks by the copies taken out, each as long as it was
            copied = source if in_step or name == "floors" else None
            lengths = copy_lengths(node, length)
            mine = copied is not None and id(node) not in ground and any(o.copy == copied for o in node.exceptions)
            own[id(node)] = (delta * (lengths[copied] if mine else repeat_unit(node, length)[0]) if delta > 0
                             else -sum(lengths[c] for c in range(node.count) if c not in moved))
            recount(out.root, node, new, moved, copied, id(node) not in ground)
        if own and gap is not None:
            # rows written out cell by cell under the bays (a ground floor of shops) take a cell in step; rows of
            # their own over the bays (an attic's dormers) open their wall where the new bay goes
            for row, offset in aligned:
                own[id(row)] = step_cells(row, offset, inst.extent[id(row)][0], main, step, source)
            at, width = gap
            for row in wall_rows(out, inst.extent, boxes, main_node, building, own):
                if (grown := open_wall(row, inst.extent[id(row)][0], boxes[id(row)][0], at, width)) is not None:
                    own[id(row)] = grown
        if not own and change:
            raise ValueError(f"{name} cannot be {value:g} here: no row of {role}s takes {change:+d} (a mirrored row "
                             f"changes by two)")
        grow(out, axis, own, shrink=change < 0)
    try:
        validate(out)
    except ProcedureError as exc:
        raise ValueError(f"{name} {value:g} makes an invalid procedure: {exc}") from None
    return out


def set_parameters(proc: Procedure, values: dict[str, float]) -> Procedure:
    """Several named parameters, set one after the other in `NAMES` order (counts before lengths)."""
    unknown = sorted(set(values) - set(NAMES))
    if unknown:
        raise ValueError(f"unknown parameter(s) {', '.join(unknown)}; the named parameters are {', '.join(NAMES)}")
    for name in NAMES:
        if name in values:
            proc = set_parameter(proc, name, values[name])
    return proc
