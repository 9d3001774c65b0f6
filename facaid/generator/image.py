"""The whole image of a generated facade: its buildings (`heuristics.Builder`) side by side as wings of one height,
the sky and side margins around them, scaled to pixels and put in the canonical form."""

from __future__ import annotations

import random

from facaid.generator.canonical import canonical
from facaid.generator.heuristics import Builder
from facaid.generator.styles import Style
from facaid.grammar.nodes import Node, Size
from facaid.grammar.procedure import Procedure


def _scaled(node: Node, scale: float) -> Node:
    """The tree with its sizes in pixels (to 0.1 px), in place."""
    node.sizes = [s if s.mode == "rel" else Size(s.mode, round(s.value * scale, 1)) for s in node.sizes]
    for child in node.children:
        if child.children:  # a leaf has no sizes
            _scaled(child, scale)
    return node


def build_procedure(rng: random.Random, styles: list[Style], long_side: float) -> Procedure:
    """The whole image: one facade (or several wings side by side), background around it, with the longer
    side ``long_side`` pixels."""
    b = Builder(rng)
    built = [b.facade(s) for s in styles]
    width_m = sum(w for _, w, _ in built)
    height_m = max(h for _, _, h in built)
    wings: list[tuple[Size, Node]] = []
    for node, w, h in built:
        if len(built) > 1 and h < height_m - 0.05:
            node = Node.split("y", [(b.flt(height_m - h), Node.leaf("background", role="margin")),
                                    (b.flt(h), node)])
        wings.append((b.flt(w), node))
    body = wings[0][1] if len(wings) == 1 else Node.split("x", wings, role="facade")
    sky_m = height_m * styles[0].sky / max(1e-6, 1 - styles[0].sky)
    side_m = width_m * rng.uniform(0.03, 0.15) if styles[0].side_bg else 0.0
    if side_m > 0:
        body = Node.split("x", [(b.abs(side_m), Node.leaf("background", role="margin")), (b.flt(width_m), body),
                                (b.abs(side_m), Node.leaf("background", role="margin"))])
    if sky_m > 0.05:
        body = Node.split("y", [(b.abs(sky_m), Node.leaf("background", role="margin")), (b.flt(height_m), body)])
    body.role = "image"
    total_w, total_h = width_m + 2 * side_m, height_m + (sky_m if sky_m > 0.05 else 0.0)
    scale = long_side / max(total_w, total_h)
    width_px = max(8, round(total_w * scale))
    height_px = max(8, round(total_h * scale))
    return canonical(Procedure(width_px, height_px, _scaled(body, scale)))
