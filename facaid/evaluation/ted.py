"""Tree edit distance (Zhang & Shasha 1989) between procedures, with unit costs.

Nodes are compared by their structure, not their sizes (sizes are fitted afterwards): a leaf by its label,
an inner node by rule, axis, role, count, centre and tail; each node also by the mode of the size its parent
gives it (abs, rel, flt), so that a missing child costs one edit, not two.
"""

from __future__ import annotations

from facaid.grammar.nodes import Node


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
    """Fewest node insertions, deletions and relabellings that turn tree ``a`` into tree ``b``.

    Zhang & Shasha's dynamic programme over the keyroot pairs; equal trees return at once (most pairs in an
    evaluation are), and labels are compared as small integers. ``tests/evaluation/test_ted.py`` checks it against the
    recursive definition of the forest distance."""
    la, ma = _postorder(a)
    lb, mb = _postorder(b)
    if la == lb and ma == mb:
        return 0
    ids: dict[str, int] = {}
    ia = [ids.setdefault(x, len(ids)) for x in la]
    ib = [ids.setdefault(x, len(ids)) for x in lb]
    td = [[0] * len(ib) for _ in ia]  # td[i][j]: distance of the subtrees rooted at i and j
    keys_b = [(j, mb[j]) for j in _keyroots(mb)]
    for i in _keyroots(ma):
        li = ma[i]
        for j, lj in keys_b:
            ys = range(1, j - lj + 2)
            # per column y (node lj + y - 1 of b): is its forest from lj a whole tree, where does its tree start
            whole = [False] + [mb[lj + y - 1] == lj for y in ys]
            start = [0] + [mb[lj + y - 1] - lj for y in ys]
            labels = [0] + ib[lj:j + 1]
            fd = [list(range(len(ys) + 1))]  # forest distances, row x: a's nodes li .. li + x - 1
            for x in range(1, i - li + 2):
                i1 = li + x - 1
                prev, row, tdi = fd[x - 1], [x] * (len(ys) + 1), td[i1]
                base = fd[ma[i1] - li]
                if ma[i1] == li:  # a's forest is a whole tree too: where its tree distances come from
                    label = ia[i1]
                    for y in ys:
                        if whole[y]:
                            v = min(prev[y] + 1, row[y - 1] + 1, prev[y - 1] + (label != labels[y]))
                            tdi[lj + y - 1] = v
                        else:
                            v = min(prev[y] + 1, row[y - 1] + 1, base[start[y]] + tdi[lj + y - 1])
                        row[y] = v
                else:
                    for y in ys:
                        row[y] = min(prev[y] + 1, row[y - 1] + 1, base[start[y]] + tdi[lj + y - 1])
                fd.append(row)
    return td[-1][-1]


def tree_size(node: Node) -> int:
    return 1 + sum(tree_size(c) for c in node.children)
