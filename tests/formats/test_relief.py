"""The relief the 3D exports share: its rows are the label map's rectangles, each with the path of the leaf that
drew it, and its boxes are those rectangles in metres with y up."""

import numpy as np
import pytest

from facaid.formats.relief import procedure_relief
from facaid.generator import generate
from facaid.grammar.execute import leaf_array
from facaid.labels import LABELS


@pytest.mark.parametrize("seed", [2, 3, 7])
def test_rows_are_the_label_maps_and_each_path_names_the_leaf_that_drew_it(seed):
    proc = generate(seed).procedure
    relief = procedure_relief(proc, 0.05)
    assert np.array_equal(relief.rows, leaf_array(proc))
    nodes = dict(proc.nodes())
    for label, path in zip(relief.labels(), relief.paths, strict=True):
        assert nodes[path].is_leaf and nodes[path].label == label
    assert len(set(relief.paths)) < len(relief.paths)  # a repeat's copies share their leaf
    x0, y0, x1, y1 = relief.rows[0, 1:]
    assert np.allclose(relief.boxes()[0], np.array([x0, x1, relief.height - y1, relief.height - y0]) * 0.05)
    assert LABELS[relief.rows[0, 0]] == relief.labels()[0]


def test_the_scale_says_where_it_came_from():
    proc = generate(3).procedure
    assert procedure_relief(proc, 0.02).describe() == "0.02 m per pixel (given): 8.88 m x 15.94 m"
    assert "(a storey 3 m tall)" in procedure_relief(proc).describe()
    given = procedure_relief(proc, 0.02, "the photo's\nreal width, 8.88 m")
    assert "(the photo's real width, 8.88 m)" in given.describe()  # on one line
