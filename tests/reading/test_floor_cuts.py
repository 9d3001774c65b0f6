"""Floors cut at their windows' pitch (issue 67, item 5): a floor is as high as from its windows to the next row's,
as a person measures it, even where a balcony fills the wall between two rows, and the ground floor's top stays where
the wall is. Checked on a drawing of our own: the kind of front (a balcony floor among plain ones) on which the wall's
own cuts made floors of 95, 145, 120 and 120 px for a pitch of 120."""

from __future__ import annotations

import numpy as np

from facaid.editing.check import MORE, check_edits
from facaid.editing.describes import describes
from facaid.editing.parameters import named_parameters
from facaid.labels import GLASS, LABEL_ID
from facaid.pipeline import best_reading
from facaid.reading import lattice
from facaid.reading.grid import read_grid
from facaid.segmentation import Segmentation, flatten, rasterize, region_boxes

PITCH, TOPS = 120, (80, 200, 320, 440)


def balcony_front(balcony: bool = True) -> Segmentation:
    """Four rows of four windows 60 px high at a pitch of 120; under the first row (``balcony``) a balcony fills
    80 % of the wall's width from 6 px below the windows to the next row; a ground floor of shops around a door."""
    width, height = 400, 640
    rects = [("facade", 0, 0, width, height)] + ([("balcony", 40, 146, 360, 200)] if balcony else [])
    for top in TOPS:
        for x in (40, 130, 220, 310):
            rects.append(("window", x, top, x + 50, top + 60))
    rects += [("shop", 30, 560, 170, 632), ("door", 180, 545, 220, height), ("shop", 230, 560, 370, 632)]
    rows = np.array([(LABEL_ID[label], *box) for label, *box in rects], dtype=np.int64)
    return Segmentation.from_array(width, height, rows)


def _grid(seg: Segmentation, pitch: bool):
    flat = flatten(seg)
    return read_grid(rasterize(flat), region_boxes(flat.to_array(), GLASS), pitch)


def test_floors_are_cut_at_one_offset_from_their_windows_across_a_balcony():
    pitched, walled = _grid(balcony_front(), True), _grid(balcony_front(), False)
    inner = np.diff(pitched.ys)[1:]  # the first floor's top is extrapolated
    assert inner.tolist() == [PITCH] * len(inner), pitched.ys
    assert np.ptp(np.diff(walled.ys)) > 0.2 * PITCH, walled.ys  # the wall's own cuts: floors of unequal heights
    offsets = [top - cut for top, cut in zip(TOPS, pitched.ys, strict=False)]
    assert len(set(offsets)) == 1, offsets


def test_the_ground_floors_top_is_where_the_wall_is_not_through_its_door():
    seg = balcony_front()
    grid = _grid(seg, True)
    door_top = 545
    assert grid.ys[-1] <= door_top  # the door is the ground floor's, whole
    assert grid.rows == len(TOPS)


def test_the_reading_describes_the_floors_and_its_new_floor_is_clean():
    seg = balcony_front()
    flat = flatten(seg)
    best = best_reading(flat)
    got = describes(best.procedure, flat.to_array())
    assert got["floor_height_ok"], got
    assert abs(got["floor_height"] - PITCH) <= 0.05 * PITCH, got
    verdicts = check_edits(best.procedure, MORE)
    assert verdicts["floors+1"].clean, verdicts["floors+1"].reason
    assert {p.name: p.value for p in named_parameters(best.procedure)}["floors"] == len(TOPS)


def test_both_cuts_are_candidate_readings_each_once():
    """The floors at their pitch come first; the wall's cuts follow where they differ, and not where they are the
    same (a regular front: one reading a group)."""
    assert len(list(lattice.readings(balcony_front()))) >= 2
    groups = [group for group, _ in lattice.readings(balcony_front(balcony=False))]
    assert len(groups) == len(set(groups)), groups
