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


def reference_distance(a: Node, b: Node) -> int:
    """The recursive definition of the ordered forest edit distance (exponential without the cache, so only
    for small trees): delete the rightmost root of one forest, insert that of the other, or match the two
    and split into their children and the rest."""
    from functools import cache

    def tree(node, mode=""):
        return node_label(node, mode), tuple(tree(c, s.mode) for s, c in zip(node.sizes, node.children, strict=True))

    def size(f):
        return sum(1 + size(kids) for _, kids in f)

    @cache
    def fd(f, g):
        if not f or not g:
            return size(f) + size(g)
        (lf, kf), (lg, kg) = f[-1], g[-1]
        return min(fd(f[:-1] + kf, g) + 1, fd(f, g[:-1] + kg) + 1,
                   fd(kf, kg) + fd(f[:-1], g[:-1]) + (lf != lg))

    return fd((tree(a),), (tree(b),))


def random_tree(rng, depth=0) -> Node:
    if depth >= 3 or rng.random() < 0.35:
        return leaf(rng.choice(["window", "door", "sill"]))
    kids = [random_tree(rng, depth + 1) for _ in range(rng.randint(1, 3))]
    return Node.split(rng.choice("xy"), [(Size(rng.choice(["flt", "abs"]), 1), c) for c in kids])


def test_distance_matches_the_recursive_definition_on_random_trees():
    import random

    rng = random.Random(0)
    differ = 0
    for _ in range(300):
        a, b = random_tree(rng), random_tree(rng)
        d = tree_edit_distance(a, b)
        assert d == reference_distance(a, b)
        differ += d > 0
    assert differ > 250  # the pairs are mostly different, so the dynamic programme is exercised
