"""The nodes of a procedure's derivation tree: `Node` (a leaf or a split, repeat or mirror of sized children),
the `Size` of a child and the `Override` of one copy of a repeat (`facaid.grammar.procedure` has the format)."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any, NamedTuple

__all__ = ["Node", "Override", "Size"]


class Override(NamedTuple):
    """One exception of a repeat: in copy ``copy`` (0-based; ``copy == count`` names the tail), the node reached by
    ``path`` (the pattern item, then the index of each expanded child below it, as `layout.expand` lays them out)
    takes the size ``size`` and/or is replaced by ``node``. An override of a copy that a ``"fill"`` repeat does not
    lay out at its length has no effect, like CGA's ``case split.index == k`` with fewer parts."""

    copy: int
    path: tuple[int, ...]
    size: Size | None = None
    node: Node | None = None

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {"copy": self.copy, "path": list(self.path)}
        if self.size is not None:
            out["size"] = [self.size.mode, self.size.value]
        if self.node is not None:
            out["node"] = self.node.to_dict()
        return out


class Size(NamedTuple):
    """A child's size along its parent's axis. A named tuple, not a dataclass: the generator makes some 170 a
    facade, and a tuple is made in two thirds of a frozen dataclass's time."""

    mode: str  # one of MODES
    value: float


@dataclass(slots=True)
class Node:
    rule: str
    label: str | None = None  # leaf only
    axis: str | None = None  # inner nodes
    sizes: list[Size] = field(default_factory=list)
    children: list[Node] = field(default_factory=list)
    count: int | str | None = None  # repeat only: int or "fill"
    tail: int = 0  # repeat only
    center: bool = False  # mirror only
    role: str | None = None
    exceptions: list[Override] = field(default_factory=list)  # repeat only: copies that differ

    # --- construction helpers -------------------------------------------------------------------------
    @staticmethod
    def leaf(label: str, role: str | None = None) -> Node:
        return Node("leaf", label=label, role=role)

    @staticmethod
    def split(axis: str, items: list[tuple[Size, Node]], role: str | None = None) -> Node:
        return Node("split", axis=axis, sizes=[s for s, _ in items], children=[n for _, n in items], role=role)

    @staticmethod
    def repeat(axis: str, count: int | str, items: list[tuple[Size, Node]], tail: int = 0,
               role: str | None = None) -> Node:
        return Node("repeat", axis=axis, sizes=[s for s, _ in items], children=[n for _, n in items],
                    count=count, tail=tail, role=role)

    @staticmethod
    def mirror(axis: str, items: list[tuple[Size, Node]], center: bool = False, role: str | None = None) -> Node:
        return Node("mirror", axis=axis, sizes=[s for s, _ in items], children=[n for _, n in items],
                    center=center, role=role)

    def copy(self) -> Node:
        """A deep copy (sizes are immutable and shared)."""
        return Node(self.rule, self.label, self.axis, list(self.sizes), [c.copy() for c in self.children],
                    self.count, self.tail, self.center, self.role,
                    [o._replace(node=o.node.copy()) if o.node is not None else o for o in self.exceptions])

    @property
    def is_leaf(self) -> bool:
        return self.rule == "leaf"

    def walk(self, path: str = "root") -> Iterator[tuple[str, Node]]:
        """Depth-first pre-order over (path, node): the children, then the nodes of the exceptions (the node of
        exception ``e`` of ``root/1`` is ``root/1/!e``)."""
        yield path, self
        for i, child in enumerate(self.children):
            yield from child.walk(f"{path}/{i}")
        for e, o in enumerate(self.exceptions):
            if o.node is not None:
                yield from o.node.walk(f"{path}/!{e}")

    def subtrees(self) -> list[Node]:
        """The children, then the exceptions' nodes."""
        if not self.exceptions:
            return self.children
        return self.children + [o.node for o in self.exceptions if o.node is not None]

    def own_sizes(self) -> list[Size]:
        """The sizes this node holds as parameters: its children's, then its exceptions' (`Procedure.parameters`)."""
        if not self.exceptions:
            return self.sizes
        return self.sizes + [o.size for o in self.exceptions if o.size is not None]

    def bfs(self) -> Iterator[Node]:
        queue = [self]
        i = 0
        while i < len(queue):
            node = queue[i]
            i += 1
            yield node
            queue.extend(node.subtrees())

    # --- JSON -----------------------------------------------------------------------------------------
    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {"rule": self.rule}
        if self.role is not None:
            out["role"] = self.role
        if self.rule == "leaf":
            out["label"] = self.label
            return out
        out["axis"] = self.axis
        if self.rule == "repeat":
            out["count"] = self.count
            out["tail"] = self.tail
            if self.exceptions:
                out["exceptions"] = [o.to_dict() for o in self.exceptions]
        if self.rule == "mirror":
            out["center"] = self.center
        out["sizes"] = [[s.mode, s.value] for s in self.sizes]
        out["children"] = [c.to_dict() for c in self.children]
        return out
