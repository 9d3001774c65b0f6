"""The editability figures: windows as connected window-or-blind regions, their rows and columns, and what
floors + 1 and bays + 1 do to them."""

import numpy as np
from grammar_helpers import example, facade

from facaid.evaluation.editability import editability, lattice, window_boxes
from facaid.grammar.execute import flat_rows
from facaid.grammar.procedure import Node, Procedure, Size


def test_a_window_cut_by_its_blind_counts_once():
    rows = np.array([[2, 0, 0, 10, 5], [7, 0, 5, 10, 12], [2, 0, 12, 10, 20], [5, 0, 20, 10, 22],
                     [2, 30, 0, 40, 20]])
    assert window_boxes(rows).tolist() == [[0, 0, 10, 20], [30, 0, 40, 20]]
    assert lattice(rows) == (1, 2)


def test_rows_and_columns_of_a_facade_with_exceptions():
    proc = example()
    assert lattice(flat_rows(proc)) == (4, 5)
    got = editability(proc, (4, 5))
    assert got == {"rows": 4, "columns": 5, "floors": True, "bays": True, "floors_plus_one": True,
                   "bays_plus_one": True, "eligible": True}


def test_a_facade_without_repeats_cannot_be_edited():
    tile = facade([]).root.children[1].children[0].children[0]
    row = Node.split("x", [(Size("flt", 60), tile.copy()) for _ in range(3)])
    proc = Procedure(180, 200, Node.split("y", [(Size("flt", 100), row), (Size("flt", 100), row.copy())]))
    got = editability(proc, (2, 3))
    assert (got["rows"], got["columns"]) == (2, 3)
    assert not got["floors"] and not got["floors_plus_one"] and not got["bays_plus_one"]
