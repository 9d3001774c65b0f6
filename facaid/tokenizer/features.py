"""Input features and quantization: peer counts of a rectangle (how many of its label share its row and column,
and its rank there), and sizes quantized to tokens and back."""

from __future__ import annotations

import math

import numpy as np

MAX_PEERS = 64  # peer counts and ranks are clipped here
PEER_RULES = ("overlap", "shape")
SHAPE_TOLERANCE = 0.25  # "shape" peers: edges and sizes agree within this share of the larger extent


def _near(v: np.ndarray, scale: np.ndarray) -> np.ndarray:
    """(N, N): pairs whose values ``v`` differ by at most `SHAPE_TOLERANCE` of the larger of their ``scale``."""
    return np.abs(v[:, None] - v[None, :]) <= SHAPE_TOLERANCE * np.maximum(scale[:, None], scale[None, :])


def peer_counts(arr: np.ndarray, rule: str = "overlap") -> np.ndarray:
    """(N, 4) int64 for int rows (label, x0, y0, x1, y1), y down: the number of rectangles of the same label
    in the row's row, itself included, and its rank in it from the left, then the same for its column (rank
    from the bottom). A window in a grid of 5 floors by 6 bays gets (6, bay, 5, floor): the counts a repeat
    needs, which the model would otherwise have to count by attention.

    ``rule`` says who is in a row (a column likewise, the axes swapped):
    - "overlap": vertical overlap >= half the lower height. Peers by overlap rather than equal edges, so that
      edges moved a little keep the counts (a rectangle that noise breaks into pieces changes them).
    - "shape": a translate along the row, within `SHAPE_TOLERANCE`: top and bottom edges and width agree to a
      quarter of the larger height or width. The copies of one repeat are peers, the windows of the next
      building in the same row (another floor height, another window size) are not, nor a floor's windows
      and the taller ones of the floor below, which a repeat of floors does not count either."""
    if len(arr) == 0:
        return np.zeros((0, 4), dtype=np.int64)
    if rule not in PEER_RULES:
        raise ValueError(f"peer rule must be one of {', '.join(PEER_RULES)}, got {rule!r}")
    a = np.asarray(arr, dtype=np.float64)
    same = a[:, 0][:, None] == a[:, 0][None, :]
    order = np.arange(len(a))  # ties in position rank by row order
    out = []
    for lo, hi, rank_lo, rank_hi, sign in ((2, 4, 1, 3, 1.0), (1, 3, 2, 4, -1.0)):
        # peers share the (lo, hi) axis's span; rank on the other axis (x from the left, y from the bottom)
        extent = a[:, hi] - a[:, lo]
        if rule == "overlap":
            overlap = (np.minimum(a[:, hi][:, None], a[:, hi][None, :])
                       - np.maximum(a[:, lo][:, None], a[:, lo][None, :]))
            peers = same & (overlap >= 0.5 * np.minimum(extent[:, None], extent[None, :])) & (overlap > 0)
        else:
            length = a[:, rank_hi] - a[:, rank_lo]  # the size along the row
            peers = same & _near(a[:, lo], extent) & _near(a[:, hi], extent) & _near(length, length)
        centre = sign * (a[:, rank_lo] + a[:, rank_hi])
        before = peers & ((centre[None, :] < centre[:, None])
                          | ((centre[None, :] == centre[:, None]) & (order[None, :] < order[:, None])))
        out += [np.minimum(peers.sum(1), MAX_PEERS), np.minimum(before.sum(1), MAX_PEERS - 1)]
    return np.stack(out, axis=1).astype(np.int64)


def quantize_size(value: float, side: float, bins: int) -> int:
    """abs/flt sizes: the fraction of the image side, sqrt-spaced so small parts keep precision."""
    frac = min(max(value / side, 0.0), 1.0)
    return min(bins - 1, round(math.sqrt(frac) * (bins - 1)))


def dequantize_size(q: int, side: float, bins: int) -> float:
    return (q / (bins - 1)) ** 2 * side


def quantize_rel(value: float, bins: int) -> int:
    return min(bins - 1, max(0, round(value * (bins - 1))))
