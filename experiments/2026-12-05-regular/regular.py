"""Regular structures: a compact procedure read off a label map that tolerates an annotator's noise.

`facaid.reading.induce` cuts only where no rectangle is crossed and folds only siblings of exactly one shape, so on a
hand-made annotation (edges a few pixels apart, a blind open here and closed there) it copies every element:
about one leaf per annotated rectangle. This module reads the same label map the way a person writes a facade:

1. **Soft cuts.** Along an axis, every line (a row for ``y``) whose commonest label covers at least
   ``1 - tau`` of it is *uniform*; runs of uniform lines are bands of that label, and what lies between them is a
   structured band, read again along the other axis. A line a pillar or a stray box crosses for a few pixels
   stays uniform, so floors become siblings where one offset side column would stop a clean cut.
2. **Stripes.** Where neither axis has a uniform line, the band is cut where consecutive lines stop agreeing
   (short transitions join their neighbour), so every piece is nearly constant along the axis and reads as
   runs along the other.
3. **Consensus folds.** Along every split, runs of siblings (periods of 1 to 4) whose lengths agree within
   ``tolerance`` and whose label maps agree on at least ``1 - eps`` of the pixels (one scaled onto the other)
   become one repeat. The repeat's pattern is read from the siblings' per-pixel majority label map: the elements
   most copies show, at their mean size. A window missed in one floor comes back; a stray box goes.

``eps`` sets the trade between fidelity and compactness: 0 folds only what is identical, larger values fold
floors and tiles that differ in details. `facaid.pipeline` reads several and ranks them with the others.
"""

from __future__ import annotations

import numpy as np

from facaid.grammar.procedure import Procedure, ProcedureError
from facaid.reading.induce import _node as to_node
from facaid.reading.induce import _Tree as InducedTree
from facaid.labels import LABELS
from facaid.segmentation import Segmentation, rasterize

_N = len(LABELS)
_MAX_DEPTH = 24
_MAX_PERIOD = 4


def _line_counts(a: np.ndarray) -> np.ndarray:
    """(n, labels) counts of each label on each line (row) of ``a``."""
    n, m = a.shape
    idx = a.astype(np.int64) + _N * np.arange(n)[:, None]
    return np.bincount(idx.ravel(), minlength=n * _N).reshape(n, _N)


def _runs(flags: np.ndarray) -> list[tuple[int, int, object]]:
    """Maximal runs of equal values: [(start, stop, value)]."""
    out = []
    start = 0
    for i in range(1, len(flags) + 1):
        if i == len(flags) or flags[i] != flags[start]:
            out.append((start, i, flags[start]))
            start = i
    return out


def _scale(a: np.ndarray, n: int) -> np.ndarray:
    """``a`` (lines along axis 0) resampled to ``n`` lines (nearest)."""
    if a.shape[0] == n:
        return a
    idx = np.minimum((np.arange(n) + 0.5) * a.shape[0] / n, a.shape[0] - 1).astype(np.int64)
    return a[idx]


def _majority(maps: list[np.ndarray], n: int) -> np.ndarray:
    """The per-pixel commonest label of the maps, each scaled to ``n`` lines."""
    stack = np.stack([_scale(m, n) for m in maps])
    votes = np.zeros((_N, *stack.shape[1:]), dtype=np.int32)
    for k in range(_N):
        votes[k] = (stack == k).sum(axis=0)
    return votes.argmax(axis=0).astype(np.uint8)


def _elements(tree: InducedTree) -> int:
    """Element leaves of a tree (wall and background leaves do not count)."""
    if tree.rule == "leaf":
        return int(LABELS[tree.label] not in ("facade", "background"))
    return sum(_elements(c) for c in tree.children)


class _Reader:
    def __init__(self, tau: float, eps: float, tolerance: float, min_px: int, lookahead: int, sliver: int):
        self.tau, self.eps, self.tolerance, self.min_px, self.lookahead = tau, eps, tolerance, min_px, lookahead
        self.sliver = sliver

    def read(self, a: np.ndarray, axis: str, depth: int = 0) -> InducedTree:
        """The tree of label map ``a`` (lines along axis 0 are cut first: rows for ``axis`` y, ``a`` is then the
        map itself; for x, ``a`` is the transposed map)."""
        counts = np.bincount(a.ravel(), minlength=_N)
        top = int(counts.argmax())
        if counts[top] >= (1 - self.tau / 4) * a.size or depth >= _MAX_DEPTH or min(a.shape) < 2:
            return InducedTree("leaf", label=top)
        other = "x" if axis == "y" else "y"
        options = []
        for cut_axis, lines in ((axis, a), (other, a.T)):
            bands = self._uniform_bands(lines)
            if len(bands) > 1:
                options.append((lines, cut_axis, bands))
        if options:
            if depth >= self.lookahead or len(options) == 1:
                return self._split(*max(options, key=lambda o: len(o[2])), depth)
            trees = [self._split(*o, depth) for o in options]
            return min(trees, key=_elements)  # the first (preferred) one on a tie
        for cut_axis, lines in ((axis, a), (other, a.T)):
            bands = self._stripes(lines)
            if len(bands) > 1:
                return self._split(lines, cut_axis, bands, depth)
        return InducedTree("leaf", label=top)

    def _uniform_bands(self, lines: np.ndarray) -> list[tuple[int, int, int]]:
        """[(start, stop, kind)] covering the lines: runs of *plain* lines and the structured runs between them
        (kind -1). A line is plain when its commonest label covers at least ``1 - tau`` of it, not counting the
        positions that one label holds along nearly all the lines (a pillar through every floor): kind is that
        label where those positions hold it too (a band of one label), else -2 (a band of the label with the
        pillars through it). A plain run shorter than ``min_px`` between two structured ones is shared out between
        them (a floor gap of a pixel is a cut, not a band)."""
        n, m = lines.shape
        through = _line_counts(lines.T)  # (positions, labels)
        spanning = through.max(axis=1) >= 0.9 * n
        rest = lines[:, ~spanning] if (~spanning).any() else lines
        c = _line_counts(rest)
        top = c.argmax(axis=1)
        uniform = c.max(axis=1) >= (1 - self.tau) * rest.shape[1]
        span_labels = set(through[spanning].argmax(axis=1).tolist())
        plain_kind = np.array([k if span_labels <= {k} else -2 for k in range(_N)])
        flags = np.where(uniform, plain_kind[top] * 100 + top, -1)  # plain runs of one top label stay one run
        runs = _runs(flags)
        out: list[list[int]] = []
        for i, (s, e, f) in enumerate(runs):
            v = -1 if f == -1 else (-2 if f < 0 else int(f) % 100)
            thin = v != -1 and e - s < self.min_px
            if thin and 0 < i < len(runs) - 1:
                mid = (s + e) // 2
                out[-1][1] = mid
                out.append([mid, e, -1])
                continue
            if thin or (out and v == -1 and out[-1][2] == -1):
                if out:
                    out[-1][1] = e
                else:
                    out.append([s, e, -1 if thin else v])
                continue
            out.append([s, e, v])
        merged: list[list[int]] = []
        for s, e, v in out:  # neighbours of one kind join
            if merged and merged[-1][2] == v and v != -2:
                merged[-1][1] = e
            else:
                merged.append([s, e, v])
        return [tuple(x) for x in merged]

    def _stripes(self, lines: np.ndarray) -> list[tuple[int, int, int]]:
        """Cuts where consecutive lines stop agreeing on at least ``1 - tau`` of their pixels; pieces shorter
        than ``min_px`` join the neighbour they agree with most."""
        n = lines.shape[0]
        if n < 2:
            return [(0, n, -1)]
        agree = (lines[1:] == lines[:-1]).mean(axis=1)
        cuts = [0, *(np.flatnonzero(agree < 1 - self.tau) + 1).tolist(), n]
        pieces = [[s, e] for s, e in zip(cuts[:-1], cuts[1:], strict=True) if e > s]
        changed = True
        while changed and len(pieces) > 1:
            changed = False
            for i, (s, e) in enumerate(pieces):
                if e - s >= self.min_px:
                    continue
                if i == 0:
                    j = 1
                elif i == len(pieces) - 1:
                    j = i - 1
                else:
                    up = (lines[s] == lines[pieces[i - 1][1] - 1]).mean()
                    down = (lines[e - 1] == lines[pieces[i + 1][0]]).mean()
                    j = i - 1 if up >= down else i + 1
                lo, hi = min(i, j), max(i, j)
                pieces[lo] = [pieces[lo][0], pieces[hi][1]]
                del pieces[hi]
                changed = True
                break
        return [(s, e, -1) for s, e in pieces]

    def _split(self, lines: np.ndarray, axis: str, bands: list[tuple[int, int, int]], depth: int) -> InducedTree:
        pieces = []  # [length, label of a one-label band or -1, map with lines along this axis]
        for s, e, v in bands:
            part = lines[s:e]
            if v == -2:  # a plain band with pillars through it: its lines' majority, the same on every line
                part = np.repeat(_line_counts(part.T).argmax(axis=1).astype(part.dtype)[None], len(part), axis=0)
            pieces.append([e - s, v if v >= 0 else -1, part])
        pieces = self._absorb(pieces)
        other = "y" if axis == "x" else "x"
        items = [(float(n), InducedTree("leaf", label=v) if v >= 0 else self.read(part.T, other, depth + 1), part)
                 for n, v, part in pieces]
        if len(items) == 1:
            return items[0][1]
        return self._fold(axis, items, depth)

    def _absorb(self, pieces: list) -> list:
        """Pieces thinner than ``sliver`` pixels (an edge of the next band that leaked in, a hairline gap) become
        part of their longer neighbour: its edge line drawn over them."""
        while len(pieces) > 1:
            thin = [k for k, it in enumerate(pieces) if it[0] < self.sliver]
            if not thin:
                break
            k = min(thin, key=lambda j: pieces[j][0])
            j = k - 1 if k == len(pieces) - 1 or (k > 0 and pieces[k - 1][0] >= pieces[k + 1][0]) else k + 1
            keep = pieces[j][2]
            filler = np.repeat(keep[-1:] if j < k else keep[:1], pieces[k][0], axis=0)
            part = np.concatenate([keep, filler] if j < k else [filler, keep])
            pieces[j] = [pieces[j][0] + pieces[k][0], pieces[j][1], part]
            del pieces[k]
        return pieces

    def _alike(self, a, b) -> bool:
        """A cheap gate: lengths within the tolerance, and leaves of one label or maps agreeing on at least
        ``1 - 3 eps`` of the pixels (the run as a whole is held to ``eps`` by `_fits`)."""
        la, lb = a[0], b[0]
        if abs(la - lb) > max(self.min_px, self.tolerance * max(la, lb)):
            return False
        if a[1].rule == "leaf" or b[1].rule == "leaf":
            return a[1].rule == b[1].rule and a[1].label == b[1].label
        n = max(a[2].shape[0], b[2].shape[0])
        return float((_scale(a[2], n) == _scale(b[2], n)).mean()) >= 1 - 3 * self.eps

    def _fits(self, part: list, p: int) -> list | None:
        """The pattern of a run folded with period ``p``: [(mean length, majority map)] per position, or None
        where the copies disagree with their majority on more than ``eps`` of the run's pixels."""
        wrong = total = 0
        pattern = []
        for j in range(p):
            group = part[j::p]
            mean = max(1, round(float(np.mean([g[0] for g in group]))))
            consensus = _majority([g[2] for g in group], mean)
            for g in group:
                wrong += int((_scale(consensus, g[2].shape[0]) != g[2]).sum())
                total += g[2].size
            pattern.append((float(np.mean([g[0] for g in group])), consensus))
        return pattern if wrong <= self.eps * total else None

    def _best_run(self, items, i):
        """(covered, period, repeats, tail, pattern) of the longest run from item ``i`` that folds, or None."""
        best = None
        n = len(items)
        for p in range(1, _MAX_PERIOD + 1):
            # a run must hold an element, not only wall: folding bare wall gains nothing
            if not any(it[1].rule != "leaf" or LABELS[it[1].label] not in ("facade", "background")
                       for it in items[i : i + p]):
                continue
            reps = 1
            while (i + (reps + 1) * p <= n
                   and all(self._alike(items[i + j], items[i + reps * p + j]) for j in range(p))):
                reps += 1
            while reps >= 2:
                t = 0
                while t < p - 1 and i + reps * p + t < n and self._alike(items[i + t], items[i + reps * p + t]):
                    t += 1
                covered = reps * p + t
                if best is not None and covered <= best[0]:
                    break
                pattern = self._fits(items[i : i + covered], p)
                if pattern is not None:
                    best = (covered, p, reps, t, pattern)
                    break
                reps -= 1
        return best

    def _fold(self, axis: str, items: list, depth: int) -> InducedTree:
        out = []
        i = 0
        while i < len(items):
            run = self._best_run(items, i)
            if run is None:
                out.append(items[i][:2])
                i += 1
                continue
            covered, p, reps, t, pattern = run
            part = items[i : i + covered]
            lengths, children = [], []
            for j, (mean, consensus) in enumerate(pattern):
                group = part[j::p]
                if all(g[1].rule == "leaf" for g in group):
                    child = group[0][1]
                else:
                    child = self.read(consensus.T, "y" if axis == "x" else "x", depth + 1)
                lengths.append(mean)
                children.append(child)
            out.append((float(sum(g[0] for g in part)),
                        InducedTree("repeat", axis=axis, lengths=lengths, children=children, count=reps, tail=t)))
            i += covered
        if len(out) == 1:
            return out[0][1]
        return InducedTree("split", axis=axis, lengths=[x for x, _ in out], children=[c for _, c in out])


def regular_procedure(seg: Segmentation, *, eps: float = 0.1, tau: float = 0.03, tolerance: float = 0.15,
                      snap: float = 0.006, lookahead: int = 2, sliver: float = 0.004) -> Procedure | None:
    """A compact procedure for the (flattened) segmentation, or None where the grammar's limits are exceeded.
    ``tau``: share of a line that may disagree with its label for it to count as uniform; ``eps``: share of the
    pixels in which siblings may differ and still fold; ``tolerance``: relative difference of their lengths;
    ``snap``: the shortest band kept, as a share of the longer side."""
    label_map = rasterize(seg)
    min_px = max(2, round(snap * max(seg.width, seg.height)))
    tree = _Reader(tau, eps, tolerance, min_px, lookahead, max(1, round(sliver * max(seg.width, seg.height)))).read(label_map, "y")
    proc = Procedure(seg.width, seg.height, to_node(tree), {"source": "facaid.regular", "eps": eps})
    try:
        return Procedure.from_dict(proc.to_dict())
    except ProcedureError:
        return None
