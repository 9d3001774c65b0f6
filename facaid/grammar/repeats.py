"""Repeats and their exceptions walked and recounted: how many children a node lays out, the node an exception's
path runs through, and a repeat's count changed with every exception kept on its copy."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import TYPE_CHECKING

from facaid.grammar.limits import MAX_COUNT

if TYPE_CHECKING:
    from facaid.grammar.nodes import Node, Override


def expanded_count(node: Node) -> int:
    """How many children a node lays out (a ``"fill"`` repeat: as many as it may)."""
    k = len(node.children)
    if node.rule == "repeat":
        return k * (MAX_COUNT if node.count == "fill" else node.count) + node.tail
    if node.rule == "mirror":
        return 2 * k - node.center
    return k


def pattern_child(node: Node, i: int, index: PathIndex | None = None) -> Node:
    """The node expanded child ``i`` of ``node`` is (`layout.expand`'s order), or the node an exception of ``node``
    puts in its place (an exception of a whole copy's item: a path through it goes on in that node). ``index``
    keeps each repeat's such nodes found once, for walks of many paths."""
    k = len(node.children)
    if node.rule == "mirror" and i >= k:
        return node.children[k - (2 if node.center else 1) - (i - k)]
    if node.exceptions:
        found = (index or PathIndex()).items(node).get(divmod(i, k))
        if found is not None:
            return found
    return node.children[i % k]


class PathIndex:
    """The nodes exceptions put in place, indexed once per repeat: walking every exception's path of a tree then
    costs its steps, not its steps times the exceptions (a tree of 8 nested repeats of 1,010 exceptions each was
    1 s to parse). Valid while the exceptions it has read do not change."""

    def __init__(self) -> None:
        self._items: dict[int, dict[tuple[int, int], Node]] = {}
        self._own: dict[int, dict[tuple[int, tuple[int, ...]], Override]] = {}

    def items(self, node: Node) -> dict[tuple[int, int], Node]:
        """(copy, item) -> the node an exception of ``node`` puts in place of that copy's whole item."""
        found = self._items.get(id(node))
        if found is None:
            found = self._items[id(node)] = {(o.copy, o.path[0]): o.node for o in node.exceptions
                                             if o.node is not None and len(o.path) == 1}
        return found

    def own(self, exceptions: list[Override]) -> dict[tuple[int, tuple[int, ...]], Override]:
        """(copy, path) -> the exception of this list that puts a node there."""
        found = self._own.get(id(exceptions))
        if found is None:
            found = self._own[id(exceptions)] = {(e.copy, e.path): e for e in exceptions if e.node is not None}
        return found


def copies_moved(node: Node, count: int, source: int | None = None, before: bool = False) -> dict[int, int]:
    """Where each copy of the repeat ``node`` goes when its count becomes ``count`` (a copy absent: removed; the
    tail, ``node.count``, goes to ``count``): new copies are typical and go after ``source`` (before it with
    ``before``; by default after the last typical copy, one that no exception of ``node`` changes), between their
    like; removed copies are ``source`` first, then typical ones from the end, then the others, those fewest
    exceptions change first (from the end), but the last copy that lays out the pattern (with none, it would never
    be laid out)."""
    old = node.count
    changed = {o.copy for o in node.exceptions}
    typical = [c for c in range(old) if c not in changed]
    if count >= old:
        at = source + (not before) if source is not None else typical[-1] + 1 if typical else old
        new = {c: c if c < at else c + count - old for c in range(old)}
    else:
        # a copy that lays the pattern out (no exception puts a node in place of its items) stays while it is the
        # last: without one, the pattern's own exceptions would never be laid out, which a tree may not hold
        holders = list(_holders(node))
        replaced = {o.copy for o in node.exceptions if o.node is not None
                    and any(h[: len(o.path)] == o.path for h in holders)}
        laying = {c for c in range(old) if c not in replaced}
        gone: set[int] = set()
        first = [source] if source is not None else []
        own = {c: sum(1 for o in node.exceptions if o.copy == c) for c in changed}
        for c in first + typical[::-1] + sorted(changed, key=lambda c: (own[c], -c)):
            if len(gone) == old - count:
                break
            if c not in gone and laying - gone != {c}:
                gone.add(c)
        if len(gone) < old - count:  # only that copy is left to take
            gone |= laying
        new = {c: c - sum(1 for g in gone if g < c) for c in range(old) if c not in gone}
    new[old] = count  # the tail
    return new


def most_typical(root: Node, node: Node, rows: tuple[Node, ...] = (),
                 avoid: frozenset[int] = frozenset()) -> int | None:
    """Of the typical copies of the repeat ``node`` (no exception of its own), the one fewest exceptions change: of
    the repeats above that run through it, and of ``rows``, repeats of as many copies kept in step with it (a
    floor of its own tiles); the last of those, None with none typical. It is the column every floor lays out most
    as its typical tile: a new copy repeats it, cells of other floors and all, and a copy fewer takes it. A copy in
    ``avoid`` (one holding the door, `copies_where`) is taken only where all are."""
    changed = {o.copy for o in node.exceptions}
    typical = [c for c in range(node.count) if c not in changed]
    if not typical:
        return None
    k = len(node.children)
    through = {c: 0 for c in typical}
    for _, o, s in _through(root, node):
        if (c := o.path[s] // k) in through:
            through[c] += 1
    for row in rows:
        for o in row.exceptions:
            if row is not node and o.copy in through:
                through[o.copy] += 1
    return min(typical[::-1], key=lambda c: (c in avoid, through[c]))


def copies_where(root: Node, node: Node, rows: tuple[Node, ...], test: Callable[[Node], bool]) -> frozenset[int]:
    """The copies of the repeat ``node`` where an exception puts a node ``test`` is true of (one that holds the
    door): an exception of a repeat above whose path runs through the copy, or of one of ``rows`` (repeats kept in
    step with ``node``) at the same copy."""
    k = len(node.children)
    found = {o.path[s] // k for _, o, s in _through(root, node) if o.node is not None and test(o.node)}
    found |= {o.copy for row in rows for o in row.exceptions if o.node is not None and test(o.node)}
    return frozenset(found)


def _through(root: Node, node: Node) -> Iterator[tuple[Node, Override, int]]:
    """The exceptions of the repeats under ``root`` above ``node`` whose paths run through it: (the repeat, the
    exception, the step of its path that names ``node``'s child, copy times pattern length plus item)."""
    index = PathIndex()
    for _, above in root.walk():
        if not above.exceptions or above is node:
            continue
        for o in above.exceptions:
            for s, target in along_path(above, o, above.exceptions, index):
                if target is node and s + 1 < len(o.path):
                    yield above, o, s + 1
                    break


def _holders(node: Node) -> Iterator[tuple[int, ...]]:
    """The paths (pattern item, then children of splits) of the nodes in a repeat's pattern that have exceptions of
    their own, or the pattern items themselves where none has."""
    def walk(n: Node, path: tuple[int, ...]) -> Iterator[tuple[int, ...]]:
        if n.exceptions:
            yield path
        elif n.rule == "split":
            for i, c in enumerate(n.children):
                yield from walk(c, (*path, i))
    found = False
    for item, child in enumerate(node.children):
        for path in walk(child, (item,)):
            found = True
            yield path
    if not found:
        yield from ((item,) for item in range(len(node.children)))


def recount(root: Node, node: Node, count: int, new: dict[int, int] | None = None, source: int | None = None,
            own: bool = True) -> None:
    """Set the count of the repeat ``node`` (in the tree under ``root``) to ``count``, in place, keeping every
    exception on its copy as `copies_moved` places the copies (or as ``new`` says, a mapping of the same kind:
    rows of tiles that must stay in step). The tail keeps its exceptions, and the paths of repeats above that run
    through ``node`` follow their copies. New copies repeat copy ``source`` where given: the exceptions above that
    run through it, and its own unless ``own`` is False (a ground floor's new cell is its typical shop, not the
    source's door)."""
    k = len(node.children)
    moved = (copies_moved(node, count, source) if new is None else new).get  # a copy's new index, None: it goes
    added = sorted(set(range(count)) - {moved(c) for c in range(node.count)}) if source is not None else []
    redone: dict[int, list[Override]] = {}  # id of an exception above -> what it becomes (none: its copy goes)
    aboves: dict[int, tuple[Node, list[Override]]] = {}  # the repeats above, and the new copies' exceptions
    for above, o, s in _through(root, node):  # the repeats above first: their paths run through node as it is now
        extra = aboves.setdefault(id(above), (above, []))[1]
        c, item = divmod(o.path[s], k)
        to = moved(c)
        redone[id(o)] = [] if to is None else [o._replace(path=(*o.path[:s], to * k + item, *o.path[s + 1 :]))]
        if c == source:  # each new copy its own nodes: one node in two places would edit both
            extra += [_own(o)._replace(path=(*o.path[:s], a * k + item, *o.path[s + 1 :])) for a in added]
    for above, extra in aboves.values():
        above.exceptions = [e for o in above.exceptions for e in redone.get(id(o), [o])] + extra
    kept = [o._replace(copy=moved(o.copy)) for o in node.exceptions if moved(o.copy) is not None]
    if own:
        kept += [_own(o)._replace(copy=a) for o in node.exceptions if o.copy == source for a in added]
    node.exceptions = kept
    node.count = count


def _own(o: Override) -> Override:
    """The exception with a copy of its node (a new copy's exceptions never share a node with its source's)."""
    return o if o.node is None else o._replace(node=o.node.copy())


def along_path(node: Node, o: Override, exceptions: list[Override],
               index: PathIndex | None = None) -> Iterator[tuple[int, Node]]:
    """The nodes an exception's path runs through, (step, node reached) each: the copy's item, then each child as
    laid out, where an exception of the same copy puts a node at a shorter path or a repeat below puts one in
    place of a whole item (`pattern_child`), that node. Pass one ``index`` to walk many paths of one tree."""
    index = index or PathIndex()
    own = index.own(exceptions)

    def placed(path: tuple[int, ...]) -> Node | None:
        e = own.get((o.copy, path))
        return e.node if e is not None and e is not o else None

    target = placed(o.path[:1]) or node.children[o.path[0]]
    yield 0, target
    for k in range(1, len(o.path)):
        if target.rule == "leaf" or o.path[k] >= expanded_count(target):
            return
        target = placed(o.path[: k + 1]) or pattern_child(target, o.path[k], index)
        yield k, target


def path_problem(node: Node, o: Override, index: PathIndex | None = None) -> str | None:
    """What is wrong with the path of ``o``, an exception of ``node`` (None if nothing): a step below a leaf or
    past the children, as the tree stands (`along_path`)."""
    reached = 0
    parent = None
    for k, target in along_path(node, o, node.exceptions, index):
        reached, parent = k, target
    if reached == len(o.path) - 1:
        return None
    k = reached + 1
    if parent.rule == "leaf":
        return f"path[{k}] goes below a leaf"
    return f"path[{k}] is {o.path[k]}, but that node lays out {expanded_count(parent)} children"
