"""The editability figures: windows as connected window-or-blind regions, their rows and columns, and what
floors + 1 and bays + 1 do to them."""

import numpy as np
import pytest
from grammar_helpers import example, facade

from facaid.editing.describes import describes
from facaid.evaluation.editability import editability, kept_elements
from facaid.grammar.execute import flat_rows
from facaid.grammar.nodes import Node, Size
from facaid.grammar.procedure import Procedure
from facaid.reading.windows import lattice, window_boxes


def test_a_window_cut_by_its_blind_counts_once():
    rows = np.array([[2, 0, 0, 10, 5], [7, 0, 5, 10, 12], [2, 0, 12, 10, 20], [5, 0, 20, 10, 22],
                     [2, 30, 0, 40, 20]])
    assert window_boxes(rows).tolist() == [[0, 0, 10, 20], [30, 0, 40, 20]]
    assert lattice(rows) == (1, 2)


def test_rows_and_columns_of_a_facade_with_exceptions():
    proc = example()
    assert lattice(flat_rows(proc)) == (4, 5)
    got = editability(proc, (4, 5))
    assert {k: got[k] for k in ("rows", "columns", "floors", "bays", "floors_plus_one", "bays_plus_one",
                                "eligible")} == {"rows": 4, "columns": 5, "floors": True, "bays": True,
                                                 "floors_plus_one": True, "bays_plus_one": True, "eligible": True}
    assert got["floors_clean"], got["floors_why"]


def test_a_facade_without_repeats_cannot_be_edited():
    tile = facade([]).root.children[1].children[0].children[0]
    row = Node.split("x", [(Size("flt", 60), tile.copy()) for _ in range(3)])
    proc = Procedure(180, 200, Node.split("y", [(Size("flt", 100), row), (Size("flt", 100), row.copy())]))
    got = editability(proc, (2, 3))
    assert (got["rows"], got["columns"]) == (2, 3)
    assert not got["floors"] and not got["floors_plus_one"] and not got["bays_plus_one"]


def test_kept_elements_forgives_a_thin_element_a_little_off():
    target = np.ones((40, 40), dtype=np.uint8)
    target[10:13, 5:30] = 5  # a 3 px sill
    rows = np.array([[1, 0, 0, 40, 10], [5, 5, 10, 30, 13], [1, 0, 10, 5, 13], [1, 30, 10, 40, 13],
                     [1, 0, 13, 40, 40]])
    moved = np.ones_like(target)
    moved[12:15, 5:30] = 5  # drawn 2 px lower: still there
    assert kept_elements(rows, target, moved) == (1, 1)
    assert kept_elements(rows, target, np.ones_like(target)) == (1, 0)  # left out


def test_parameters_describe_the_building():
    proc = example()
    got = describes(proc, flat_rows(proc))
    assert got["floor_height_ok"] and got["tile_width_ok"]
    assert got["floor_height"] == pytest.approx(got["floor_pitch"], rel=0.15)
