"""Whether a procedure's named parameters describe the building it reads: its floor height the floors' pitch, its
tile width the bays', as a person measures them on the drawing (`facaid.reading.windows.window_pitch`: from a window
to the next one up its column, along its row). Issue 67's item 5: reported by `facaid evaluate-real`, and one of
what the pipeline ranks its lattice readings by (`facaid.pipeline.best_reading`)."""

from __future__ import annotations

import numpy as np

from facaid.editing.parameters import named_parameters
from facaid.grammar.procedure import Procedure
from facaid.reading.windows import pitches

__all__ = ["PITCH", "describes"]

PITCH = 0.15  # floor_height within this share of the window rows' pitch


def describes(proc: Procedure, rows: np.ndarray,
              pitch: tuple[float | None, float | None] | None = None) -> dict:
    """Whether the named parameters describe the building of a flattened annotation's ``rows``: ``floor_height``
    within `PITCH` of its floors' pitch (where it has at least three rows of windows: the median step from a window
    to the next one up its column, `facaid.reading.windows.window_pitch`), ``tile_width`` the same of its bays' pitch,
    and no narrower than ``window_width`` (None where there is nothing to judge). ``pitch``: ``pitches(rows)``,
    where the caller judges several procedures of the same rows."""
    names = {p.name: p.value for p in named_parameters(proc)}
    floor, bay = pitches(rows) if pitch is None else pitch
    out = {"floor_pitch": floor, "bay_pitch": bay, "floor_height": names.get("floor_height"),
           "tile_width": names.get("tile_width"), "floor_height_ok": None, "tile_width_ok": None}
    if floor is not None and "floor_height" in names:
        out["floor_height_ok"] = abs(names["floor_height"] / floor - 1) <= PITCH
    if bay is not None and "tile_width" in names:
        out["tile_width_ok"] = (abs(names["tile_width"] / bay - 1) <= PITCH
                                and names["tile_width"] >= names.get("window_width", 0.0))
    return out
