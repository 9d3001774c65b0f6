"""The numeric executor: the reference semantics of the grammar, in plain Python floats.

`execute` returns the leaf rectangles (a partition of the image) in depth-first order. The differentiable
executor in `facaid.grammar.differentiable` computes the same boxes with torch and is checked against this one.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from facaid.grammar.layout import expand_over, layout
from facaid.grammar.limits import MAX_COUNT
from facaid.grammar.nodes import Node
from facaid.grammar.procedure import MAX_LEAVES, Procedure, ProcedureError
from facaid.labels import BACKGROUND, LABEL_ID
from facaid.native.rects import executed_rows
from facaid.segmentation import Segmentation, flatten_array, rasterize


@dataclass
class Trace:
    """What the differentiable executor needs: one record per node instance, depth-first."""

    depth: list[int] = field(default_factory=list)
    parent: list[int] = field(default_factory=list)  # instance index of the parent, -1 for the root
    param: list[int] = field(default_factory=list)  # index of the size in Procedure.parameters(), -1 at root
    mode: list[str] = field(default_factory=list)
    axis: list[str] = field(default_factory=list)  # the axis the parent splits along
    flip: list[bool] = field(default_factory=list)  # laid out from the far end (inside a reflection)
    leaves: list[int] = field(default_factory=list)  # instance indices of the leaves, depth-first
    extent: list[float] = field(default_factory=list)  # the length the instance lays out to along its parent's axis


def spans(lo: float, hi: float, lengths: list[float], flip: bool) -> list[tuple[float, float]]:
    """Where children of these lengths lie in [lo, hi) along their parent's axis, as (start, end) in child order:
    from ``lo`` up, or from ``hi`` down when ``flip`` (inside a reflection); the last child ends exactly at the far
    end, so that rounding never leaves a gap."""
    out = []
    last = len(lengths) - 1
    if flip:
        pos = hi
        for i, length in enumerate(lengths):
            a = lo if i == last else pos - length
            out.append((a, pos))
            pos = a
    else:
        pos = lo
        for i, length in enumerate(lengths):
            b = hi if i == last else pos + length
            out.append((pos, b))
            pos = b
    return out


class _Executor:
    def __init__(self, proc: Procedure, trace: Trace | None):
        self.out: list[tuple[int, float, float, float, float]] = []
        self.trace = trace
        self.layouts: dict[tuple[int, float], tuple] = {}  # repeated copies share their layout
        self.fill_counts: dict[int, int] = {}
        self.first_boxes: dict[int, tuple[float, float, float, float]] | None = None  # set to record them
        self.leaf_nodes: list[Node] | None = None  # set to record the node of each leaf
        self.offsets: dict[int, int] = {}  # id(node) or id(override) -> its first parameter
        if trace is not None:
            k = 0
            for _, node in proc.root.walk():  # in `Procedure.parameters` order
                self.offsets[id(node)] = k
                k += len(node.sizes)
                for o in node.exceptions:
                    if o.size is not None:
                        self.offsets[id(o)] = k
                        k += 1

    def run(self, node: Node, box: tuple[float, float, float, float], flips: tuple[bool, bool],
            where: tuple, me: int, pending: list | None = None) -> None:
        # ``where`` is (parent's where, child index): the node path, formatted only for an error; ``pending``: the
        # exceptions of repeats above that reach into this instance (`layout.expand_over`)
        if self.first_boxes is not None:
            self.first_boxes.setdefault(id(node), box)
        if node.rule == "leaf":
            self.leaf(node, box, where, me)
            return
        x0, y0, x1, y1 = box
        along_x = node.axis == "x"
        lo, hi = (x0, x1) if along_x else (y0, y1)
        key = (id(node), hi - lo)
        cached = self.layouts.get(key) if pending is None else None
        if cached is None:
            sizes, children, reflected, below, sources = expand_over(node, hi - lo, pending)
            cached = (sizes, children, reflected, layout(sizes, hi - lo), below, sources)
            if pending is None:  # an instance that exceptions from above reach into is its own
                self.layouts[key] = cached
        sizes, children, reflected, lengths, below, sources = cached
        if node.count == "fill":
            self.fill_counts[id(node)] = (len(children) - node.tail) // len(node.children)
        flip = flips[0] if along_x else flips[1]
        mirrored = (not flips[0], flips[1]) if along_x else (flips[0], not flips[1])
        trace = self.trace
        pidx = self._param_indices(node, len(sizes)) if trace is not None else None
        n_pattern = len(node.children)
        out = self.out
        for i, (child, (a, b)) in enumerate(zip(children, spans(lo, hi, lengths, flip), strict=True)):
            sub = (a, y0, b, y1) if along_x else (x0, a, x1, b)
            child_id = -1
            if trace is not None:
                child_id = len(trace.depth)
                trace.depth.append(trace.depth[me] + 1)
                trace.parent.append(me)
                source = sources[i] if sources is not None else None
                trace.param.append(self.offsets[id(node)] + pidx[i] if source is None else self.offsets[id(source[1])])
                trace.mode.append(sizes[i].mode)
                trace.axis.append(node.axis)
                trace.flip.append(flip)
                trace.extent.append(b - a)
            if child.rule == "leaf" and self.first_boxes is None and self.leaf_nodes is None:  # most are: no call
                if trace is None and len(out) < MAX_LEAVES:
                    out.append((LABEL_ID[child.label], *sub))
                else:
                    self.leaf(child, sub, (where, i % n_pattern), child_id)
            else:
                self.run(child, sub, mirrored if reflected[i] else flips, (where, i % n_pattern), child_id,
                         below[i] if below is not None else None)

    def leaf(self, node: Node, box: tuple[float, float, float, float], where: tuple, me: int) -> None:
        if len(self.out) >= MAX_LEAVES:
            raise ProcedureError(_path(where), f"expands to more than {MAX_LEAVES} rectangles")
        self.out.append((LABEL_ID[node.label], *box))
        if self.leaf_nodes is not None:
            self.leaf_nodes.append(node)
        if self.trace is not None:
            self.trace.leaves.append(me)

    @staticmethod
    def _param_indices(node: Node, n: int) -> list[int]:
        """For each expanded child, the index of its size among the node's own sizes."""
        k = len(node.sizes)
        if node.rule == "mirror":
            return list(range(k)) + list(range(k - (2 if node.center else 1), -1, -1))
        return [i % k for i in range(n)]  # a repeat's copies share the pattern's sizes


def _path(where: tuple) -> str:
    parts = []
    while where:
        where, i = where
        parts.append(str(i))
    return "/".join(["root", *reversed(parts)])


def execute(proc: Procedure, trace: Trace | None = None) -> list[tuple[int, float, float, float, float]]:
    """Execute a procedure: its leaves as (label_id, x0, y0, x1, y1) floats, depth-first.

    The leaves partition the image [0, width) x [0, height); some may be empty (zero length).
    """
    ex = _Executor(proc, trace)
    if trace is not None:
        trace.depth.append(0)
        trace.parent.append(-1)
        trace.param.append(-1)
        trace.mode.append("")
        trace.axis.append("")
        trace.flip.append(False)
        trace.extent.append(0.0)
    ex.run(proc.root, (0.0, 0.0, float(proc.width), float(proc.height)), (False, False), (), 0)
    return ex.out


def parameter_lengths(proc: Procedure) -> list[float | None]:
    """For each parameter (`Procedure.parameters` order), the length its first instance lays out to, depth-first;
    None for a size no instance uses."""
    trace = Trace()
    execute(proc, trace)
    out: list[float | None] = [None] * len(proc.parameters())
    for param, extent in zip(trace.param[1:], trace.extent[1:], strict=True):
        if out[param] is None:
            out[param] = extent
    return out


def fill_counts(proc: Procedure) -> dict[int, int]:
    """The count each ``"fill"`` repeat resolves to, keyed by ``id(node)`` (the last copy's, if it occurs in
    regions of several lengths)."""
    ex = _Executor(proc, None)
    ex.run(proc.root, (0.0, 0.0, float(proc.width), float(proc.height)), (False, False), (), 0)
    return ex.fill_counts


def first_boxes(proc: Procedure) -> dict[int, tuple[float, float, float, float]]:
    """The box of the first instance of every node, keyed by ``id(node)``. Each node is visited once, where it
    first occurs depth-first: the later copies of a repeat or mirror are skipped with their subtrees, whose first
    instances all came before them (the boxes are those `execute_with_boxes` records, placed by the same `spans`)."""
    seen: dict[int, tuple[float, float, float, float]] = {}

    def visit(node: Node, box: tuple[float, float, float, float], flip_x: bool, flip_y: bool,
              pending: list | None = None) -> None:
        seen.setdefault(id(node), box)
        x0, y0, x1, y1 = box
        along_x = node.axis == "x"
        lo, hi = (x0, x1) if along_x else (y0, y1)
        sizes, children, reflected, below, _ = expand_over(node, hi - lo, pending)
        lengths = layout(sizes, hi - lo)
        for i, (child, (a, b)) in enumerate(zip(children, spans(lo, hi, lengths, flip_x if along_x else flip_y),
                                                strict=True)):
            deeper = below[i] if below is not None else None
            if id(child) in seen and deeper is None:  # an exception below a copy may hold nodes not seen yet
                continue
            sub = (a, y0, b, y1) if along_x else (x0, a, x1, b)
            if child.rule == "leaf":
                seen[id(child)] = sub
            elif reflected[i]:
                visit(child, sub, flip_x != along_x, flip_y == along_x, deeper)
            else:
                visit(child, sub, flip_x, flip_y, deeper)

    box = (0.0, 0.0, float(proc.width), float(proc.height))
    if proc.root.rule == "leaf":
        return {id(proc.root): box}
    visit(proc.root, box, False, False)
    return seen


def execute_with_boxes(proc: Procedure) -> tuple[list[tuple[int, float, float, float, float]],
                                                 dict[int, tuple[float, float, float, float]]]:
    """`execute` and `first_boxes` in one pass."""
    ex = _Executor(proc, None)
    ex.first_boxes = {}
    ex.run(proc.root, (0.0, 0.0, float(proc.width), float(proc.height)), (False, False), (), 0)
    return ex.out, ex.first_boxes


def execute_with_nodes(proc: Procedure) -> tuple[list[tuple[int, float, float, float, float]], list[Node]]:
    """`execute`, and the node each leaf is (the same node for every copy of a repeated one)."""
    ex = _Executor(proc, None)
    ex.leaf_nodes = []
    ex.run(proc.root, (0.0, 0.0, float(proc.width), float(proc.height)), (False, False), (), 0)
    return ex.out, ex.leaf_nodes


def leaf_rows(proc: Procedure, leaves: list[tuple[int, float, float, float, float]]) -> tuple[np.ndarray, np.ndarray]:
    """`leaf_array`'s rows and, for each, the index of its leaf in ``leaves``."""
    w, h = round(proc.width), round(proc.height)
    arr = np.array(leaves, dtype=np.float64).reshape(-1, 5)
    index = np.flatnonzero(arr[:, 0] != BACKGROUND)
    box = np.rint(arr[index, 1:]).astype(np.int64)  # half to even, like round()
    np.clip(box, 0, [w, h, w, h], out=box)
    keep = (box[:, 0] < box[:, 2]) & (box[:, 1] < box[:, 3])
    return np.concatenate([arr[index[keep], :1].astype(np.int64), box[keep]], axis=1), index[keep]


def leaf_array(proc: Procedure, leaves: list[tuple[int, float, float, float, float]] | None = None
               ) -> np.ndarray:
    """The executed leaves rounded to whole pixels as int64 rows (label, x0, y0, x1, y1); background and empty
    leaves are dropped.

    Edges are rounded, not sizes, so neighbours that share an edge keep sharing it and nothing overlaps.
    """
    return leaf_rows(proc, execute(proc) if leaves is None else leaves)[0]


def flat_rows(proc: Procedure) -> np.ndarray:
    """The executed procedure flattened: ``flatten_array(w, h, leaf_array(proc))``, the rows of `to_segmentation`.
    In one call of C (`facaid.native.rects`) where the library builds; else, or when the C declines the tree, in
    Python, which also raises `ProcedureError` for a tree that expands to too much."""
    rows = executed_rows(proc.root, (proc.width, proc.height), MAX_COUNT, MAX_LEAVES)
    return flatten_array(round(proc.width), round(proc.height), leaf_array(proc)) if rows is None else rows


def label_map(proc: Procedure, rows: np.ndarray | None = None) -> np.ndarray:
    """The procedure's label map at full resolution, flattened as a person's annotation is (its `flat_rows`, or
    ``rows`` where they are at hand)."""
    rows = flat_rows(proc) if rows is None else rows
    return rasterize(Segmentation.from_array(round(proc.width), round(proc.height), rows))


def to_segmentation(proc: Procedure, leaves: list[tuple[int, float, float, float, float]] | None = None
                    ) -> Segmentation:
    """The executed procedure as a segmentation (see `leaf_array`)."""
    return Segmentation.from_array(round(proc.width), round(proc.height), leaf_array(proc, leaves))
