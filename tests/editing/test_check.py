"""The edit check: an edit of a count judged from the facade before and after, as a person looks at it."""

import numpy as np
from grammar_helpers import example, tile

from facaid.editing.check import band_holds, band_lattice, check_edits, insertion, judge, judge_insert
from facaid.editing.parameters import set_parameter
from facaid.generator import generate_procedure
from facaid.grammar.execute import label_map
from facaid.grammar.nodes import Node, Override, Size
from facaid.grammar.procedure import Procedure
from facaid.labels import LABEL_ID


def floors_map(n: int, odd: int | None = None) -> np.ndarray:
    """A facade of n floors of 20 px, each a window row (label 2) on wall (1); floor ``odd`` has no windows."""
    rows = []
    for i in range(n):
        floor = np.ones((20, 60), dtype=np.uint8)
        if i != odd:
            floor[5:15, 10:20] = floor[5:15, 40:50] = 2
        rows.append(floor)
    ground = np.full((15, 60), 3, dtype=np.uint8)
    return np.concatenate([np.ones((10, 60), dtype=np.uint8), *rows, ground])


def test_a_floor_put_in_between_two_is_clean():
    old, new = floors_map(4), floors_map(5)
    at, kept, copy = insertion(old, new, 0.98)
    assert kept == 1.0 and copy == 1.0 and 10 <= at <= 90
    windows = np.array([[10, 15 + 20 * i, 20, 25 + 20 * i] for i in range(5)] +
                       [[40, 15 + 20 * i, 50, 25 + 20 * i] for i in range(5)])
    assert judge_insert(old, new, (4, 2), (5, 2), windows, "y", 0.98).clean


def test_a_floor_put_in_from_the_middle_of_one_row_of_windows_to_the_next_holds_one_row():
    # rows of windows 10 px high at a pitch of 20 px, drawn a pixel off as a reading is: the band put in runs from
    # the middle of one row to the middle of the next, and as it lies it takes in both rows' centres
    rows = [15, 35, 55.5, 75, 95]
    windows = np.array([[x, c - 5, x + 10, c + 5] for c in rows for x in (10, 40)], dtype=float)
    assert band_lattice(windows, 35, 21, "y") == 2  # the centres at 35 and 55.5
    assert band_holds(windows, 35, 21, "y") == 1
    pairs = np.array([[x, c - 3, x + 10, c + 3] for f in range(5) for c in (20 * f + 12, 20 * f + 20)
                      for x in (10, 40)], dtype=float)  # a floor with a mezzanine: two rows of windows a floor
    assert band_holds(pairs, 30, 20, "y") == 2


def test_a_floor_whose_window_has_a_strip_beside_it_grows_the_rows_by_one():
    # each row of windows has a strip of a window 6 px lower beside one of them: counted apart from the facade, the
    # new floor holds two rows (the strip's centre is over half a window's height off); the facade grows by one
    old, new = floors_map(4), floors_map(5)
    windows = np.array([[10, 15 + 20 * i, 20, 25 + 20 * i] for i in range(5)] +
                       [[40, 15 + 20 * i, 50, 25 + 20 * i] for i in range(5)] +
                       [[21, 23 + 20 * i, 23, 29 + 20 * i] for i in range(5)], dtype=float)
    verdict = judge_insert(old, new, (4, 2), (5, 2), windows, "y", 0.98)
    assert band_holds(windows, verdict.at, 20, "y") == 2
    assert verdict.clean
    assert not judge_insert(old, new, (4, 2), (7, 2), windows, "y", 0.98).clean  # two rows more than it holds


def test_a_band_stuck_on_at_the_edge_or_unlike_any_floor_is_not():
    old = floors_map(4)
    under = np.concatenate([old, old[10:30]])  # a floor under the shops, at the image's edge
    verdict = judge_insert(old, under, (4, 2), (5, 2), np.zeros((0, 4)), "y", 0.98)
    assert not verdict.clean and "edge" in verdict.reason
    blank = floors_map(5, odd=2)  # a floor of bare wall: like no floor of the facade
    verdict = judge_insert(old, blank, (4, 2), (4, 2), np.zeros((0, 4)), "y", 0.98)
    assert not verdict.clean


def test_a_blend_of_floors_is_not_a_copy():
    old = floors_map(4)
    new = floors_map(5)
    new[50:70, :] = 1
    new[55:65, 5:55] = 2  # the third floor a ribbon window: like no floor of the old facade
    verdict = judge_insert(old, new, (4, 2), (5, 2), np.zeros((0, 4)), "y", 0.98)
    assert not verdict.clean and verdict.copy < 0.9


def test_edits_of_a_regular_facade_are_clean_both_ways():
    proc = example()
    checks = check_edits(proc)
    assert set(checks) == {"floors+1", "floors-1", "bays+1", "bays-1"}
    assert checks["floors+1"].clean and checks["floors-1"].clean, checks
    more = set_parameter(proc, "floors", 5)
    assert judge(proc, more, "floors", 1).clean and label_map(more).shape[0] > label_map(proc).shape[0]


def test_fewer_floors_make_a_lower_facade():
    proc = generate_procedure(5003)
    fewer = set_parameter(proc, "floors", 2)
    assert fewer.height < proc.height - 50


def test_a_second_door_is_not_clean():
    """A new bay whose ground-floor cell is a door (a tree whose typical ground tile is one) adds a door: not clean
    however alike the band, since the entrance stays one (issue 67's trial)."""
    row = Node.repeat("x", 4, [(Size("flt", 60), tile())], role="floor")
    floors = Node.repeat("y", 3, [(Size("flt", 90), row)], role="floors")
    ground = Node.repeat("x", 4, [(Size("flt", 60), tile(sill=False, window="door"))], role="ground")
    ground.exceptions = [Override(c, (0, 1, 1), node=Node.leaf("shop")) for c in (0, 1, 3)]
    proc = Procedure(240, 370, Node.split("y", [(Size("flt", 270), floors), (Size("flt", 100), ground)]))
    verdict = check_edits(proc, (("bays", 1),))["bays+1"]
    assert not verdict.clean and verdict.reason == "the doors went from 1 to 2"


def test_a_new_bay_of_a_row_of_entrances_brings_its_door():
    """Where every bay has a door of its own (a row of shop doors), a bay more is one more of them."""
    row = Node.repeat("x", 4, [(Size("flt", 60), tile())], role="floor")
    floors = Node.repeat("y", 3, [(Size("flt", 90), row)], role="floors")
    ground = Node.repeat("x", 4, [(Size("flt", 60), tile(sill=False, window="door"))], role="ground")
    proc = Procedure(240, 370, Node.split("y", [(Size("flt", 270), floors), (Size("flt", 100), ground)]))
    verdicts = check_edits(proc)
    assert verdicts["bays+1"].clean and verdicts["bays-1"].clean, verdicts
    more = set_parameter(proc, "bays", 5)
    assert (label_map(more) == LABEL_ID["door"]).any(axis=0).reshape(-1).sum() == 5 * 30  # five doors, 30 px each


def test_a_floor_fewer_takes_a_floor_the_facade_keeps_a_twin_of():
    from grammar_helpers import facade

    from facaid.editing.floors import twins
    from facaid.grammar.nodes import Node, Size

    def row(window: str) -> Node:
        return Node.repeat("x", 5, [(Size("flt", 60), tile(window=window))], role="floor")

    # the repeat's own floor once (copy 0), two floors of closed blinds, and one of balconies: the plain floor is
    # the one fewest exceptions change, but no floor left is like it; a floor of blinds has its twin
    proc = facade([Override(1, (0,), node=row("blind")), Override(2, (0,), node=row("blind")),
                   Override(3, (0,), node=row("balcony"))])
    edges = np.array([40.0, 130.0, 220.0, 310.0, 400.0])
    alike = twins(label_map(proc), edges)
    assert alike[1] == alike[2] == 1.0 and max(alike[0], alike[3]) < 0.9
    fewer = set_parameter(proc, "floors", 3)
    floors = fewer.root.children[1]
    assert [o.copy for o in floors.exceptions] == [1, 2]  # a floor of blinds went; the plain one stayed
    verdict = check_edits(proc)["floors-1"]
    assert verdict.clean, verdict


def test_a_floor_fewer_leaves_the_copy_that_alone_lays_out_the_floors_pattern():
    from grammar_helpers import facade

    from facaid.editing.floors import plain_floor
    from facaid.editing.instances import Instances
    from facaid.editing.parameters import _floor_repeats, normalised
    from facaid.grammar.nodes import Node, Size

    def row(window: str) -> Node:
        out = Node.repeat("x", 5, [(Size("flt", 60), tile(window=window))], role="floor")
        out.exceptions = [Override(2, (0,), size=Size("flt", 90))]
        return out

    # the pattern's row has an exception of its own (its middle bay wider), so a copy must keep laying it out:
    # copy 3 alone does; copy 2 is drawn alike by a node of its own, copies 0 and 1 are floors of blinds
    proc = facade([Override(0, (0,), node=row("blind")), Override(1, (0,), node=row("blind")),
                   Override(2, (0,), node=row("window"))], bays=[Override(2, (0,), size=Size("flt", 90))])
    out = normalised(proc)
    inst = Instances(out)
    floors = _floor_repeats(out, inst, "floor", "y")[0][1]
    assert plain_floor(out, floors, inst) == 3  # a floor more repeats the pattern's own copy
    assert plain_floor(out, floors, inst, fewer=True) == 2  # a floor fewer takes its twin
    verdict = check_edits(proc)["floors-1"]
    assert verdict.clean, verdict
