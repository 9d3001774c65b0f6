import numpy as np
from hypothesis import example, given, settings
from hypothesis import strategies as st

from facaid.generator import STYLE_NAMES, generate_procedure
from facaid.generator.canonical import IMPLICIT, MIN_GAP, canonical
from facaid.generator.dataset import sample_seed
from facaid.grammar import Procedure, execute
from facaid.grammar.execute import first_boxes, leaf_array
from facaid.grammar.floors import merge_floor_runs, merge_repeated_floors, structure
from facaid.grammar.nodes import Node, Size


def wall(role=None):
    return Node.leaf("facade", role=role)


def test_invisible_wall_goes_and_a_lone_child_takes_the_split_s_place():
    column = Node.split("y", [(Size("flt", 2), wall()), (Size("abs", 100), Node.leaf("window")),
                              (Size("flt", 300), wall())])
    tile = Node.split("x", [(Size("flt", 1), wall()), (Size("abs", 500), column), (Size("flt", 1), wall())],
                      role="tile")
    proc = canonical(Procedure(512, 402, tile))
    root = proc.root
    # the side walls are 6 pixels wide, over 512 / 128 = 4: they stay
    assert root.rule == "split" and len(root.children) == 3
    column = root.children[1]
    assert [c.label for c in column.children] == ["window", "facade"]  # the 2-pixel top wall went
    assert [s.mode for s in column.sizes] == ["abs", "flt"]


def test_lone_child_inherits_the_role_and_a_centre_that_went_clears_center():
    inner = Node.split("y", [(Size("abs", 1), wall()), (Size("flt", 99), Node.leaf("window"))])
    tile = Node.split("x", [(Size("abs", 1), wall()), (Size("flt", 100), inner)], role="tile")
    proc = canonical(Procedure(256, 256, tile))  # 1-pixel walls, under 256 / 128 = 2 pixels
    assert (proc.root.rule, proc.root.label, proc.root.role) == ("leaf", "window", "tile")

    # the centre (a half-pixel door) goes: window and its reflection remain, a mirror without centre
    m = Node.mirror("x", [(Size("flt", 100), Node.leaf("window")), (Size("abs", 0.5), Node.leaf("door"))],
                    center=True)
    proc = canonical(Procedure(256, 256, m))
    assert proc.root.rule == "mirror" and not proc.root.center
    assert [c.label for c in proc.root.children] == ["window"]

    # a side child goes: the centre stays the centre
    m = Node.mirror("x", [(Size("abs", 0.5), Node.leaf("door")), (Size("flt", 60), Node.leaf("window")),
                          (Size("flt", 60), wall())], center=True)
    proc = canonical(Procedure(256, 256, m))
    assert proc.root.center and [c.label for c in proc.root.children] == ["window", "facade"]


def test_a_floor_whose_margins_went_keeps_the_floor_s_role():
    # the builder's floor: margins (role floor) around a row of bays; margins of 1 px, under 512 / 128 = 4 px
    def floor(margin):
        row = Node.repeat("x", 4, [(Size("flt", 1), Node.leaf("window"))], role="bay")
        return Node.split("x", [(Size("abs", margin), wall()), (Size("flt", 500), row),
                                (Size("abs", margin), wall())], role="floor")

    floors = Node.split("y", [(Size("flt", 1), floor(1)), (Size("flt", 1), floor(1))], role="floors")
    proc = canonical(Procedure(512, 400, floors))
    # both floors are the row now, with the role a floor without margins gets: so they merge into one repeat
    assert (proc.root.rule, proc.root.role, proc.root.count) == ("repeat", "floors", 2)
    assert (proc.root.children[0].rule, proc.root.children[0].role) == ("repeat", "floor")
    # visible margins stay, and so do the roles
    proc = canonical(Procedure(512, 400, Node.split("y", [(Size("flt", 1), floor(8))], role="floors")))
    visible = proc.root.children[0]
    assert (visible.role, len(visible.children), visible.children[1].role) == ("floor", 3, "bay")


def test_canonical_keeps_the_picture_within_the_removed_gaps():
    column = Node.split("y", [(Size("flt", 3), wall()), (Size("abs", 200), Node.leaf("window")),
                              (Size("flt", 197), wall())])
    proc = Procedure(400, 400, Node.split("x", [(Size("flt", 1), wall()), (Size("abs", 100), column),
                                                (Size("flt", 1), wall())]))
    before = leaf_array(proc)
    after = leaf_array(canonical(proc))
    win_before = before[before[:, 0] == 2][0, 1:]
    win_after = after[after[:, 0] == 2][0, 1:]
    assert np.abs(win_before - win_after).max() <= 3


@settings(max_examples=60, deadline=None)
@given(st.integers(min_value=0, max_value=2**63), st.sampled_from((None, *STYLE_NAMES)))
@example(18582, "haussmann")  # two runs of floors told apart only by a gap that canonical removed
def test_generated_procedures_show_every_node(seed, style):
    proc = generate_procedure(seed, style)
    boxes = first_boxes(proc)
    for _, node in proc.nodes():
        if node.rule in ("split", "mirror"):
            if node.rule == "split" or node.center:
                assert len(node.children) >= 2
            for child in node.children:
                if child.rule == "leaf" and id(child) in boxes:
                    x0, y0, x1, y1 = boxes[id(child)]
                    extent, side = (x1 - x0, proc.width) if node.axis == "x" else (y1 - y0, proc.height)
                    assert extent >= (MIN_GAP * side if child.label in IMPLICIT else 1.0) - 1e-6
        if node.role == "floors" and node.rule == "split":  # runs of floors that look alike are one repeat
            for a, b in zip(node.children, node.children[1:], strict=False):
                assert structure(a) != structure(b)
    assert len(execute(proc)) > 0


def test_runs_of_floors_that_look_alike_become_one_repeat():
    def floor(window_h):
        return Node.split("y", [(Size("flt", 1), wall()), (Size("abs", window_h), Node.leaf("window"))],
                          role="floor")

    band = (Size("abs", 3), Node.leaf("molding", role="band"))
    runs = Node.split("y", [
        (Size("flt", 60), Node.repeat("y", 2, [(Size("flt", 27), floor(20)), band], role="floors")),
        (Size("flt", 90), Node.repeat("y", 3, [(Size("flt", 27), floor(21)), band], role="floors")),
        (Size("flt", 30), Node.split("y", [(Size("flt", 1), wall()), (Size("abs", 10), Node.leaf("door"))],
                                     role="floor")),
    ], role="floors")
    merge_floor_runs(runs)
    assert [(c.rule, c.count) for c in runs.children] == [("repeat", 5), ("split", None)]
    assert [s.value for s in runs.sizes] == [150, 30]
    assert runs.children[0].children[0].children[1].label == "window"

    # a lone floor followed by a repeat of the same floor: one repeat that fills the whole split
    alike = Node.split("y", [(Size("flt", 30), floor(20)),
                             (Size("flt", 60), Node.repeat("y", 2, [(Size("flt", 30), floor(22))], role="floors"))],
                       role="floors")
    proc = canonical(Procedure(300, 900, alike))
    assert (proc.root.rule, proc.root.count, proc.root.role) == ("repeat", 3, "floors")
    assert len(execute(proc)) > 0


def _unrolled(node):
    """A tree drawing the same picture with every repeat of floors written out as single floors."""
    node.children = [_unrolled(c) for c in node.children]
    if node.rule == "split" and node.role == "floors":
        sizes, children = [], []
        for size, child in zip(node.sizes, node.children, strict=True):
            if child.rule == "repeat" and child.role == "floors" and len(child.children) == 1:
                for _ in range(child.count):
                    sizes.append(Size("flt", size.value / child.count))
                    copy = child.children[0].copy()
                    copy.role = copy.role or "floor"
                    children.append(copy)
            else:
                sizes.append(size)
                children.append(child)
        node.sizes, node.children = sizes, children
    return node


def test_decoded_floors_written_out_merge_back_into_the_canonical_repeat():
    found = 0
    for seed in range(60):
        proc = generate_procedure(seed)
        floors = [n for n in proc.root.bfs() if n.rule == "split" and n.role == "floors"]
        runs = [c for n in floors for c in n.children if c.rule == "repeat" and len(c.children) == 1]
        if not runs:
            continue
        found += 1
        root = _unrolled(proc.root.copy())
        assert structure(root) != structure(proc.root)
        merged = merge_repeated_floors(root, tolerance=0.25)
        assert structure(merged) == structure(proc.root), seed
        picture = leaf_array(proc)
        assert np.array_equal(leaf_array(Procedure(proc.width, proc.height, merged)), picture)
    assert found >= 5


def test_floors_of_other_sizes_stay_apart_under_a_tolerance():
    def floor(window_h):
        return Node.split("y", [(Size("flt", 10), wall()), (Size("abs", window_h), Node.leaf("window"))],
                          role="floor")

    def floors(*heights):
        return Node.split("y", [(Size("flt", 30), floor(h)) for h in heights], role="floors")

    lone = merge_repeated_floors(Node.split("x", [(Size("flt", 1), floors(20, 22))]), tolerance=0.25)
    assert (lone.children[0].rule, lone.children[0].count, lone.children[0].role) == ("repeat", 2, "floors")
    apart = merge_repeated_floors(floors(20, 30, 31), tolerance=0.25)  # 20 against 30: a third apart
    assert [(c.rule, c.count) for c in apart.children] == [("split", None), ("repeat", 2)]
    assert merge_repeated_floors(floors(20, 30), tolerance=None).rule == "repeat"  # no size check


def test_an_entrance_in_the_middle_of_an_odd_row_is_a_mirror():
    seen = 0
    for seed in range(400):
        proc = generate_procedure(seed)
        for _, node in proc.nodes():
            if node.role == "bay" and node.rule == "split":
                bays = [c for c in node.children if c.label != "pillar"]
                doors = [i for i, c in enumerate(bays) if c.role == "entrance"]
                if len(bays) % 2 == 1 and doors:
                    seen += 1
                    assert doors != [len(bays) // 2]
    assert seen > 10


def _bay(window: float) -> Node:
    return Node.split("y", [(Size("flt", 10), wall()), (Size("abs", window), Node.leaf("window", role="window")),
                            (Size("flt", 5), wall())], role="tile")


def _mirrored_row(pillar: bool, centre: Node) -> Node:
    if pillar:
        side = Node.repeat("x", 3, [(Size("abs", 4), Node.leaf("pillar")), (Size("flt", 40), _bay(30))])
        return Node.mirror("x", [(Size("flt", 132), side), (Size("abs", 4), Node.leaf("pillar")),
                                 (Size("flt", 40), centre)], center=True, role="bay")
    side = Node.repeat("x", 3, [(Size("flt", 40), _bay(30))])
    return Node.mirror("x", [(Size("flt", 120), side), (Size("flt", 40), centre)], center=True, role="bay")


def test_a_row_mirrored_around_a_centre_bay_like_the_others_becomes_a_repeat():
    for pillar in (False, True):
        width = 7 * 40 + (8 * 4 if pillar else 0)
        row = _mirrored_row(pillar, _bay(30))
        drawn = sorted(execute(Procedure(width, 60, row.copy())))
        proc = canonical(Procedure(width, 60, row))
        assert proc.root.rule == "repeat" and proc.root.count == 7 and proc.root.role == "bay"
        assert proc.root.tail == (1 if pillar else 0)
        np.testing.assert_allclose(sorted(execute(proc)), drawn, atol=1e-9)  # the same picture
        # a centre bay that differs (a wider window) stays a mirror
        assert canonical(Procedure(width, 60, _mirrored_row(pillar, _bay(36)))).root.rule == "mirror"
    # a pillar of another width before the centre is not the row's pattern either
    row = _mirrored_row(True, _bay(30))
    row.sizes[1] = Size("abs", 6)
    assert canonical(Procedure(7 * 40 + 34, 60, row)).root.rule == "mirror"


def test_generated_rows_never_mirror_a_centre_bay_like_the_others():
    mirrors = 0
    for i in range(540, 600):  # held-out facade 556 of dataset seed 1000 had one
        seed = sample_seed(1000, i)
        for _, node in generate_procedure(seed).nodes():
            if node.rule == "mirror" and node.role == "bay" and node.children[0].rule == "repeat":
                mirrors += 1
                assert node.children[-1].to_dict() != node.children[0].children[-1].to_dict(), seed
    assert mirrors > 3
