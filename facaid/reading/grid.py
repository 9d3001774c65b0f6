"""Step 1 of the lattice reader (`facaid.reading.lattice`): the grid of a facade's floors and tiles, read off its
windows' rows and columns.

Windows are the connected window-or-blind regions of the main building (`footprint`), but for strips; their rows and
columns are bands of centres (`window_bands`); a column needs windows in `COLUMN_SUPPORT` of the floors. Floors are cut
between two rows where the label map is most wall, at one offset from their windows where the wall allows (`ALIGN`:
floors as high as the windows' pitch); the last rows whose bands hold doors or shops (`GROUND_SHARE`) are the ground
floor's. Tiles are the columns within the floors, cut the same way.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from facaid.grammar.procedure import MAX_COUNT
from facaid.labels import BACKGROUND, FACADE, LABEL_ID
from facaid.reading.windows import centre_bands

ALIGN = 0.05  # a cut between two bands may move to a line this much less wall to sit at the typical offset
COLUMN_SUPPORT = 0.5  # a column of windows needs windows in this share of the floors
GROUND_SHARE = 0.05  # a last row of windows whose band is this much door or shop belongs to the ground floor


def window_bands(lo: np.ndarray, hi: np.ndarray) -> list[np.ndarray]:
    """Indices of the boxes [lo, hi) grouped in bands of centres (`facaid.reading.windows.centre_bands`: split where
    the gap between neighbouring centres is over half the median size); bands whose typical extents overlap (wide and
    narrow windows in one column) are one."""
    out = centre_bands((lo + hi) / 2, hi - lo)
    if not out:
        return out
    merged = [out[0]]
    for band in out[1:]:
        if np.median(lo[band]) < np.median(hi[merged[-1]]):
            merged[-1] = np.concatenate([merged[-1], band])
        else:
            merged.append(band)
    return merged


def _cut(profile: np.ndarray, lo: int, hi: int, near: float | None = None) -> int:
    """Where to cut between two bands: a line in [lo, hi] whose share of wall (``profile``) is highest, the middle
    of the widest run of such lines; with ``near``, of the lines within `ALIGN` of that share, the one nearest it."""
    lo, hi = int(max(0, lo)), int(min(len(profile), max(lo, hi)))
    if hi <= lo:
        return lo
    seg = profile[lo : hi + 1] if hi < len(profile) else profile[lo:hi]
    best = seg.max()
    if near is not None:
        good = np.flatnonzero(seg >= best - ALIGN)
        return lo + int(good[np.argmin(np.abs(lo + good - near))])
    good = np.flatnonzero(seg >= best - 1e-9)
    runs = np.split(good, np.flatnonzero(np.diff(good) > 1) + 1)
    run = max(runs, key=len)
    return lo + int(run[len(run) // 2])


def _edges(profile: np.ndarray, starts: np.ndarray, ends: np.ndarray, limit: int, pitch: bool = False) -> list[int]:
    """The cuts around bands that start at ``starts`` and end at ``ends`` (sorted): one between each two, each as
    near its band's start less the typical distance of the cuts from their bands as the wall allows (`ALIGN`:
    floors and tiles cut at one offset from their windows are as long as the windows' pitch), and an outer one on
    each side at that distance. With ``pitch`` (the floors), every cut is at one offset before its band (`_offset`)
    wherever the gap is that long, whatever it crosses: a floor is as high as from its windows to the next row's,
    as a person measures it, and a balcony or cornice the cut crosses is in every floor alike."""
    inner = [_cut(profile, int(e), int(s)) for e, s in zip(ends[:-1], starts[1:], strict=True)]
    before = np.median([s - c for s, c in zip(starts[1:], inner, strict=True)])
    if pitch and inner:
        d = _offset(profile, starts, ends, before)
        inner = [int(s - d) if e <= s - d else c for e, s, c in zip(ends[:-1], starts[1:], inner, strict=True)]
        before = np.median([s - c for s, c in zip(starts[1:], inner, strict=True)])
    elif ALIGN:
        inner = [_cut(profile, int(e), int(s), s - before) for e, s in zip(ends[:-1], starts[1:], strict=True)]
        before = np.median([s - c for s, c in zip(starts[1:], inner, strict=True)])
    after = np.median([c - e for e, c in zip(ends[:-1], inner, strict=True)])
    first = int(np.clip(round(starts[0] - before), 0, starts[0]))
    last = int(np.clip(round(ends[-1] + after), ends[-1], limit))
    return [first, *inner, last]


def _offset(profile: np.ndarray, starts: np.ndarray, ends: np.ndarray, before: float) -> int:
    """The one distance before each band to cut at: the one whose cuts (in the gaps at least that long) cross the
    most wall in all, the nearest ``before`` (the free cuts' median) of equals."""
    s, e = starts[1:].astype(int), ends[:-1]
    offsets = np.arange(0, max(0, int((starts[1:] - e).max())) + 1)
    at = s[None, :] - offsets[:, None]
    fits = (at >= e[None, :]) & (at >= 0)
    wall = np.where(fits, profile[np.clip(at, 0, len(profile) - 1)], 0.0).sum(axis=1)
    best = np.flatnonzero(wall >= wall.max() - 1e-6)
    return int(best[np.argmin(np.abs(best - before))])


def footprint(label_map: np.ndarray) -> tuple[int, int]:
    """The main building's columns [x0, x1): the longest run of columns that are mostly not background (a
    neighbour's strip beside it, in shadow or cut by the photo, is left out when background parts it off)."""
    building = (label_map != BACKGROUND).mean(axis=0) >= 0.5
    if not building.any():
        return 0, label_map.shape[1]
    edges = np.flatnonzero(np.diff(np.concatenate([[0], building.astype(np.int8), [0]])))
    runs = edges.reshape(-1, 2)
    x0, x1 = max(runs, key=lambda r: r[1] - r[0])
    return int(x0), int(x1)


def _ground_rows(label_map: np.ndarray, ys: list[int]) -> int:
    """How many of the last rows of windows belong to the ground floor: those whose bands hold doors or shops."""
    shopfront = np.isin(label_map, (LABEL_ID["door"], LABEL_ID["shop"])).mean(axis=1)
    n = 0
    for i in range(len(ys) - 2, 0, -1):  # the first row stays a floor
        if shopfront[ys[i] : ys[i + 1]].mean() < GROUND_SHARE:
            break
        n += 1
    return n


@dataclass
class Grid:
    """The floors' cuts ``ys`` (rows + 1 of them) and the tiles' ``xs`` (columns + 1) of a label map."""

    label_map: np.ndarray
    ys: list[int]
    xs: list[int]

    @property
    def rows(self) -> int:
        return len(self.ys) - 1

    @property
    def columns(self) -> int:
        return len(self.xs) - 1

    def cell(self, i: int, j: int) -> np.ndarray:
        return self.label_map[self.ys[i] : self.ys[i + 1], self.xs[j] : self.xs[j + 1]]

    @property
    def heights(self) -> np.ndarray:
        return np.diff(self.ys).astype(float)

    @property
    def widths(self) -> np.ndarray:
        return np.diff(self.xs).astype(float)


def read_grid(label_map: np.ndarray, windows: np.ndarray, pitch: bool = True) -> Grid | None:
    """The floors and tiles of the windows' rows and columns, or None where there are fewer than two of either.
    ``pitch``: the floors cut at one offset from their windows (`_edges`), the ground floor's top where the wall is;
    else each cut where the wall is, moved to the offset only where the wall allows (`ALIGN`)."""
    height, width = label_map.shape
    if len(windows) < 4:
        return None
    rows = window_bands(windows[:, 1], windows[:, 3])
    if not 2 <= len(rows) <= MAX_COUNT:
        return None
    wall = label_map == FACADE
    tops = np.array([np.median(windows[r, 1]) for r in rows])
    bottoms = np.array([np.median(windows[r, 3]) for r in rows])
    profile = wall.mean(axis=1)
    ys = _edges(profile, tops, bottoms, height, pitch=pitch)
    if any(b <= a for a, b in zip(ys[:-1], ys[1:], strict=True)):
        return None
    n_rows = len(rows) - _ground_rows(label_map, ys)
    ys = ys[: n_rows + 1]
    if pitch and n_rows < len(rows):  # the ground floor's top is where the wall is, not at the floors' offset:
        free = _edges(profile, tops, bottoms, height)[n_rows]  # its doors and shops are its own
        ys[-1] = free if free > ys[-2] else ys[-1]
    row_of = np.concatenate([np.full(len(r), i) for i, r in enumerate(rows[:n_rows])])
    upper = windows[np.concatenate(rows[:n_rows])]
    cols = window_bands(upper[:, 0], upper[:, 2])
    # columns are those most floors have a window in; the others' windows are content of their neighbours' tiles
    # (a floor whose windows sit half a bay over does not halve every tile)
    support = [len(set(row_of[c].tolist())) / n_rows for c in cols]
    strong = [c for c, share in zip(cols, support, strict=True) if share >= COLUMN_SUPPORT]
    if len(strong) >= 2:
        cols = strong
    if not 2 <= len(cols) <= MAX_COUNT:
        return None
    lefts = np.array([np.median(upper[c, 0]) for c in cols])
    rights = np.array([np.median(upper[c, 2]) for c in cols])
    xs = _edges(wall[ys[0] : ys[-1]].mean(axis=0), lefts, rights, width)
    if any(b <= a for a, b in zip(xs[:-1], xs[1:], strict=True)):
        return None
    return Grid(label_map, ys, xs)


__all__ = ["ALIGN", "COLUMN_SUPPORT", "GROUND_SHARE", "Grid", "footprint", "read_grid", "window_bands"]
