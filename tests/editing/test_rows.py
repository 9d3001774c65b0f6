"""The rows a bay edit reaches besides the rows of tiles (`facaid.editing.rows`), on trees written as the generator
writes them: a ground floor of shops written out cell by cell, an attic of dormers, a row mirrored around its centre
bay, a facade of wings. Each edit is judged as a person looks at it (`facaid.editing.check`), and the generated
facades' figure is measured on held-out seeds."""

import numpy as np
import pytest
from grammar_helpers import leaf, tile

from facaid.editing.check import check_edits
from facaid.editing.parameters import named_parameters, set_parameter
from facaid.editing.rows import unmirrored
from facaid.evaluation.editability import generated_edits
from facaid.generator import generate_procedure
from facaid.grammar.execute import flat_rows, label_map
from facaid.grammar.nodes import Node, Override, Size
from facaid.grammar.procedure import Procedure, validate
from facaid.labels import LABEL_ID
from facaid.segmentation import region_boxes


def boxes(proc: Procedure, label: str) -> np.ndarray:
    return region_boxes(flat_rows(proc), (LABEL_ID[label],))


def cell(label: str) -> Node:
    """A ground-floor cell as wide as a tile: a shop or the door in wall."""
    return Node.split("x", [(Size("flt", 1), leaf("facade")), (Size("abs", 40), Node.split(
        "y", [(Size("flt", 1), leaf("facade")), (Size("abs", 70), leaf(label))])), (Size("flt", 1), leaf("facade"))])


def shops_under_bays(door: int = 2, bays: int = 5) -> Procedure:
    """Three floors of ``bays`` tiles over a ground floor written out as a cell under each bay, the door under bay
    ``door``, and an attic with two dormers over bays 1 and 3."""
    row = Node.repeat("x", bays, [(Size("flt", 60), tile())], role="bay")
    floors = Node.repeat("y", 3, [(Size("flt", 90), Node.split("y", [(Size("flt", 1), row)], role="floor"))],
                         role="floors")
    ground = Node.split("x", [(Size("flt", 60), cell("door" if j == door else "shop")) for j in range(bays)],
                        role="ground")
    attic = Node.split("x", [(Size("flt", 80), leaf("facade")), (Size("flt", 20), leaf("window")),
                             (Size("flt", 100), leaf("facade")), (Size("flt", 20), leaf("window")),
                             (Size("flt", 80), leaf("facade"))], role="attic")
    root = Node.split("y", [(Size("abs", 40), attic), (Size("flt", 270), floors), (Size("abs", 100), ground)],
                      role="facade")
    return Procedure(60 * bays, 410, root)


@pytest.mark.parametrize("door", [0, 2, 4])
def test_a_ground_floor_of_cells_takes_a_shop_under_the_new_bay(door):
    """The ground floor written out under the bays takes a cell where the new bay goes, a shop however near the
    door (before, it stretched: every shop moved off its column); a bay fewer takes a shop, never the door."""
    proc = shops_under_bays(door)
    wider = set_parameter(proc, "bays", 6)
    validate(wider)
    assert len(boxes(wider, "shop")) == 5 and len(boxes(wider, "door")) == 1
    windows, shops = boxes(wider, "window"), boxes(wider, "shop")
    columns = {int(x) for x in (windows[:, 0] + windows[:, 2]) // 2}
    assert {int(x) for x in (shops[:, 0] + shops[:, 2]) // 2} <= columns  # every shop under a column
    assert check_edits(proc, (("bays", 1),))["bays+1"].clean
    narrower = set_parameter(proc, "bays", 4)
    assert len(boxes(narrower, "door")) == 1 and len(boxes(narrower, "shop")) == 3


def test_dormers_stay_over_their_columns():
    """A bay more opens the attic's wall where the new bay goes: the dormers keep their places over bays 1 and 3
    (before, the attic stretched and they moved between columns)."""
    proc = shops_under_bays()
    wider = set_parameter(proc, "bays", 6)
    assert [tuple(b) for b in boxes(wider, "window")[:2].tolist()] == [tuple(b) for b in
                                                                     boxes(proc, "window")[:2].tolist()]


def mirrored_row() -> Procedure:
    """Two floors of tiles mirrored around a wider centre tile (3, the centre, 3), over a ground floor mirrored around
    its entrance."""
    side = Node.repeat("x", 3, [(Size("flt", 60), tile())])
    wide = tile(window="window")
    wide.sizes[1] = Size("abs", 44)
    floor = Node.mirror("x", [(Size("flt", 180), side), (Size("flt", 60), wide)], center=True, role="floor")
    floors = Node.repeat("y", 2, [(Size("flt", 90), floor)], role="floors")
    shops = Node.repeat("x", 3, [(Size("flt", 60), cell("shop"))])
    ground = Node.mirror("x", [(Size("flt", 180), shops), (Size("flt", 60), cell("door"))], center=True,
                         role="ground")
    return Procedure(420, 280, Node.split("y", [(Size("flt", 180), floors), (Size("abs", 100), ground)]))


def test_a_mirrored_row_is_the_repeat_it_draws_and_takes_one_bay():
    """A row mirrored around its centre bay could only change by two: it is first written as the repeat of 7 that
    draws the same pixels, the centre its exception, so bays + 1 adds one bay beside the others."""
    proc = mirrored_row()
    before = label_map(proc)
    as_repeat = unmirrored(Procedure.from_dict(proc.to_dict()))
    assert not any(n.rule == "mirror" for _, n in as_repeat.nodes())
    assert np.array_equal(label_map(as_repeat), before)
    wider = set_parameter(proc, "bays", 8)
    assert {p.name: p.value for p in named_parameters(wider)}["bays"] == 8
    assert len(boxes(wider, "door")) == 1 and len(boxes(wider, "shop")) == 7
    assert check_edits(proc, (("bays", 1),))["bays+1"].clean


def test_a_wing_keeps_its_bays():
    """On a facade of two buildings, a bay more goes to the building of the most laid-out row; the other wing's
    bays stay as many."""
    def building(bays: int, floors: int) -> Node:
        row = Node.repeat("x", bays, [(Size("flt", 60), tile())], role="bay")
        rep = Node.repeat("y", floors, [(Size("flt", 90), Node.split("y", [(Size("flt", 1), row)], role="floor"))],
                          role="floors")
        return Node.split("y", [(Size("flt", 1), rep)], role="facade")

    proc = Procedure(540, 360, Node.split("x", [(Size("flt", 300), building(5, 4)), (Size("flt", 240),
                                                                                     building(4, 3))], role="facade"))
    wider = set_parameter(proc, "bays", 6)
    rows = sorted(n.count for _, n in wider.nodes() if n.rule == "repeat" and n.axis == "x")
    assert rows == [4, 6]


def test_generated_facades_edit_cleanly():
    """`floors` + 1 and `bays` + 1 on held-out generated facades with a lattice of windows (two rows and two
    columns at least), judged as a person looks: both clean on most (the generated figure of issue 67; the rest
    are wings, whose new floor cannot be one band across buildings of other floor heights)."""
    eligible, clean, _ = generated_edits(range(5000, 5040))
    both = len(clean)
    assert eligible >= 35 and both / eligible >= 0.85


@pytest.mark.parametrize("seed", range(6))
def test_a_wing_takes_the_bays_asked_for(seed):
    """The named `bays` counts the first wing's tiles; set, that wing has as many (the edit went to the building
    of the most laid-out row, and the named value did not move on most generated wings)."""
    proc = generate_procedure(seed, "wings")
    bays = {p.name: p for p in named_parameters(proc)}["bays"]
    for value in (bays.value + 1, bays.value + 2, max(1, bays.value - 1)):
        try:
            out = set_parameter(proc, "bays", value)
        except ValueError:
            continue
        assert {p.name: p.value for p in named_parameters(out)}["bays"] == value


def test_a_new_copy_has_nodes_of_its_own():
    """A new bay copies its source column's exceptions with nodes of their own: one node in two places of a tree
    would make an edit of one change both."""
    row = Node.repeat("x", 4, [(Size("flt", 60), tile())], role="floor")
    floors = Node.repeat("y", 3, [(Size("flt", 90), row)], role="floors")
    floors.exceptions = [Override(1, (0, j, 1, 2), node=leaf("balcony")) for j in range(4)]
    wider = set_parameter(Procedure(240, 270, floors), "bays", 6)
    nodes = [id(n) for _, node in wider.nodes() for o in node.exceptions if o.node is not None
             for _, n in o.node.walk()]
    assert len(nodes) == len(set(nodes))


def test_two_bays_fewer_never_take_a_door():
    """Two bays fewer on a ground floor of shops and three doors take two shops out; the cells to take are chosen
    before any goes (the second was chosen by indices the first had moved, and a door went)."""
    proc = shops_under_bays(door=0, bays=7)
    ground = next(n for _, n in proc.nodes() if n.role == "ground")
    for j in (2, 4):
        ground.children[j] = cell("door")
    narrower = set_parameter(proc, "bays", 5)
    assert len(boxes(narrower, "door")) == 3 and len(boxes(narrower, "shop")) == 2
