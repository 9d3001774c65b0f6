import numpy as np
import pytest

from facaid.decoding.composition import compose, single_regions
from facaid.evaluation.ted import tree_edit_distance
from facaid.grammar import Node, Procedure, Size
from facaid.grammar.execute import to_segmentation
from facaid.metrics import element_counts_within, scaled_label_map

F = Size("flt", 1)


def column(*items, axis="y"):
    return Node.split(axis, [(size, Node.leaf(label) if isinstance(label, str) else label) for size, label in items])


def building(label):
    """A building 100 wide: wall, one element 40 high, wall."""
    return column((F, "facade"), (Size("abs", 40), column((F, "facade"), (Size("abs", 30), label), (F, "facade"),
                                                              axis="x")), (F, "facade"))


def street(left, right):
    return Procedure(200, 120, Node.split("x", [(Size("abs", 100), left), (F, right)]))


def inputs(proc):
    seg = to_segmentation(proc)
    return seg.to_array(), scaled_label_map(seg, 0.25)


def test_each_building_comes_from_the_candidate_that_reproduces_it():
    truth = street(building("window"), building("door"))
    rows, target = inputs(truth)
    left_right = street(building("window"), Node.leaf("facade"))  # ranked first: the right building missing
    right_right = street(building("shop"), building("door"))  # the left building's element mislabelled
    proc, swaps = compose([left_right, right_right], [-1.0, -2.0], rows, target)
    assert swaps == 1 and tree_edit_distance(proc.root, truth.root) == 0
    assert tree_edit_distance(left_right.root, truth.root) > 0  # the inputs are left as they were
    # the first candidate keeps what it reproduces best
    same, none = compose([truth, right_right], [-1.0, -3.0], rows, target)
    assert none == 0 and tree_edit_distance(same.root, truth.root) == 0 and same is not truth


def test_a_refused_swap_is_undone_and_depth_zero_swaps_nothing():
    truth = street(building("window"), building("door"))
    rows, target = inputs(truth)
    first, other = street(building("window"), Node.leaf("facade")), street(building("shop"), building("door"))
    proc, swaps = compose([first, other], [0.0, 0.0], rows, target, valid=lambda p: False)
    assert swaps == 0 and tree_edit_distance(proc.root, first.root) == 0
    assert compose([first, other], [0.0, 0.0], rows, target, depth=0)[1] == 0


def test_ties_go_to_the_likelier_candidate():
    truth = street(building("window"), building("door"))
    rows, target = inputs(truth)
    first = street(building("window"), Node.leaf("facade"))
    a = street(building("window"), building("door"))
    b = street(building("window"), building("door"))
    b.root.children[1].children[2] = column((F, "facade"), (F, "facade"))  # the same picture, another tree
    assert tree_edit_distance(a.root, b.root) > 0 and inputs(b)[1].tolist() == target.tolist()
    for logprobs, winner in (([0.0, -5.0, -1.0], a), ([0.0, -1.0, -5.0], b)):
        proc, swaps = compose([first, b, a], logprobs, rows, target)
        assert swaps == 1 and tree_edit_distance(proc.root, winner.root) == 0
    # where the first reproduces a region better, a likelier candidate's subtree stays out
    worse = street(building("shop"), building("door"))
    proc, _ = compose([truth, worse], [-9.0, 0.0], rows, target)
    assert tree_edit_distance(proc.root, truth.root) == 0


def test_regions_stop_at_repeats_and_mirrors():
    inner = building("window")
    root = Node.split("x", [(F, Node.repeat("x", 2, [(F, inner)])), (F, Node.mirror("x", [(F, Node.leaf("door"))]))])
    nodes = [n for n, _, _, _ in single_regions(root)]
    assert len(nodes) == 3 and inner not in nodes
    assert [d for _, _, _, d in single_regions(building("door"), depth=1)] == [0, 1, 1, 1]


def test_elements_count_by_centre_within_a_box():
    rows = np.array([[2, 0, 0, 10, 10], [2, 10, 0, 20, 10], [2, 40, 0, 50, 10], [3, 95, 0, 120, 10]])
    counts = element_counts_within(rows, (0, 0, 100, 20))
    assert counts[2] == 2  # the first two touch: one element; the third is apart
    assert counts[3] == 0  # its centre (107.5) lies outside, though it reaches in


def test_compose_checks_its_arguments():
    with pytest.raises(ValueError, match="log-probability"):
        compose([street(building("window"), building("door"))], [], np.zeros((0, 5)), np.zeros((30, 50)))
