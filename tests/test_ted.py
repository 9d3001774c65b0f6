from facaid.evaluation.ted import node_label, tree_edit_distance, tree_size
from facaid.generator import generate_procedure
from facaid.grammar import Node, Size

F = Size("flt", 1)


def split(*children, axis="x"):
    return Node.split(axis, [(F, c) for c in children])


def leaf(name):
    return Node.leaf(name)


def test_identical_trees_have_distance_zero():
    p = generate_procedure(3)
    assert tree_edit_distance(p.root, generate_procedure(3).root) == 0


def test_unit_costs():
    a = split(leaf("window"), leaf("door"))
    assert tree_edit_distance(a, split(leaf("window"), leaf("shop"))) == 1  # relabel
    assert tree_edit_distance(a, split(leaf("window"))) == 1  # delete
    assert tree_edit_distance(a, split(leaf("window"), leaf("door"), leaf("sill"))) == 1  # insert
    assert tree_edit_distance(a, split(leaf("window"), leaf("door"), axis="y")) == 1  # root relabel
    # the classic example: delete an inner node and keep its children
    b = split(split(leaf("window"), leaf("door")), leaf("sill"))
    c = split(leaf("window"), leaf("door"), leaf("sill"))
    assert tree_edit_distance(b, c) == 1
    assert tree_edit_distance(c, b) == 1


def test_distance_is_symmetric_and_bounded_by_sizes():
    for s in range(4):
        a, b = generate_procedure(s).root, generate_procedure(s + 10).root
        d = tree_edit_distance(a, b)
        assert d == tree_edit_distance(b, a)
        assert 0 < d <= tree_size(a) + tree_size(b)


def test_sizes_count_by_mode_not_value():
    a = Node.split("x", [(Size("abs", 3), leaf("window"))])
    b = Node.split("x", [(Size("abs", 7), leaf("window"))])
    c = Node.split("x", [(Size("flt", 3), leaf("window"))])
    assert tree_edit_distance(a, b) == 0
    assert tree_edit_distance(a, c) == 1
    assert node_label(leaf("door"), "abs") != node_label(leaf("door"), "rel")
