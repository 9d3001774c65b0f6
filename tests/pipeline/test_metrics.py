import numpy as np
import pytest

from facaid.generator import generate
from facaid.grammar.execute import to_segmentation
from facaid.labels import LABEL_ID
from facaid.metrics import element_counts
from facaid.segmentation import Rect, Segmentation, flatten

W, D = LABEL_ID["window"], LABEL_ID["door"]


def counts(*rects: tuple[int, int, int, int, int]) -> np.ndarray:
    wall = Rect(LABEL_ID["facade"], 0, 0, 100, 100)
    return element_counts(Segmentation(100, 100, (wall, *map(Rect._make, rects))))


def test_element_counts_joins_rectangles_that_share_an_edge_or_overlap():
    assert counts()[W] == 0  # the wall is not an element
    assert counts((W, 10, 10, 20, 20), (W, 30, 10, 40, 20))[W] == 2
    assert counts((W, 10, 10, 20, 20), (W, 20, 10, 30, 20))[W] == 1  # side by side
    assert counts((W, 10, 10, 20, 20), (W, 10, 20, 20, 30))[W] == 1  # one on the other
    assert counts((W, 10, 10, 20, 20), (W, 15, 15, 25, 25))[W] == 1  # overlapping
    assert counts((W, 10, 10, 20, 20), (W, 20, 20, 30, 30))[W] == 2  # corners only
    chain = counts((W, 0, 0, 10, 10), (W, 10, 0, 20, 10), (W, 40, 0, 50, 10), (W, 20, 0, 30, 10))
    assert chain[W] == 2  # union over a chain, whatever the order
    mixed = counts((W, 10, 10, 20, 20), (D, 20, 10, 30, 20))
    assert (mixed[W], mixed[D]) == (1, 1)  # classes count apart


@pytest.mark.parametrize("seed", [3, 17, 40])
def test_element_counts_are_the_same_for_any_cover_of_the_picture(seed):
    sample = generate(seed)
    pieces = sample.segmentation
    expected = element_counts(to_segmentation(sample.procedure))
    assert expected.sum() > 0
    assert np.array_equal(element_counts(pieces), expected)
    assert np.array_equal(element_counts(flatten(pieces, wall="footprint")), expected)


def test_compression_counts_the_input_elements_per_element_leaf_of_the_tree():
    from facaid.grammar import Node, Procedure, Size
    from facaid.labels import FACADE
    from facaid.metrics import compression, element_leaves, element_rectangles
    from facaid.segmentation import Rect, Segmentation

    windows = Segmentation(600, 100, (Rect(FACADE, 0, 0, 600, 100),
                                      *(Rect(2, 20 + 100 * i, 20, 80 + 100 * i, 80) for i in range(6))))
    tile = Node.split("x", [(Size("abs", 20), Node.leaf("facade")), (Size("flt", 60), Node.leaf("window")),
                            (Size("abs", 20), Node.leaf("facade"))])
    row = Node.split("y", [(Size("abs", 20), Node.leaf("facade")), (Size("flt", 60), Node.repeat("x", 6, [
        (Size("flt", 100), tile)])), (Size("abs", 20), Node.leaf("facade"))])
    flat = Node.split("x", [(Size("abs", 100), Node.leaf("window")) for _ in range(6)])
    assert element_rectangles(windows) == 6  # the wall rectangle is not an element
    assert element_leaves(Procedure(600, 100, row)) == 1  # one window leaf, repeated: its copies do not count
    assert compression(Procedure(600, 100, row), windows) == 6.0
    assert compression(Procedure(600, 100, flat), windows) == 1.0  # a flat list
    wall = Procedure(600, 100, Node.leaf("facade"))
    assert compression(wall, windows) == float("inf")
    assert compression(wall, Segmentation(600, 100, (Rect(FACADE, 0, 0, 600, 100),))) == 1.0


def test_unexplained_counts_disagreement_away_from_the_inputs_edges():
    from facaid.metrics import unexplained

    given = np.zeros((300, 400), np.uint8)  # 1 %: 4 px along x, 3 px along y
    given[60:120, 100:160] = LABEL_ID["window"]
    moved = given.copy()
    moved[57:122, 97:163] = LABEL_ID["window"]  # every edge off by 2-3 px
    assert unexplained(moved, given) == 0.0
    assert unexplained(given, given) == 0.0
    added = given.copy()
    added[180:240, 250:310] = LABEL_ID["window"]  # a whole window the input lacks
    assert unexplained(added, given) == pytest.approx(3600 / 120_000)
    far = given.copy()
    far[60:120, 100:160] = 0
    far[60:120, 200:260] = LABEL_ID["window"]  # the window drawn 100 px off: its core is unexplained
    assert unexplained(far, given) > 0.02
    assert unexplained(moved, given, edge=0.001) > 0  # a narrower band explains less


def test_reads_through_noise_keeps_a_compact_structure_that_restores_a_missed_window():
    from facaid.grammar.nodes import Node, Size
    from facaid.grammar.procedure import Procedure
    from facaid.pipeline import reads_through_noise
    from facaid.reading.induce import induce_procedure

    tile = Node.split("x", [(Size("abs", 20), Node.leaf("facade")), (Size("abs", 40), Node.leaf("window")),
                            (Size("abs", 20), Node.leaf("facade"))])
    floor = Node.split("y", [(Size("abs", 20), Node.leaf("facade")), (Size("abs", 50), Node.repeat("x", 6, [
        (Size("abs", 80), tile)])), (Size("abs", 20), Node.leaf("facade"))])
    regular = Procedure(480, 450, Node.repeat("y", 5, [(Size("abs", 90), floor)]))
    clean = to_segmentation(regular)
    windows = [r for r in clean.rects if r.label == LABEL_ID["window"]]
    walls = [r for r in clean.rects if r.label != LABEL_ID["window"]]
    jittered = [Rect(r.label, r.x0 + (i % 3) - 1, r.y0 + (i % 2), r.x1 - (i % 2), r.y1 + (i % 3) - 1)
                for i, r in enumerate(windows)]
    drawn = Segmentation(480, 450, tuple(walls + jittered[:7] + jittered[8:]))  # one window missed
    induced = induce_procedure(flatten(drawn))
    assert reads_through_noise(regular, induced, flatten(drawn))  # 30 windows in 3 leaves; one window unexplained
    wrong = Procedure(480, 450, Node.repeat("y", 5, [(Size("abs", 90), Node.split("y", [
        (Size("abs", 20), Node.leaf("facade")), (Size("abs", 50), Node.leaf("window")),
        (Size("abs", 20), Node.leaf("facade"))]))]))
    assert not reads_through_noise(wrong, induced, flatten(drawn))  # compact, but bands where windows are not
    assert not reads_through_noise(induced, induced, flatten(drawn))  # no more compact than the induced one
