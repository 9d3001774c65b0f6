"""Variations of a procedure: edit one parameter, resize with repeats adapting, change counts, swap tiles.

Every function returns a new, validated procedure and leaves its input untouched. `vary` draws a mix of
these edits, deterministically by seed.
"""

from __future__ import annotations

import random

from facaid.editing.parameters import named_parameters, set_parameters
from facaid.editing.resizing import box_sizes, copy_procedure, regions, resize
from facaid.generator import STYLE_NAMES, generate_procedure
from facaid.grammar.nodes import Node, Size
from facaid.grammar.procedure import MAX_COUNT, MAX_EXTENT, Procedure, ProcedureError, validate

__all__ = ["change_count", "swap", "vary", "with_count", "with_size"]


def _node(proc: Procedure, path: str) -> Node:
    for p, node in proc.nodes():
        if p == path:
            return node
    raise ProcedureError(path, "no such node")


def with_size(proc: Procedure, path: str, index: int, value: float, mode: str | None = None) -> Procedure:
    """Set size ``index`` of the node at ``path`` (e.g. ``root/1/0``); the site's parameter editor."""
    out = copy_procedure(proc)
    node = _node(out, path)
    if not 0 <= index < len(node.sizes):
        raise ProcedureError(path, f"has {len(node.sizes)} sizes, no size {index}")
    node.sizes[index] = Size(mode or node.sizes[index].mode, value)
    validate(out)
    return out


def with_count(proc: Procedure, path: str, count: int | str) -> Procedure:
    out = copy_procedure(proc)
    node = _node(out, path)
    if node.rule != "repeat":
        raise ProcedureError(path, f"is a {node.rule} node, not a repeat")
    node.count = count
    validate(out)
    return out


def change_count(proc: Procedure, path: str, delta: int) -> Procedure:
    """Add or remove copies of a repeat (floors, tiles); the image grows or shrinks by as many units, so
    the other parts keep their size."""
    node = _node(proc, path)
    if node.rule != "repeat" or node.count == "fill":
        raise ProcedureError(path, "is not a repeat with a count")
    new_count = max(1, min(MAX_COUNT, node.count + delta))
    unit = regions(proc)[id(node)] / node.count
    grow = (new_count - node.count) * unit
    out = with_count(proc, path, new_count)
    if node.axis == "x":
        out.width = max(8.0, round(proc.width + grow))
    else:
        out.height = max(8.0, round(proc.height + grow))
    validate(out)
    return out


def _scaled_subtree(node: Node, sx: float, sy: float) -> Node:
    out = node.copy()
    for _, n in out.walk():
        f = sx if n.axis == "x" else sy
        n.sizes = [s if s.mode == "rel" else Size(s.mode, round(s.value * f, 2)) for s in n.sizes]
    return out


def swap(proc: Procedure, role: str, rng: random.Random, style: str | None = None) -> Procedure:
    """Replace one node of the given role ("tile" or "floor") by another of that role: from elsewhere in the
    procedure, or from a facade generated in the same style, scaled to the region it lands in."""
    targets = [(p, n) for p, n in proc.nodes() if n.role == role]
    if not targets:
        raise ValueError(f"the procedure has no node with role {role!r}")
    path, target = rng.choice(targets)
    extents = box_sizes(proc)
    donors = [(n, extents[id(n)]) for _, n in proc.nodes()
              if n.role == role and id(n) in extents and n.to_dict() != target.to_dict()]
    if not donors or rng.random() < 0.5:
        name = style if style in STYLE_NAMES else rng.choice(STYLE_NAMES)
        other = generate_procedure(rng.randrange(2**31), name)
        other_regions = box_sizes(other)
        donors = [(n, other_regions[id(n)]) for _, n in other.nodes() if n.role == role and id(n) in other_regions]
    if not donors:
        return copy_procedure(proc)
    donor, (dw, dh) = rng.choice(donors)
    tw, th = extents[id(target)]
    replacement = _scaled_subtree(donor, tw / max(dw, 1e-6), th / max(dh, 1e-6))
    replacement.role = role
    out = copy_procedure(proc)
    parent_path, _, index = path.rpartition("/")
    if not parent_path:
        out.root = replacement
    else:
        _node(out, parent_path).children[int(index)] = replacement
    validate(out)
    return out


def vary(proc: Procedure, n: int = 8, seed: int = 0,
         ranges: dict[str, tuple[float, float]] | None = None, hold: tuple[str, ...] = ()) -> list[Procedure]:
    """``n`` variants: counts of floors and tiles changed, the facade resized with its repeats adapting,
    tiles or floors swapped within the style. Deterministic by seed; every variant is valid. A draw that would
    cross the grammar's limits (a count past them, a facade at its largest made larger) is drawn again, so fewer
    than ``n`` come back only when that keeps happening.

    ``hold`` names counts ("floors", "bays") that these variants keep as they are: no repeat that lays them out
    changes its count, the facade is not resized along their axis (a resize recounts the repeats: a taller facade
    holds more floors), with both held it is not resized, and a variant that changed one anyway (a floor swapped
    for one of another facade, with other tiles) is drawn again. Without ``hold`` the draws are as they were.

    With ``ranges`` (named parameter → (low, high), see `facaid.editing.parameters`), each variant instead draws every
    named parameter uniformly from its range (whole numbers for counts) and sets them: ``{"floors": (4, 7)}``
    (``hold`` does not apply: the ranges say what changes)."""
    if not 1 <= n <= 64:
        raise ValueError(f"n must be between 1 and 64, got {n}")
    rng = random.Random(f"facaid-vary:{seed}")
    if ranges:
        return _vary_ranges(proc, n, seed, rng, ranges)
    held = _held_repeats(proc, hold)
    repeats = [p for p, node in proc.nodes() if node.rule == "repeat" and node.count != "fill" and p not in held]
    roles = [r for r in ("tile", "floor") if any(node.role == r for _, node in proc.nodes())]
    style = proc.meta.get("style")
    kinds = ([] if {"floors", "bays"} <= set(hold) else ["resize"]) + (["count"] if repeats else []) + \
        (["swap"] if roles else [])
    if not kinds:
        raise ValueError(f"nothing to vary while {' and '.join(hold)} stay as they are")
    counts = _counts(proc, hold) if hold else {}
    out = []
    for attempt in range(4 * n):  # a variant past the grammar's limits (a facade at its largest) is drawn again
        if len(out) == n:
            break
        i = len(out)
        kind = kinds[i % len(kinds)] if attempt < len(kinds) else rng.choice(kinds)
        try:
            if kind == "count":
                path = rng.choice(repeats)
                delta = rng.choice([-2, -1, 1, 2])
                variant = change_count(proc, path, delta)
            elif kind == "swap":
                variant = swap(proc, rng.choice(roles), rng, style)
            else:
                width = min(MAX_EXTENT, round(proc.width * rng.uniform(0.7, 1.5)))
                height = min(MAX_EXTENT, round(proc.height * rng.uniform(0.8, 1.3)))
                variant = resize(proc, proc.width if "bays" in hold else width,
                                 proc.height if "floors" in hold else height)
        except (ProcedureError, ValueError):
            continue
        if hold and _counts(variant, hold) != counts:  # a swapped floor of another facade holds other tiles
            continue
        variant.meta = {**proc.meta, "variation": kind, "variation_seed": seed, "variation_index": i,
                        "counts": _counts(variant, COUNTS)}
        out.append(variant)
    return out


COUNTS = ("floors", "bays")  # a variant's meta "counts": its caption, "7 upper floors, 8 tiles a floor"


def _counts(proc: Procedure, names: tuple[str, ...]) -> dict[str, float]:
    return {p.name: p.value for p in named_parameters(proc) if p.name in names}


def _held_repeats(proc: Procedure, hold: tuple[str, ...]) -> set[str]:
    """The paths of the repeats with a count that lay out the held counts' nodes: above a floor along y (``floors``),
    above a tile along x (``bays``)."""
    unknown = set(hold) - {"floors", "bays"}
    if unknown:
        raise ValueError(f"only the counts floors and bays can be held, not {', '.join(sorted(unknown))}")
    if not hold:
        return set()
    params = {p.name: p for p in named_parameters(proc)}
    nodes = dict(proc.nodes())
    out = set()
    for name, axis in (("floors", "y"), ("bays", "x")):
        if name not in hold or name not in params:
            continue
        for path in params[name].nodes:
            parts = path.split("/")
            for k in range(len(parts) - 1, 0, -1):
                above = "/".join(parts[:k])
                node = nodes.get(above)
                if node is not None and node.rule == "repeat" and node.axis == axis and node.count != "fill":
                    out.add(above)
    return out


def _vary_ranges(proc: Procedure, n: int, seed: int, rng: random.Random,
                 ranges: dict[str, tuple[float, float]]) -> list[Procedure]:
    params = {p.name: p for p in named_parameters(proc)}
    for name, (lo, hi) in ranges.items():
        if name not in params:
            raise ValueError(f"no named parameter {name!r} here; this procedure has {', '.join(params)}")
        p = params[name]
        if not lo <= hi:
            raise ValueError(f"{name}: the range {lo:g}-{hi:g} is empty (low above high)")
        if lo < p.min or hi > p.max:
            raise ValueError(f"{name}: the range {lo:g}-{hi:g} leaves {p.min:g}-{p.max:g}")
        if p.integer and (lo != int(lo) or hi != int(hi)):
            raise ValueError(f"{name} is a count: give whole numbers, got {lo:g}-{hi:g}")
    out = []
    for _ in range(4 * n):
        if len(out) == n:
            break
        values = {name: (rng.randint(int(lo), int(hi)) if params[name].integer else round(rng.uniform(lo, hi), 1))
                  for name, (lo, hi) in sorted(ranges.items())}
        try:
            variant = set_parameters(proc, values)
        except (ProcedureError, ValueError):
            continue
        variant.meta = {**proc.meta, "variation": "ranges", "variation_seed": seed, "variation_index": len(out),
                        "parameters": values, "counts": _counts(variant, COUNTS)}
        out.append(variant)
    return out
