"""Procedures the grammar and format tests share: a facade whose repeats have exceptions."""

from facaid.grammar.procedure import Node, Override, Procedure, Size


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
