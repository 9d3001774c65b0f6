"""The windows as a person counts them, and the pitch a person measures from one to the next."""

import numpy as np
import pytest

from facaid.reading.windows import window_pitch


def stack(x0: float, y0: float, step: float, floors: int, width: float = 20, height: float = 30) -> list:
    """A column of ``floors`` windows from (x0, y0), one every ``step`` px down."""
    return [[x0, y0 + i * step, x0 + width, y0 + i * step + height] for i in range(floors)]


def test_the_floor_pitch_is_from_a_window_to_the_next_in_its_column():
    # two buildings side by side, floors of 100 px and of 110 px, their rows 40 px apart: bands of centres across
    # both are 40 to 70 px apart, a window to the next in its column 100 or 110 px
    left = stack(10, 50, 100, 4) + stack(60, 50, 100, 4)
    right = stack(200, 90, 110, 4) + stack(250, 90, 110, 4) + stack(300, 90, 110, 4)
    windows = np.array(left + right, dtype=float)
    assert window_pitch(windows, "y") == pytest.approx(110)  # 9 steps of 110 px, 6 of 100
    assert window_pitch(windows, "x") == pytest.approx(50)


def test_a_dormer_over_a_column_is_no_floor_of_it():
    columns = [stack(x, 100, 90, 3) for x in (10, 60, 110)]
    dormer = [[55, 20, 85, 40]]  # in the roof, over the middle column
    windows = np.array(sum(columns, []) + dormer, dtype=float)
    assert window_pitch(windows, "y") == pytest.approx(90)


def test_no_pitch_without_three_rows():
    windows = np.array(stack(10, 10, 50, 2) + stack(60, 10, 50, 2), dtype=float)
    assert window_pitch(windows, "y") is None
    assert window_pitch(np.zeros((0, 4)), "x") is None
