"""Tree edit distance (Zhang & Shasha 1989) between procedures, with unit costs.

Nodes are compared by their structure, not their sizes (sizes are fitted afterwards): a leaf by its label,
an inner node by rule, axis, role, count, centre and tail; each node also by the mode of the size its parent
gives it (abs, rel, flt), so that a missing child costs one edit, not two.
"""

from __future__ import annotations

from facaid.grammar.procedure import Node


def node_label(node: Node, mode: str = "") -> str:
    """The structure of a node; ``mode`` is the mode of the size its parent gives it."""
    if node.rule == "leaf":
        return f"{mode}:{node.label}"
    extra = {"repeat": f"|{node.count}|{node.tail}", "mirror": f"|{node.center}"}.get(node.rule, "")
    return f"{mode}:{node.rule}_{node.axis}|{node.role}{extra}"


def _postorder(root: Node) -> tuple[list[str], list[int]]:
    labels: list[str] = []
    leftmost: list[int] = []

    def visit(node: Node, mode: str) -> int:
        first = None
        for size, child in zip(node.sizes, node.children, strict=True):
            lm = visit(child, size.mode)
            if first is None:
                first = lm
        i = len(labels)
        labels.append(node_label(node, mode))
        leftmost.append(i if first is None else first)
        return leftmost[i]

    visit(root, "")
    return labels, leftmost


def _keyroots(leftmost: list[int]) -> list[int]:
    last: dict[int, int] = {}
    for i, lm in enumerate(leftmost):
        last[lm] = i
    return sorted(last.values())


def tree_edit_distance(a: Node, b: Node) -> int:
    """Fewest node insertions, deletions and relabellings that turn tree ``a`` into tree ``b``."""
    la, ma = _postorder(a)
    lb, mb = _postorder(b)
    td = [[0] * len(lb) for _ in la]
    for i in _keyroots(ma):
        li = ma[i]
        for j in _keyroots(mb):
            lj = mb[j]
            m, n = i - li + 2, j - lj + 2
            fd = [[0] * n for _ in range(m)]
            for x in range(1, m):
                fd[x][0] = x
            for y in range(1, n):
                fd[0][y] = y
            for x in range(1, m):
                i1 = li + x - 1
                row, prev = fd[x], fd[x - 1]
                tdi = td[i1]
                for y in range(1, n):
                    j1 = lj + y - 1
                    if ma[i1] == li and mb[j1] == lj:
                        v = min(prev[y] + 1, row[y - 1] + 1, prev[y - 1] + (la[i1] != lb[j1]))
                        row[y] = v
                        tdi[j1] = v
                    else:
                        row[y] = min(prev[y] + 1, row[y - 1] + 1, fd[ma[i1] - li][mb[j1] - lj] + tdi[j1])
    return td[-1][-1]


def tree_size(node: Node) -> int:
    return 1 + sum(tree_size(c) for c in node.children)
