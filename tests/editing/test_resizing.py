"""Resizing a procedure (`facaid.editing.resizing`): fixed sizes keep their pixels, floating ones stretch, and each
repeat lays out as many copies of its pattern as now fit, on trees made here and on generated facades."""

from __future__ import annotations

import pytest

from facaid.editing.resizing import copy_lengths, copy_procedure, repeat_unit, resize
from facaid.generator import generate_procedure
from facaid.grammar.execute import execute
from facaid.grammar.nodes import Node, Override, Size
from facaid.grammar.procedure import Procedure
from facaid.labels import LABEL_ID

WINDOW = LABEL_ID["window"]


def _bays(count: int = 4, margin: float = 20.0) -> Procedure:
    """A wall with a fixed margin on each side and ``count`` bays of a window between wall."""
    bay = Node.split("x", [(Size("flt", 1.0), Node.leaf("facade")), (Size("flt", 2.0), Node.leaf("window")),
                           (Size("flt", 1.0), Node.leaf("facade"))], role="tile")
    row = Node.repeat("x", count, [(Size("flt", 1.0), bay)], role="bay")
    root = Node.split("x", [(Size("abs", margin), Node.leaf("facade")), (Size("flt", 1.0), row),
                            (Size("abs", margin), Node.leaf("facade"))], role="facade")
    return Procedure(40 + 60 * count, 100, root, {})


def test_a_wider_facade_gets_more_bays_of_the_same_width_and_keeps_its_fixed_margins():
    proc = _bays(4)  # bays of 60 px between margins of 20
    wide = resize(proc, 40 + 60 * 7, 100)
    (row,) = [n for _, n in wide.nodes() if n.rule == "repeat"]
    assert row.count == 7 and (wide.width, wide.height) == (460, 100)
    windows = [r for r in execute(wide) if r[0] == WINDOW]
    assert len(windows) == 7
    assert min(w[1] for w in windows) == pytest.approx(20 + 15, abs=1)  # the margin kept its 20 px
    assert {round(w[3] - w[1]) for w in windows} == {30}  # each bay as wide as before
    assert [n.count for _, n in proc.nodes() if n.rule == "repeat"] == [4]  # the original is untouched


def test_a_narrower_facade_keeps_at_least_one_copy_and_rounds_to_the_nearest_count():
    proc = _bays(4)
    assert [n.count for _, n in resize(proc, 40 + 60 * 2.4, 100).nodes() if n.rule == "repeat"] == [2]
    assert [n.count for _, n in resize(proc, 40 + 60 * 2.6, 100).nodes() if n.rule == "repeat"] == [3]
    assert [n.count for _, n in resize(proc, 45, 100).nodes() if n.rule == "repeat"] == [1]


@pytest.mark.parametrize("size", [(0, 100), (100, 0), (1e9, 100), (100, -5)])
def test_a_size_out_of_range_is_refused_naming_it(size):
    with pytest.raises(ValueError, match="size must be between 1 and"):
        resize(_bays(), *size)


def test_the_typical_copy_of_a_repeat_is_one_no_exception_resizes():
    proc = _bays(4)
    (row,) = [n for _, n in proc.nodes() if n.rule == "repeat"]
    row.exceptions.append(Override(0, (0,), size=Size("flt", 2.0)))  # the first bay twice as wide
    unit, tail = repeat_unit(row, 240.0)
    lengths = copy_lengths(row, 240.0)
    assert tail == 0 and lengths[0] == pytest.approx(2 * lengths[1]) and sum(lengths) == pytest.approx(240.0)
    assert unit == pytest.approx(lengths[1])  # not the mean copy: the one laid out as the pattern says


def test_copy_procedure_is_a_copy():
    proc = _bays()
    copy = copy_procedure(proc)
    copy.root.children[0].label = "shop"
    copy.meta["source"] = "elsewhere"
    assert proc.root.children[0].label == "facade" and "source" not in proc.meta


def test_generated_facades_resize_to_valid_procedures_whose_fixed_parts_keep_their_size():
    for seed in range(12):
        proc = generate_procedure(seed)
        for w, h in ((proc.width * 1.5, proc.height), (proc.width, proc.height * 0.7),
                     (proc.width * 0.6, proc.height * 1.3)):
            out = resize(proc, w, h)
            rects = execute(out)
            assert rects and (out.width, out.height) == (w, h)
            assert max(r[3] for r in rects) <= w + 1e-6 and max(r[4] for r in rects) <= h + 1e-6
