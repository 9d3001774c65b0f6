"""Executing and flattening in C (`facaid.native.rects`): the same rows as the Python reference, and a clean
fallback where the C declines or is switched off."""

import numpy as np
import orjson
import pytest

from facaid.generator import generate_procedure
from facaid.generator.dataset import sample_line, sample_record
from facaid.grammar.execute import execute, flat_rows, leaf_array
from facaid.grammar.nodes import Node, Size
from facaid.grammar.procedure import Procedure, ProcedureError
from facaid.native import rects
from facaid.segmentation import flatten_array, flatten_array_numpy, rect_dicts, rects_json

needs_c = pytest.mark.skipif(rects.library() is None, reason="no C compiler to build the rectangles library")


def reference_rows(proc: Procedure, wall: str = "pieces") -> np.ndarray:
    return flatten_array_numpy(round(proc.width), round(proc.height), leaf_array(proc, execute(proc)), wall)


@needs_c
@pytest.mark.parametrize("style", [None, "wing", "wings", "tenement", "commercial"])
def test_executed_rows_are_the_python_rows(style):
    for seed in range(60):
        proc = generate_procedure(seed, style)
        assert np.array_equal(flat_rows(proc), reference_rows(proc))
        got = rects.executed_rows(proc.root, (proc.width, proc.height), 256, 100_000, wall="footprint")
        assert np.array_equal(got, reference_rows(proc, "footprint"))


@needs_c
def test_executed_rows_on_a_fractional_extent_and_a_mirror():
    """A procedure's size need not be whole pixels: the C lays out on the extent and clips to the rounded image;
    a centred mirror of fill repeats exercises the reflected, far-end layout."""
    bay = Node.split("x", [(Size("flt", 1.0), Node.leaf("facade")), (Size("abs", 13.3), Node.leaf("window")),
                           (Size("flt", 1.0), Node.leaf("facade"))])
    row = Node.repeat("x", "fill", [(Size("abs", 41.7), bay), (Size("abs", 3.2), Node.leaf("pillar"))], tail=1)
    side = Node.split("y", [(Size("rel", 0.31), row), (Size("flt", 1.0), Node.leaf("door"))])
    root = Node.mirror("x", [(Size("flt", 1.0), side), (Size("abs", 7.7), Node.leaf("deco")),
                             (Size("rel", 0.2), Node.leaf("shop"))], center=True)
    for width, height in [(300.4, 200.6), (517.5, 88.5), (97.0, 1001.49)]:
        proc = Procedure(width, height, root)
        assert np.array_equal(flat_rows(proc), reference_rows(proc))


@needs_c
def test_flatten_matches_numpy_on_random_overlapping_boxes():
    """Overlaps resolved by paint order, boxes reaching past the image, empty boxes, both wall forms."""
    rng = np.random.default_rng(0)
    for _ in range(400):
        n = int(rng.integers(1, 60))
        w, h = int(rng.integers(5, 300)), int(rng.integers(5, 300))
        x = np.sort(rng.integers(-5, w + 6, (n, 2)), 1)
        y = np.sort(rng.integers(-5, h + 6, (n, 2)), 1)
        rows = np.stack([rng.integers(0, 12, n), x[:, 0], y[:, 0], x[:, 1], y[:, 1]], 1)
        for wall in ("pieces", "footprint"):
            fast = rects.flatten_rows(w, h, rows, wall)
            assert fast is not None and np.array_equal(fast, flatten_array_numpy(w, h, rows, wall))


@needs_c
def test_the_c_declines_what_it_cannot_read():
    """A label outside the 12 or an inverted box goes to the numpy path; a tree that expands past the limit or
    a fill repeat of no length to the Python executor, which names the problem."""
    assert rects.flatten_rows(10, 10, np.array([[12, 0, 0, 5, 5]]), "pieces") is None
    assert rects.flatten_rows(10, 10, np.array([[2, 5, 0, 1, 5]]), "pieces") is None
    assert rects.rects_json(np.array([[-1, 0, 0, 1, 1]])) is None
    cell = Node.leaf("window")
    grid = Node.repeat("y", 256, [(Size("flt", 1.0), Node.repeat("x", 256, [(Size("flt", 1.0), cell)]))])
    huge = Procedure(1000, 1000, Node.repeat("x", 2, [(Size("flt", 1.0), grid)]))
    assert rects.executed_rows(huge.root, (1000, 1000), 256, 100_000) is None
    with pytest.raises(ProcedureError, match="more than 100000 rectangles"):
        flat_rows(huge)
    empty = Node.repeat("x", "fill", [(Size("abs", 0.0), Node.leaf("window"))])
    assert rects.executed_rows(empty, (50, 50), 256, 100_000) is None


@needs_c
def test_rects_json_is_what_orjson_writes():
    proc = generate_procedure(3)
    rows = reference_rows(proc)
    assert rects.rects_json(rows) == orjson.dumps(rect_dicts(rows.tolist()))
    odd = np.array([[3, -5, 0, 123456789012, 7], [11, 0, -9223372036854775808, 1, 9223372036854775807]])
    assert rects.rects_json(odd) == orjson.dumps(rect_dicts(odd.tolist()))
    assert rects.rects_json(np.zeros((0, 5), dtype=np.int64)) == b"[]"


def test_dataset_lines_are_the_records_json():
    for index in range(20):
        assert sample_line(5, index) == orjson.dumps(sample_record(5, index))
    assert sample_line(5, 3, "wing") == orjson.dumps(sample_record(5, 3, "wing"))


def test_switched_off_the_python_paths_give_the_same(monkeypatch):
    procs = [generate_procedure(seed) for seed in range(5)]
    native = [flat_rows(p) for p in procs]
    lines = [sample_line(9, i) for i in range(3)]
    monkeypatch.setenv("FACAID_NATIVE", "0")
    assert rects.library() is None
    for proc, rows in zip(procs, native, strict=True):
        assert np.array_equal(flat_rows(proc), rows)
        assert np.array_equal(flatten_array(round(proc.width), round(proc.height), leaf_array(proc)), rows)
    assert rects_json(native[0]) == orjson.dumps(rect_dicts(native[0].tolist()))
    assert [sample_line(9, i) for i in range(3)] == lines
