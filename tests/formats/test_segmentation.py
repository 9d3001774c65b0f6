import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from facaid.labels import LABELS, PAINT_ORDER, PRIORITY
from facaid.segmentation import Rect, Segmentation, SegmentationError, flatten, rasterize


def seg(rects, w=100, h=80):
    return Segmentation.from_dict({"width": w, "height": h, "rects": rects})


def r(label, x0, y0, x1, y1):
    return {"label": label, "x0": x0, "y0": y0, "x1": x1, "y1": y1}


def test_paint_order_is_a_permutation_of_the_labels():
    assert sorted(PAINT_ORDER) == sorted(LABELS)
    assert PRIORITY[LABELS.index("deco")] == 11 and PRIORITY[LABELS.index("facade")] == 1


def test_parse_round_trip_and_extra_keys_ignored():
    obj = {"id": "x", "set": "base", "width": 10, "height": 20, "rects": [r("window", 1, 2, 3, 4)]}
    s = Segmentation.from_dict(obj)
    assert s.rects == (Rect(2, 1, 2, 3, 4),)
    assert Segmentation.from_json(s.to_json()) == s


@pytest.mark.parametrize(
    "obj, message",
    [
        ([], "must be a JSON object"),
        ({"height": 5, "rects": []}, "missing 'width'"),
        ({"width": "10", "height": 5, "rects": []}, "width must be a number"),
        ({"width": True, "height": 5, "rects": []}, "width must be a number"),
        ({"width": 0, "height": 5, "rects": []}, "between 1 and"),
        ({"width": -3, "height": 5, "rects": []}, "between 1 and"),
        ({"width": 99999, "height": 5, "rects": []}, "between 1 and"),
        ({"width": 10.5, "height": 5, "rects": []}, "whole number"),
        ({"width": 16000, "height": 16000, "rects": []}, "image too large"),
        ({"width": 10, "height": 5, "rects": {}}, "'rects' must be a list"),
        ({"width": 10, "height": 5, "rects": [7]}, "rects[0] must be an object"),
        ({"width": 10, "height": 5, "rects": [r("roof", 0, 0, 1, 1)]}, "rects[0].label 'roof'"),
        ({"width": 10, "height": 5, "rects": [{"label": "window", "x0": 0, "y0": 0, "x1": 1}]}, "missing 'y1'"),
        ({"width": 10, "height": 5, "rects": [r("window", 0, 0, float("nan"), 1)]}, "rects[0].x1 must be finite"),
        ({"width": 10, "height": 5, "rects": [r("window", 0, 0, None, 1)]}, "rects[0].x1 must be a number"),
        ({"width": 10, "height": 5, "rects": [r("window", 5, 0, 5, 1)]}, "0 <= x0 < x1 <= width=10"),
        ({"width": 10, "height": 5, "rects": [r("window", -1, 0, 5, 1)]}, "0 <= x0 < x1"),
        ({"width": 10, "height": 5, "rects": [r("window", 0, 0, 5, 6)]}, "0 <= y0 < y1 <= height=5"),
    ],
)
def test_bad_segmentations_are_rejected_with_a_message(obj, message):
    with pytest.raises(SegmentationError) as err:
        Segmentation.from_dict(obj)
    assert message in str(err.value)


def test_malformed_json_and_binary_input():
    with pytest.raises(SegmentationError, match="malformed JSON"):
        Segmentation.from_json('{"width": 3,')
    with pytest.raises(SegmentationError, match="malformed JSON"):
        Segmentation.from_json(b"\x89PNG\r\n\x1a\n\x00\xff")


def test_clip_mode_clips_and_drops():
    s = Segmentation.from_dict({"width": 10, "height": 10, "rects": [r("window", -5, 2, 4, 20),
                                                                      r("door", 12, 0, 15, 3)]}, clip=True)
    assert s.rects == (Rect(2, 0, 2, 4, 10),)


def test_rasterize_uses_the_paint_order_not_the_file_order():
    s = seg([r("deco", 0, 0, 10, 10), r("window", 0, 0, 20, 20), r("facade", 0, 0, 100, 80)])
    m = rasterize(s)
    assert m[5, 5] == LABELS.index("deco")
    assert m[15, 15] == LABELS.index("window")
    assert m[50, 50] == LABELS.index("facade")
    assert m.shape == (80, 100)


def test_flatten_blind_on_window():
    s = seg([r("window", 10, 10, 30, 50), r("blind", 10, 10, 30, 25), r("facade", 0, 0, 100, 80)])
    flat = flatten(s, wall="footprint")
    labels = {(LABELS[x.label], x.x0, x.y0, x.x1, x.y1) for x in flat.rects}
    assert labels == {("facade", 0, 0, 100, 80), ("blind", 10, 10, 30, 25), ("window", 10, 25, 30, 50)}


def test_flatten_merges_pieces_canonically():
    whole = seg([r("window", 10, 10, 30, 50)])
    pieces = seg([r("window", 10, 10, 20, 50), r("window", 20, 10, 30, 30), r("window", 20, 30, 30, 50)])
    assert flatten(whole) == flatten(pieces)
    assert flatten(whole, wall="footprint") == flatten(pieces, wall="footprint")


rect_strategy = st.tuples(
    st.sampled_from(LABELS[1:]), st.integers(0, 59), st.integers(0, 39), st.integers(1, 60), st.integers(1, 40)
).map(lambda t: r(t[0], min(t[1], t[3] - 1), min(t[2], t[4] - 1), max(t[3], t[1] + 1), max(t[4], t[2] + 1)))


@settings(max_examples=150, deadline=None)
@given(st.lists(rect_strategy, max_size=25))
def test_flatten_preserves_the_label_map_without_overlaps(rects):
    s = seg(rects, 61, 41)
    target = rasterize(s)
    for wall in ("pieces", "footprint"):
        flat = flatten(s, wall=wall)
        assert np.array_equal(rasterize(flat), target)
        layers = [flat.rects] if wall == "pieces" else [
            [x for x in flat.rects if LABELS[x.label] == "facade"],
            [x for x in flat.rects if LABELS[x.label] != "facade"]]
        for layer in layers:
            cover = np.zeros((41, 61), int)
            for x in layer:
                cover[x.y0:x.y1, x.x0:x.x1] += 1
            assert cover.max(initial=0) <= 1
        # canonical: flattening again changes nothing
        assert flatten(flat, wall=wall) == flat
    assert sum(x.area for x in flatten(s).rects) == int((target != 0).sum())


def test_cmp_records_parse_and_flatten_exactly(cmp_records):
    for rec in cmp_records:
        s = Segmentation.from_dict(rec)
        target = rasterize(s)
        assert np.array_equal(rasterize(flatten(s)), target)
        assert np.array_equal(rasterize(flatten(s, wall="footprint")), target)


def test_schema_accepts_what_the_parser_accepts(cmp_records):
    jsonschema = pytest.importorskip("jsonschema")
    from pathlib import Path

    import facaid

    schema = json.loads((Path(facaid.__file__).parent / "segmentation.schema.json").read_text())
    for rec in cmp_records[:5]:
        jsonschema.validate(rec, schema)


def _aligned_lines_reference(lo, hi):
    """`aligned_lines` as it was written first, with `np.median` of each line's members at every step."""
    order = np.argsort((lo + hi) / 2, kind="stable")
    lines = []
    for i in order.tolist():
        if lines:
            members = lines[-1]
            a, b = np.median(lo[members]), np.median(hi[members])
            if min(b, hi[i]) - max(a, lo[i]) >= 0.5 * (hi[i] - lo[i]):
                members.append(i)
                continue
        lines.append([i])
    return [np.array(m) for m in lines]


@given(st.lists(st.tuples(st.integers(0, 400), st.integers(1, 60)), min_size=1, max_size=200), st.booleans())
def test_aligned_lines_keep_each_lines_median_as_np_median_has_it(intervals, floats):
    from facaid.segmentation import aligned_lines

    lo = np.array([a for a, _ in intervals], dtype=float if floats else np.int64)
    hi = lo + np.array([n for _, n in intervals], dtype=lo.dtype) / (3 if floats else 1)
    got, want = aligned_lines(lo, hi), _aligned_lines_reference(lo, hi)
    assert [m.tolist() for m in got] == [m.tolist() for m in want]
