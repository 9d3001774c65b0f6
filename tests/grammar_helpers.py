"""Procedures the grammar, format and site tests share: a facade whose repeats have exceptions, and the trees of
exceptions issue 66's probe crafted (also built by `bench/bench_request_cost.py` and `bench/bench_cost_model.py`)."""

import numpy as np

from facaid.grammar.nodes import Node, Override, Size
from facaid.grammar.procedure import GRAMMAR_VERSION, Procedure, ProcedureError
from facaid.grammar.repeats import expanded_count, pattern_child
from facaid.labels import LABEL_ID
from facaid.segmentation import Segmentation


def leaf(label: str) -> Node:
    return Node.leaf(label)


def tile(sill: bool = True, window: str = "window") -> Node:
    column = [(Size("flt", 1), leaf("facade")), (Size("abs", 40), leaf(window))]
    if sill:
        column.append((Size("abs", 6), leaf("sill")))
    column.append((Size("flt", 1), leaf("facade")))
    return Node.split("x", [(Size("flt", 1), leaf("facade")), (Size("abs", 30), Node.split("y", column)),
                            (Size("flt", 1), leaf("facade"))], role="tile")


def facade(exceptions: list[Override], bays: list[Override] | None = None) -> Procedure:
    """Four floors of five tiles under a molding; ``exceptions`` on the floors, ``bays`` on every row."""
    row = Node.repeat("x", 5, [(Size("flt", 60), tile())], role="floor")
    row.exceptions = list(bays or [])
    floors = Node.repeat("y", 4, [(Size("flt", 90), row)], role="floors")
    floors.exceptions = list(exceptions)
    root = Node.split("y", [(Size("abs", 40), leaf("molding")), (Size("flt", 1), floors)])
    return Procedure(330, 400, root)


def plain_facade() -> Procedure:
    """`example()` written out without exceptions: every copy that differs as a node of its own."""
    def row(special: dict[int, Node], widths: dict[int, float] | None = None) -> Node:
        widths = widths or {}
        return Node.split("x", [(Size("flt", widths.get(j, 60)), special.get(j, tile())) for j in range(5)],
                          role="floor")
    rows = [row({4: tile(sill=False)}, {2: 90}), row({3: tile(window="blind")}, {2: 90}), row({}, {2: 90}),
            row({}, {2: 90})]
    floors = Node.split("y", [(Size("flt", 90 if i < 3 else 120), r) for i, r in enumerate(rows)], role="floors")
    return Procedure(330, 400, Node.split("y", [(Size("abs", 40), leaf("molding")), (Size("flt", 1), floors)]))


def example() -> Procedure:
    """A blind closed in floor 1, tile 3; floor 3 taller; tile 4 of floor 0 without its sill (the sill's place
    goes to the wall); the middle bay wider on every floor."""
    return facade([Override(1, (0, 3, 1, 1), node=leaf("blind")),
                   Override(3, (0,), size=Size("flt", 120)),
                   Override(0, (0, 4, 1, 2), size=Size("abs", 0), node=leaf("facade"))],
                  bays=[Override(2, (0,), size=Size("flt", 90))])


def real_like(seed: int = 0, floors: int = 5, bays: int = 6, door: int | None = None) -> Segmentation:
    """An annotation drawn the way people draw CMP's: layered boxes, edges a few pixels off, a facade box, windows
    with sills and hoods in rows and columns, one window's blind closed, a balcony on the second floor, a taller
    ground floor of shops around a door (under column ``door``, by default the middle one), a cornice band under
    the roof, and sky above."""
    rng = np.random.default_rng(seed)
    tile, storey, top, ground = 70, 95, 60, 130
    width, height = 30 * 2 + bays * tile, top + floors * storey + ground
    rects = [("facade", 0, 20, width, height), ("molding", 0, top - 16, width, top - 4)]

    def j(v: float) -> int:
        return int(round(v + rng.normal(0, 1.2)))

    for i in range(floors):
        y = top + i * storey
        if i == 1:
            rects.append(("balcony", 24, y + 70, width - 24, y + 84))
        for b in range(bays):
            x = 30 + b * tile
            rects.append(("cornice", j(x + 14), j(y + 10), j(x + 56), j(y + 18)))
            rects.append(("window", j(x + 18), j(y + 20), j(x + 52), j(y + 72)))
            rects.append(("sill", j(x + 15), j(y + 72), j(x + 55), j(y + 77)))
            if (i, b) == (3, 2):
                rects.append(("blind", j(x + 18), j(y + 20), j(x + 52), j(y + 72)))
    y = top + floors * storey
    for b in range(bays):
        x = 30 + b * tile
        if b == (bays // 2 if door is None else door):
            rects.append(("door", j(x + 16), j(y + 30), j(x + 54), height))
        else:
            rects.append(("shop", j(x + 6), j(y + 24), j(x + 64), j(height - 6)))
    rows = np.array([(LABEL_ID[label], max(0, x0), max(0, y0), min(width, max(x1, x0 + 2)),
                      min(height, max(y1, y0 + 2))) for label, x0, y0, x1, y1 in rects], dtype=np.int64)
    return Segmentation.from_array(width, height, rows)


def random_exceptions(proc: Procedure, rng: np.random.Generator, n: int = 6) -> Procedure:
    """``proc`` with up to ``n`` random exceptions on its repeats: a size, a leaf of another label or both, at a
    random depth of a random copy."""
    proc = Procedure(proc.width, proc.height, proc.root.copy(), dict(proc.meta))
    repeats = [node for _, node in proc.nodes() if node.rule == "repeat"]
    if not repeats:
        return proc
    labels = ["window", "blind", "facade", "door", "balcony", "deco"]
    for _ in range(n):
        node = repeats[rng.integers(len(repeats))]
        copies = 8 if node.count == "fill" else node.count
        path = [int(rng.integers(len(node.children)))]
        target = node.children[path[0]]
        while target.rule != "leaf" and rng.random() < 0.6:
            i = int(rng.integers(min(expanded_count(target), 40)))
            path.append(i)
            target = pattern_child(target, i)
        size = Size("flt" if rng.random() < 0.5 else "abs", float(rng.uniform(2, 60))) if rng.random() < 0.6 else None
        new = leaf(labels[rng.integers(len(labels))]) if size is None or rng.random() < 0.5 else None
        override = Override(int(rng.integers(copies)), tuple(path), size, new)
        if all((o.copy, o.path) != (override.copy, override.path) for o in node.exceptions):
            node.exceptions.append(override)
            try:  # a new whole item can leave an exception from further up without its node
                Procedure.from_dict(proc.to_dict())
            except ProcedureError:
                node.exceptions.pop()
    return Procedure.from_dict(proc.to_dict())


def doc(root: dict, side: int = 4096) -> dict:
    """A procedure's JSON around ``root``, ``side`` pixels square."""
    return {"format": "facaid-procedure", "version": 1, "grammar": GRAMMAR_VERSION, "width": side, "height": side,
            "root": root}


def probe(rows: int = 256, columns: int = 11, exceptions: int = 1024, chain: int = 28, count="fill") -> dict:
    """Issue 66's tree: repeat y x ``rows`` -> repeat x x ``columns`` -> R, a repeat of one copy whose
    ``exceptions`` size-only exceptions, all in copy 0, have paths [0, 0 x ``chain``, x] down ``chain`` one-child
    splits to a repeat (``count``) of 4 leaves of abs 5000."""
    node = {"rule": "repeat", "axis": "x", "count": count, "sizes": [["abs", 5000]] * 4,
            "children": [{"rule": "leaf", "label": "window"}] * 4}
    for _ in range(chain):
        node = {"rule": "split", "axis": "y", "sizes": [["flt", 1]], "children": [node]}
    r = {"rule": "repeat", "axis": "y", "count": 1, "sizes": [["flt", 1]], "children": [node],
         "exceptions": [{"copy": 0, "path": [0] + [0] * chain + [x], "size": ["abs", 3]} for x in range(exceptions)]}
    inner = {"rule": "repeat", "axis": "x", "count": columns, "sizes": [["flt", 1]], "children": [r]}
    return doc({"rule": "repeat", "axis": "y", "count": rows, "sizes": [["flt", 1]], "children": [inner]})


def nested() -> dict:
    """Issue 66's other shape: 8 nested repeats of 4 copies, each with 1,010 exceptions whose paths run down
    through the repeats below (265 KB; the probe's was 460 KB)."""
    node = {"rule": "leaf", "label": "window"}
    for level in range(8):
        node = {"rule": "repeat", "axis": "xy"[level % 2], "count": 4, "sizes": [["flt", 1]], "children": [node]}
        node["exceptions"] = [{"copy": e % 4, "path": [0] + [(e >> (2 * k + 2)) % 4 for k in range(level)],
                               "size": ["flt", 2]} for e in range(4 * 4 ** level)][:1010]
    return doc(node)
