"""Repeats and their exceptions walked and recounted: how many children a node lays out, the node an exception's
path runs through, and a repeat's count changed with every exception kept on its copy."""

from __future__ import annotations

from collections.abc import Iterator
from typing import TYPE_CHECKING

from facaid.grammar.limits import MAX_COUNT

if TYPE_CHECKING:
    from facaid.grammar.procedure import Node, Override


def expanded_count(node: Node) -> int:
    """How many children a node lays out (a ``"fill"`` repeat: as many as it may)."""
    k = len(node.children)
    if node.rule == "repeat":
        return k * (MAX_COUNT if node.count == "fill" else node.count) + node.tail
    if node.rule == "mirror":
        return 2 * k - node.center
    return k


def pattern_child(node: Node, i: int) -> Node:
    """The node expanded child ``i`` of ``node`` is (`layout.expand`'s order), or the node an exception of ``node``
    puts in its place (an exception of a whole copy's item: a path through it goes on in that node)."""
    k = len(node.children)
    if node.rule == "mirror" and i >= k:
        return node.children[k - (2 if node.center else 1) - (i - k)]
    if node.exceptions:
        copy, item = divmod(i, k)
        for o in node.exceptions:
            if o.node is not None and o.copy == copy and o.path == (item,):
                return o.node
    return node.children[i % k]


def copies_moved(node: Node, count: int) -> dict[int, int]:
    """Where each copy of the repeat ``node`` goes when its count becomes ``count`` (a copy absent: removed; the
    tail, ``node.count``, goes to ``count``): new copies are typical and go after the last typical copy (one that no
    exception of ``node`` changes), between its like; removed copies are typical ones from the end first, then the
    last."""
    old = node.count
    changed = {o.copy for o in node.exceptions}
    typical = [c for c in range(old) if c not in changed]
    if count >= old:
        at = typical[-1] + 1 if typical else old
        new = {c: c if c < at else c + count - old for c in range(old)}
    else:
        gone = set((typical[::-1] + [c for c in range(old - 1, -1, -1) if c in changed])[: old - count])
        new = {c: c - sum(1 for g in gone if g < c) for c in range(old) if c not in gone}
    new[old] = count  # the tail
    return new


def recount(root: Node, node: Node, count: int, new: dict[int, int] | None = None) -> None:
    """Set the count of the repeat ``node`` (in the tree under ``root``) to ``count``, in place, keeping every
    exception on its copy as `copies_moved` places the copies (or as ``new`` says, a mapping of the same kind:
    rows of tiles that must stay in step). The tail keeps its exceptions, and the paths of repeats above that run
    through ``node`` follow their copies."""
    k = len(node.children)
    moved = (copies_moved(node, count) if new is None else new).get  # a copy's new index, None when it goes
    paths = {}  # the repeats above first: their paths run through node's copies as they are now
    for _, above in root.walk():
        if not above.exceptions or above is node:
            continue
        kept = []
        for o in above.exceptions:
            steps = list(o.path)
            for s, target in along_path(above, o, above.exceptions):
                if target is node and s + 1 < len(steps):
                    c = moved(steps[s + 1] // k)
                    if c is None:
                        break
                    steps[s + 1] = c * k + steps[s + 1] % k
            else:
                kept.append(o._replace(path=tuple(steps)))
        paths[id(above)] = (above, kept)
    for above, kept in paths.values():
        above.exceptions = kept
    node.exceptions = [o._replace(copy=moved(o.copy)) for o in node.exceptions if moved(o.copy) is not None]
    node.count = count


def along_path(node: Node, o: Override, exceptions: list[Override]) -> Iterator[tuple[int, Node]]:
    """The nodes an exception's path runs through, (step, node reached) each: the copy's item, then each child as
    laid out, where an exception of the same copy puts a node at a shorter path or a repeat below puts one in
    place of a whole item (`_pattern_child`), that node."""
    own = {e.path: e.node for e in exceptions if e.copy == o.copy and e.node is not None and e is not o}
    target = own.get(o.path[:1], node.children[o.path[0]])
    yield 0, target
    for k in range(1, len(o.path)):
        if target.rule == "leaf" or o.path[k] >= expanded_count(target):
            return
        target = own.get(o.path[: k + 1]) or pattern_child(target, o.path[k])
        yield k, target
