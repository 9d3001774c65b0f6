"""One box per element for the annotation formats (`facaid.formats.annotation`): pieces merged, the wall under them."""

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from facaid.formats.annotation import as_annotated, merge_pieces
from facaid.generator import generate
from facaid.grammar.execute import to_segmentation
from facaid.labels import LABEL_ID
from facaid.segmentation import Rect, Segmentation, rasterize

CORNICE, WINDOW, FACADE = LABEL_ID["cornice"], LABEL_ID["window"], LABEL_ID["facade"]


def test_pieces_of_one_element_become_one_box_and_other_shapes_stay_apart():
    cornice = [Rect(CORNICE, x, 10, x + 20, 16) for x in (0, 20, 40)]  # one cornice cut per tile
    column = [Rect(WINDOW, 100, y, 120, y + 10) for y in (0, 10)]  # a window cut by a transom leaf
    ell = [Rect(CORNICE, 0, 30, 40, 36), Rect(CORNICE, 0, 36, 10, 50)]  # an L: no one box holds it
    apart = [Rect(WINDOW, 0, 60, 10, 70), Rect(WINDOW, 12, 60, 22, 70)]  # two windows 2 px apart
    mixed = [Rect(WINDOW, 50, 60, 60, 70), Rect(CORNICE, 60, 60, 70, 70)]  # touching, of two labels
    out = merge_pieces(cornice + column + ell + apart + mixed)
    assert Rect(CORNICE, 0, 10, 60, 16) in out and Rect(WINDOW, 100, 0, 120, 20) in out
    assert len(out) == 1 + 1 + 2 + 2 + 2


def test_a_procedures_elements_are_one_box_each_and_the_label_map_is_kept():
    seg = to_segmentation(generate(3).procedure)
    out = as_annotated(seg)
    assert (rasterize(out) == rasterize(seg)).all()
    walls = [r for r in out.rects if r.label == FACADE]
    assert len(walls) <= 3 < sum(r.label == FACADE for r in seg.rects)  # the wall's pieces: one box per block
    assert len(out.rects) < len(seg.rects)
    elements = [r for r in out.rects if r.label != FACADE]
    assert merge_pieces(elements) == elements  # nothing left to merge


@given(st.lists(st.tuples(st.integers(0, 3), st.integers(0, 3), st.sampled_from([WINDOW, CORNICE])), min_size=1,
                max_size=16, unique_by=lambda t: t[:2]))
def test_merging_a_grid_of_cells_keeps_every_pixel(cells):
    """Cells of a 4 x 4 grid (10 px each) with labels: merged, the same pixels carry the same labels, fewer boxes."""
    rects = [Rect(label, 10 * i, 10 * j, 10 * i + 10, 10 * j + 10) for i, j, label in cells]
    out = merge_pieces(rects)
    assert len(out) <= len(rects)
    before = rasterize(Segmentation(40, 40, tuple(rects)))
    after = rasterize(Segmentation(40, 40, tuple(out)))
    assert np.array_equal(before, after)
    covered = sum((r.x1 - r.x0) * (r.y1 - r.y0) for r in out)
    assert covered == 100 * len(rects)  # no two boxes overlap
