"""The lattice reader: a real-like annotation (drawn as people draw CMP's: layered boxes, edges off by a hand's
jitter, a closed blind, a balcony floor, a shop floor) read as floors of tiles with exceptions."""

import numpy as np
import pytest
from grammar_helpers import real_like

from facaid import lattice
from facaid.evaluation.editability import editability, segmentation_lattice
from facaid.generator import generate
from facaid.grammar.execute import flat_rows, to_segmentation
from facaid.grammar.procedure import Procedure
from facaid.labels import LABEL_ID
from facaid.metrics import compression, pixel_accuracy
from facaid.parameters import named_parameters, set_parameter
from facaid.segmentation import Segmentation, flatten, rasterize


def accuracy(proc: Procedure, seg: Segmentation) -> float:
    return pixel_accuracy(rasterize(to_segmentation(proc)), rasterize(flatten(seg)))


def test_a_real_like_facade_reads_as_floors_of_tiles():
    seg = real_like()
    proc = lattice.read_lattice(seg)
    params = {p.name: p.value for p in named_parameters(proc)}
    assert params["floors"] == 5 and params["bays"] == 6
    assert accuracy(proc, seg) > 0.94
    assert compression(proc, flatten(seg)) > 5  # 94 drawn elements in a few leaves and their exceptions
    assert editability(proc, segmentation_lattice(seg)) == {
        "rows": 5, "columns": 6, "floors": True, "bays": True, "floors_plus_one": True, "bays_plus_one": True,
        "eligible": True}


def test_the_closed_blind_and_the_balcony_floor_are_exceptions():
    proc = lattice.read_lattice(real_like())
    floors = next(n for _, n in proc.nodes() if n.role == "floors")
    blinds = [o for o in floors.exceptions if o.node is not None and o.node.rule == "leaf" and o.node.label == "blind"]
    assert [(o.copy, o.path[2]) for o in blinds] == [(3, 2)]  # floor 3, tile 2, one leaf
    rows = [o for o in floors.exceptions if o.node is not None and o.node.rule == "repeat"]
    assert [o.copy for o in rows] == [1]  # the balcony floor: its own row of tiles
    labels = {n.label for _, n in rows[0].node.walk() if n.rule == "leaf"}
    assert "balcony" in labels and "window" in labels


def test_floors_plus_one_adds_a_typical_floor():
    proc = lattice.read_lattice(real_like())
    more = set_parameter(proc, "floors", 6)
    counts = np.bincount(flat_rows(more)[:, 0], minlength=12)
    before = np.bincount(flat_rows(proc)[:, 0], minlength=12)
    assert counts[LABEL_ID["blind"]] == before[LABEL_ID["blind"]] == 1  # the exception is not copied
    assert editability(more)["rows"] == 6


def test_the_reading_restores_a_hands_jitter():
    """The same facade drawn twice by different hands reads the same: the typical copies, not the jitter."""
    a, b = lattice.read_lattice(real_like(seed=1)), lattice.read_lattice(real_like(seed=2))
    fa, fb = rasterize(to_segmentation(a)), rasterize(to_segmentation(b))
    drawn_a, drawn_b = rasterize(flatten(real_like(seed=1))), rasterize(flatten(real_like(seed=2)))
    assert pixel_accuracy(fa, fb) > pixel_accuracy(drawn_a, drawn_b)


def test_no_lattice_no_reading():
    one = Segmentation.from_dict({"width": 100, "height": 100, "rects": [
        {"label": "facade", "x0": 0, "y0": 0, "x1": 100, "y1": 100},
        {"label": "window", "x0": 40, "y0": 40, "x1": 60, "y1": 60}]})
    assert lattice.read_lattice(one) is None


@pytest.mark.parametrize("seed", range(8))
def test_generated_facades_read_to_valid_procedures(seed):
    """Whatever the input, a valid procedure that executes, or None."""
    seg = generate(seed).segmentation
    proc = lattice.read_lattice(seg)
    if proc is not None:
        Procedure.from_json(proc.to_json())
        assert accuracy(proc, seg) > 0.7


def test_a_reading_past_the_grammars_limits_is_no_reading(monkeypatch):
    """Where the exceptions would overflow what a repeat may hold, the exact procedure stays the only one."""
    monkeypatch.setattr("facaid.grammar.procedure.MAX_EXCEPTIONS", 1)
    assert lattice.read_lattice(real_like()) is None
