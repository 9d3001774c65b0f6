"""Every node instance of a procedure as it lays out: what a named parameter reads its value from and an edit
grows (`facaid.editing.parameters`)."""

from __future__ import annotations

import numpy as np

from facaid.grammar.layout import expand_over, layout
from facaid.grammar.nodes import Node
from facaid.grammar.procedure import Procedure

__all__ = ["Instances"]


class Instances:
    """Every node instance of a procedure: per node, its path, how many instances and the first one's extents."""

    def __init__(self, proc: Procedure):
        self.path: dict[int, str] = {}
        self.count: dict[int, int] = {}
        self.extent: dict[int, tuple[float, float]] = {}  # the first instance's
        self.extents: dict[int, list[tuple[float, float]]] = {}  # every instance's
        self.parent_axis: dict[int, str | None] = {}
        self.outer: dict[int, bool] = {}  # no ancestor with the same role
        # an exception's node is named by its own path (root/1/!0), as `Node.walk` names it, wherever it is laid out
        self.own = {id(n): p for p, n in proc.nodes() if "!" in p}
        self._visit(proc.root, "root", float(proc.width), float(proc.height), None, frozenset())

    def typical(self, key: int) -> tuple[float, float]:
        """The median extents of a node's instances: a floor's height is the floors' typical height, not the top
        floor's, which may have one of its own."""
        ws, hs = zip(*self.extents[key], strict=True)
        return float(np.median(ws)), float(np.median(hs))

    def _visit(self, node: Node, path: str, w: float, h: float, axis: str | None, roles: frozenset,
               pending: list | None = None) -> None:
        key = id(node)
        if key not in self.path:
            self.path[key], self.extent[key], self.parent_axis[key] = path, (w, h), axis
            self.outer[key] = node.role not in roles
        self.count[key] = self.count.get(key, 0) + 1
        self.extents.setdefault(key, []).append((w, h))
        if node.rule == "leaf":
            return
        length = w if node.axis == "x" else h
        sizes, children, _, below, _ = expand_over(node, length, pending)
        lengths = layout(sizes, length)
        inner = roles | {node.role} if node.role else roles
        n = len(node.children)
        for i, (child, extent) in enumerate(zip(children, lengths, strict=True)):
            cw, ch = (extent, h) if node.axis == "x" else (w, extent)
            replaced = id(child) in self.own and child is not node.children[i % n]  # an exception's node: its path
            child_path = self.own[id(child)] if replaced else f"{path}/{i % n}"
            self._visit(child, child_path, cw, ch, node.axis, inner, below[i] if below is not None else None)
