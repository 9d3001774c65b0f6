"""How an edited tree grows to fit its edited nodes: every node enclosing them and the image grow by what their
contents grew, so that the other parts keep their size (six floors of 80 px become seven: the facade is 80 px
taller, the ground floor stays). A node beside an edited one that grew less is padded in what holds no edited
node: sky first, then wall."""

from __future__ import annotations

from facaid.grammar.nodes import Node, Size
from facaid.grammar.procedure import Procedure
from facaid.grammar.repeats import pattern_child


def grow(proc: Procedure, axis: str, own: dict[int, float], shrink: bool = False) -> None:
    """Grow the nodes in ``own`` (id → change of each instance's length along ``axis``) and, to fit them, every
    node enclosing them and the image; a normalised tree stays normalised, so nothing else changes size. With
    ``shrink`` (a count made smaller), a node whose edited children shrink shrinks with them and its other children
    follow (a floor fewer makes the image lower beside it too); else the wall takes what they give up (a narrower
    window leaves its floor as high)."""
    memo: dict[int, float] = {}
    holds: dict[int, bool] = {}

    def has_target(node: Node) -> bool:
        if id(node) not in holds:
            holds[id(node)] = id(node) in own or any(has_target(c) for c in _inner(node))
        return holds[id(node)]

    def pad(node: Node, extra: float) -> None:
        """Lengthen ``node`` by ``extra`` in what holds no edited node (a wing whose floors grew less than its
        neighbour's takes the difference in its sky where it has some, else in its wall, not in its floors)."""
        if node.rule == "leaf" or id(node) in own:
            return
        if axis == "y" and node.role == "facade" and not has_target(node) and extra > 0:
            # a building beside the one that took a floor: as it was, under more sky
            inner = Node(node.rule, node.label, node.axis, node.sizes, node.children, node.count, node.tail,
                         node.center, node.role, node.exceptions)
            node.rule, node.axis, node.role, node.count, node.tail, node.center = "split", "y", None, None, 0, False
            node.sizes, node.children, node.exceptions = [Size("abs", extra), Size("flt", 1.0)], [
                Node.leaf("background"), inner], []
            return
        if node.axis != axis:
            for c in node.children:
                pad(c, extra)
            return
        free = [i for i, c in enumerate(node.children) if not has_target(c)]
        sky = [i for i in free if node.children[i].rule == "leaf" and node.children[i].label == "background"]
        i = next((i for i in sky + free if node.sizes[i].mode == "flt"), (sky + free)[0] if free else 0)
        copies = (len(_grown_copies(node, i)) if node.rule == "repeat"
                  else 1 if node.rule == "split" or (node.center and i == len(node.children) - 1) else 2)
        if not copies:  # every copy of the item has its own size: they share the extra
            _pad_own_sizes(node, i, extra)
            return
        node.sizes[i] = Size(node.sizes[i].mode, round(node.sizes[i].value + extra / copies, 4))
        if not free:
            pad(node.children[i], extra / copies)

    def grow(node: Node) -> float:
        key = id(node)
        if key in memo:
            return memo[key]
        if key in own:
            g = own[key]
        elif node.rule == "leaf":
            g = 0.0
        elif node.axis != axis:  # its children side by side: all as long as the longest needs (see ``shrink``)
            parts = [grow(c) for c in node.children]
            edited = [d for c, d in zip(node.children, parts, strict=True) if has_target(c)]
            g = max(edited) if shrink and edited else max(parts)
            for c, d in zip(node.children, parts, strict=True):
                if d != g:
                    pad(c, g - d)
        else:
            parts = [grow(c) for c in node.children]
            node.sizes = [Size(s.mode, max(0.0, round(s.value + d, 4))) for s, d in zip(node.sizes, parts,
                                                                                      strict=True)]
            if node.rule == "repeat":  # a copy an exception sizes keeps its size
                g = sum(len(_grown_copies(node, j)) * d for j, d in enumerate(parts))
            elif node.rule == "mirror":
                g = 2 * sum(parts) - (parts[-1] if node.center else 0.0)
            else:
                g = sum(parts)
        memo[key] = g
        for o in node.exceptions:  # a node an exception puts in place grows too (its windows are windows), and
            # is padded to what the node it replaces grew by, so that it fills the same place
            if o.node is not None:
                own_growth = grow(o.node)
                replaced = _pattern_at(node, o.path)
                if replaced is not None and memo.get(id(replaced), own_growth) > own_growth:  # (one that grew
                    pad(o.node, memo[id(replaced)] - own_growth)  # more is laid out in its place as it is)
        return g

    g = grow(proc.root)
    if axis == "x":
        proc.width = round(proc.width + g, 4)
    else:
        proc.height = round(proc.height + g, 4)


def _inner(node: Node) -> list[Node]:
    """A node's children and the nodes its exceptions put in place."""
    return node.children + [o.node for o in node.exceptions if o.node is not None]


def _pattern_at(node: Node, path: tuple[int, ...]) -> Node | None:
    """The node of ``node``'s pattern that an exception's path names (a repeat's copies read as its pattern), or
    None where the path goes below a leaf."""
    target = node.children[path[0]]
    for step in path[1:]:
        if target.rule == "leaf":
            return None
        target = pattern_child(target, step)
    return target


def _pad_own_sizes(node: Node, item: int, extra: float) -> None:
    """Share ``extra`` among the exceptions that size the laid-out copies of a repeat's pattern item ``item``."""
    laid_out = node.count + (item < node.tail)
    sized = [k for k, o in enumerate(node.exceptions) if o.path == (item,) and o.size is not None and o.copy < laid_out]
    for k in sized:
        o = node.exceptions[k]
        node.exceptions[k] = o._replace(size=Size(o.size.mode, round(o.size.value + extra / len(sized), 4)))


def _grown_copies(node: Node, item: int) -> list[int]:
    """The copies of a repeat's pattern item ``item`` that take the item's own size (no exception sizes them)."""
    resized = {o.copy for o in node.exceptions if o.path == (item,) and o.size is not None}
    return [c for c in range(node.count + (item < node.tail)) if c not in resized]


__all__ = ["grow"]
