"""`facaid.metrics.measure` gives the figures of `procedure_accuracy` and `procedure_iou`, from one confusion
matrix counted in blocks."""

import numpy as np
import pytest

from facaid.editing.variation import vary
from facaid.generator import generate
from facaid.labels import LABELS
from facaid.metrics import class_iou, confusion, measure, procedure_accuracy, procedure_iou


@pytest.mark.parametrize("seed", [0, 3, 4])
def test_measure_equals_accuracy_and_iou(seed):
    truth = generate(seed)
    trees = [truth.procedure] + [v for v in vary(truth.procedure, 4, seed)
                                 if (round(v.width), round(v.height)) == (truth.segmentation.width,
                                                                          truth.segmentation.height)]
    assert len(trees) > 1
    for tree in trees:
        assert measure(tree, truth.segmentation) == (procedure_accuracy(tree, truth.segmentation),
                                                     procedure_iou(tree, truth.segmentation))


def test_confusion_counted_in_blocks_is_the_whole_count():
    rng = np.random.default_rng(0)
    a, b = rng.integers(0, 12, (37, 53), dtype=np.uint8), rng.integers(0, 12, (37, 53), dtype=np.uint8)
    whole = confusion(a, b)
    assert whole.sum() == a.size and np.array_equal(confusion(a, b, block=100), whole)
    assert np.trace(whole) == (a == b).sum()
    hits, unions = np.diag(whole), whole.sum(0) + whole.sum(1) - np.diag(whole)
    assert class_iou(a, b) == {name: hits[i] / unions[i] for i, name in enumerate(LABELS) if unions[i]}
    with pytest.raises(ValueError, match="differ in shape"):
        confusion(a, b[:, :-1])
