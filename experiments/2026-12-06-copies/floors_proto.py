"""Prototype: whole floors carried down (and up) the photo's vertical repeat, decided per floor (the median NCC of
its carried windows), not per element. Imported by sim.py with FLOORS=1; knobs FLOOR_MATCH, ELEMENT_MIN,
FLOOR_SEARCH."""
import numpy as np

from facaid import completion
from facaid.labels import GLASS
from facaid.photo import repeats

FLOOR_MATCH = 0.5  # a carried floor is proposed when its windows' median NCC is this or more
ELEMENT_MIN = 0.3  # ... each of its elements alike at least this
FLOOR_SEARCH = 0.15  # share of the pitch a floor may sit off the multiple of the pitch
SCORE = 0.86


PILLARS = ("pillar",)
PILLAR_MIN = -1.0  # a pillar of a carried floor is proposed alike at least this (-1: always)
WINDOWS_TOO = True


def floor_copies(levels, props):
    keep = repeats.CARRIED
    repeats.CARRIED = tuple(keep) + tuple(PILLARS)
    try:
        drawn = repeats._carried(props.drawn)
    finally:
        repeats.CARRIED = keep
    if len(drawn) < 2:
        return
    reading = repeats._Reading(levels, drawn)
    if reading.flat:
        return
    dys = sorted({abs(dy) for dx, dy in reading.shifts(repeats.SUPPORT) if dx == 0 and dy != 0})
    if not dys:
        return
    pitch = dys[0]
    h = reading.norm.shape[0]
    glass = np.isin(drawn[:, 0], list(GLASS))
    if glass.sum() < 2:
        return
    moves_of = lambda dy: np.array([[0.0, dy / reading.to_work[1]]])  # noqa: E731
    for k in [k for k in range(1, h // max(1, pitch) + 1)] + [-k for k in range(1, h // max(1, pitch) + 1)]:
        best = None
        span = max(1, round(FLOOR_SEARCH * pitch))
        for dy in range(k * pitch - span, k * pitch + span + 1, max(1, span // 3)):
            sims = []
            for i in np.flatnonzero(glass):
                same = drawn[drawn[:, 0] == drawn[i, 0], 1:]
                if repeats._onto(drawn[i, 1:], moves_of(dy), same)[0]:
                    continue
                f = reading.carry(int(i), (0, dy))
                if f is not None:
                    sims.append(f[1])
            if len(sims) >= 2:
                m = float(np.median(sims))
                if best is None or m > best[0]:
                    best = (m, dy)
        if best is None or best[0] < FLOOR_MATCH:
            continue
        dy = best[1]
        for i in range(len(drawn)):
            same = drawn[drawn[:, 0] == drawn[i, 0], 1:]
            if repeats._onto(drawn[i, 1:], moves_of(dy), same)[0]:
                continue
            f = reading.carry(i, (0, dy))
            pillar = completion.LABELS[int(drawn[i, 0])] in PILLARS
            if pillar:
                f = (drawn[i, 1:] + np.array([0, dy, 0, dy]) / reading.to_work[1], -1.0)
            if f is None or (not pillar and not WINDOWS_TOO):
                continue
            if f[1] >= (PILLAR_MIN if pillar else ELEMENT_MIN):
                props.add(int(drawn[i, 0]), f[0], SCORE, f"repeat of floor ({completion.LABELS[int(drawn[i, 0])]})",
                          f[1])


_orig = completion._repeats


def patched(levels, props):
    _orig(levels, props)
    floor_copies(levels, props)


completion._repeats = patched
