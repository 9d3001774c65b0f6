"""The relief the 3D exports share: its rows are the elements the annotations hold and the pieces of wall around
them, each with the path of the leaf that draws the most of it; its parts leave each row open where an element
painted over it sits behind it; its boxes are in metres with y up."""

import numpy as np
import pytest
from grammar_helpers import example

from facaid.formats.annotation import as_annotated, element_array
from facaid.formats.relief import DEPTHS, procedure_relief
from facaid.generator import generate
from facaid.grammar.execute import leaf_array, to_segmentation
from facaid.grammar.nodes import Node, Size
from facaid.grammar.procedure import Procedure
from facaid.labels import FACADE, LABELS
from facaid.segmentation import rasterize


@pytest.mark.parametrize("make", [lambda: generate(2).procedure, lambda: generate(3).procedure,
                                  lambda: generate(7).procedure, example])
def test_rows_are_the_elements_and_the_wall_and_each_path_names_a_leaf_that_draws_it(make):
    proc = make()
    relief = procedure_relief(proc, 0.05)
    w, h = round(proc.width), round(proc.height)
    elements = element_array(w, h, leaf_array(proc))
    assert np.array_equal(relief.rows[relief.rows[:, 0] != FACADE], elements)
    nodes = dict(proc.nodes())
    for label, path in zip(relief.labels(), relief.paths, strict=True):
        assert nodes[path].is_leaf and nodes[path].label == label
    assert len(set(relief.paths)) < len(relief.paths)  # a repeat's copies share their leaf
    x0, y0, x1, y1 = relief.rows[0, 1:]
    assert np.allclose(relief.boxes()[0], np.array([x0, x1, relief.height - y1, relief.height - y0]) * 0.05)
    assert LABELS[relief.rows[0, 0]] == relief.labels()[0]
    # seen from the front (the nearest part hides those behind it), the parts paint what the annotations paint
    seen, depth = np.zeros((h, w), dtype=np.uint8), np.full((h, w), -np.inf)
    for row, px0, py0, px1, py1 in relief.parts.tolist():
        d = DEPTHS[LABELS[relief.rows[row, 0]]]
        nearer = depth[py0:py1, px0:px1] < d
        seen[py0:py1, px0:px1][nearer] = relief.rows[row, 0]
        depth[py0:py1, px0:px1][nearer] = d
    assert np.array_equal(seen, rasterize(as_annotated(to_segmentation(proc))))


def test_an_element_is_left_open_where_what_is_painted_over_it_sits_behind_it():
    """A cornice with a window reaching into its bottom edge: one cornice (its box, as an annotator draws it) and
    one window; the cornice stands out, so it is drawn around the window's top, which shows through it."""
    cornice = Node.split("x", [(Size("abs", 10), Node.leaf("cornice")), (Size("abs", 20), Node.leaf("window")),
                               (Size("abs", 10), Node.leaf("cornice"))])
    window = Node.split("x", [(Size("abs", 10), Node.leaf("facade")), (Size("abs", 20), Node.leaf("window")),
                              (Size("abs", 10), Node.leaf("facade"))])
    root = Node.split("y", [(Size("abs", 10), Node.leaf("cornice")), (Size("abs", 5), cornice),
                            (Size("flt", 1), window)])
    proc = Procedure(width=40, height=40, root=root)
    relief = procedure_relief(proc, 0.1)
    rows = {LABELS[r[0]]: (i, tuple(r[1:])) for i, r in enumerate(relief.rows.tolist()) if r[0] != FACADE}
    assert rows["cornice"][1] == (0, 0, 40, 15) and rows["window"][1] == (10, 10, 30, 40)
    cut = relief.parts_of(rows["cornice"][0])[:, 1:].tolist()
    assert sorted(map(tuple, cut)) == [(0, 0, 40, 10), (0, 10, 10, 15), (30, 10, 40, 15)]
    assert relief.parts_of(rows["window"][0])[:, 1:].tolist() == [[10, 10, 30, 40]]  # nothing in front of it


def test_the_scale_says_where_it_came_from():
    proc = generate(3).procedure
    assert procedure_relief(proc, 0.02).describe() == "0.02 m per pixel (given): 8.88 m x 15.94 m"
    assert "(a storey 3 m tall)" in procedure_relief(proc).describe()
    given = procedure_relief(proc, 0.02, "the photo's\nreal width, 8.88 m")
    assert "(the photo's real width, 8.88 m)" in given.describe()  # on one line
