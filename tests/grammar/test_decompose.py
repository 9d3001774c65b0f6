import numpy as np

from facaid.generator import generate
from facaid.grammar import Procedure, to_segmentation, validate
from facaid.grammar.decompose import procedure_from_segmentation
from facaid.grammar.procedure import MAX_CHILDREN
from facaid.segmentation import Segmentation, rasterize


def _exact(seg: Segmentation) -> Procedure:
    proc = procedure_from_segmentation(seg)
    validate(proc)
    assert np.array_equal(rasterize(to_segmentation(proc)), rasterize(seg))
    return proc


def test_real_facades_are_expressed_exactly(cmp_records):
    for rec in cmp_records:
        proc = _exact(Segmentation.from_dict(rec))
        assert all(len(node.children) <= MAX_CHILDREN for _, node in proc.nodes())


def test_generated_facades_are_expressed_exactly():
    for seed in range(20):
        _exact(generate(seed).segmentation)


def test_pinwheel_and_empty_segmentations():
    # four rectangles around a centre: no full line crosses the image without cutting one
    pinwheel = Segmentation.from_dict({"width": 30, "height": 30, "rects": [
        {"label": "window", "x0": 0, "y0": 0, "x1": 20, "y1": 10},
        {"label": "door", "x0": 20, "y0": 0, "x1": 30, "y1": 20},
        {"label": "shop", "x0": 10, "y0": 20, "x1": 30, "y1": 30},
        {"label": "deco", "x0": 0, "y0": 10, "x1": 10, "y1": 30},
        {"label": "sill", "x0": 10, "y0": 10, "x1": 20, "y1": 20}]})
    _exact(pinwheel)
    empty = _exact(Segmentation(12, 7, ()))
    assert empty.root.to_dict() == {"rule": "leaf", "label": "background"}
