"""A tree's shape, for comparing trees of one form: its leaves with their paths, its rules and labels without sizes,
and how many elements it draws."""

from __future__ import annotations

from facaid.grammar.nodes import Node


def leaf_paths(node: Node, path: tuple[int, ...] = ()) -> list[tuple[tuple[int, ...], Node]]:
    """The leaves of a tree of splits with their child-index paths, depth-first (`execute`'s leaf order)."""
    if node.rule == "leaf":
        return [(path, node)]
    return [lp for i, c in enumerate(node.children) for lp in leaf_paths(c, (*path, i))]


def shape(node: Node) -> tuple:
    """A tree without its sizes: rules, axes and labels."""
    if node.rule == "leaf":
        return ("leaf", node.label)
    return (node.rule, node.axis, tuple(shape(c) for c in node.children))


def elements(node: Node) -> int:
    """How many element leaves (neither wall nor background) a tree has."""
    return sum(1 for _, n in node.walk() if n.rule == "leaf" and n.label not in ("facade", "background"))
