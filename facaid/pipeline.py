"""`reconstruct`: from a segmentation to a sized procedure that reproduces it, as `ReconstructOptions` say.

The path it takes, a function each: reading (flatten, fit to what the model reads), candidates (grammar-constrained
best-of-K decoding, `_candidates`), sizing (`_sized`), choice (the exact procedure or the lattice reading first,
`_chosen`). The shipped model is loaded once per process on first use (CUDA when present) unless a model is passed
in.

A second chance: when the sized best candidate reproduces less than ``retry_below`` of the pixels, its
structure is likely wrong (sizing cannot change counts or labels), so ``retry_k`` more samples are decoded and
every candidate gets the geometric fit alone; the best of those is sized fully and kept if it does better.
Before that (unless a prefix is given or ``induce`` is off) the structure induced straight from the segmentation
(`facaid.reading.induce`: guillotine cuts folded into repeats) is sized too and kept if it does better, and then
the sampling is skipped. ``result.source`` says which kind of structure won.

Two structures (``structure``): the model's, where it wins, is compact and editable already (a generated facade);
where induction wins (a real facade, whose induced procedure copies the annotation as drawn: the *exact* one), the
lattice reader (`facaid.reading.lattice`) reads the facade as floors of tiles with exceptions (candidate readings:
its floors and bays one by one, else two by two; the first whose `floors` + 1 and `bays` + 1 are clean, else the
most accurate: `best_reading`), and that sized is the *editable* one. ``structure="editable"`` (the default)
returns it with the exact one as ``alternative``; ``"exact"`` the other way round. Where there is no lattice to
read, both are the one procedure.

A shortcut for annotations unlike the model's training data: when the decoded structure reproduces less than
`FAR_OFF` of the pixels before sizing and the induced one at least `FAR_BEHIND` more, only the induced one is
sized (``result.shortcut``): sizing the decoded structure could not close that gap, and it is the slowest stage.
The test is made on the greedy candidate, decoded first and alone, so that the samples are not drawn where it
holds (`_candidates`).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np
import torch

from facaid.decoding import Candidate, decode, ranked_candidates
from facaid.defaults import DEFAULT_K, STRUCTURES, TEMPERATURE
from facaid.editing.check import MORE, check_edits
from facaid.editing.describes import describes
from facaid.grammar.execute import to_segmentation
from facaid.grammar.procedure import Procedure
from facaid.labels import FACADE
from facaid.metrics import element_leaves, procedure_accuracy, procedure_iou, unexplained
from facaid.model import FacaidModel, load_model
from facaid.paths import DEFAULT_CHECKPOINT
from facaid.reading.induce import induce_procedure
from facaid.reading.lattice import readings
from facaid.reading.windows import pitches
from facaid.segmentation import Segmentation, flatten, flatten_array, rasterize
from facaid.sizing import fit_sizes, forget_tables
from facaid.tokenizer import Tokenizer

# When the best decoded structure reproduces less than FAR_OFF of the pixels before sizing, the induced structure
# is read at once; if it reproduces at least FAR_BEHIND more, only it is sized. On 120 generated inputs (dataset
# seed 3000, clean and with 20 % of the pixels jittered) sizing raised decoded structures that started below 0.9
# by 0.11 at the median and 0.29 at most, so a gap of 0.35 is one sizing does not close.
FAR_OFF = 0.9
FAR_BEHIND = 0.35
# A sized model structure that fits worse than the induced one is still kept when it is more compact and disagrees
# with the input only along the input's edges but for this share of the pixels (`reads_through_noise`). On 10
# generated facades annotated as people do (`annotator_noise`) the model's structures that restored the clean facade
# left 0.006-0.013 unexplained and the ones that did not 0.03-0.06; on 6 CMP dev facades, where the model's
# structures are wrong, 0.02-0.26 (experiments/2026-12-03-noise-aware).
NOISE_ONLY = 0.015


@dataclass
class Reconstruction:
    procedure: Procedure
    accuracy_decoded: float  # pixel accuracy of the decoded procedure before sizing
    accuracy: float  # after sizing, exact at full resolution
    iou: dict[str, float]
    timings: dict[str, float] = field(default_factory=dict)  # seconds per stage
    retried: bool = False  # the second chance ran (the first sized candidate was below retry_below)
    source: str = "model"  # "model" (a decoded candidate) or "induced" (facaid.reading.induce)
    shortcut: bool = False  # the decoded structure was far behind the induced one and was not sized
    denoised: bool = False  # the model's structure was kept over a closer-fitting induced one (reads_through_noise)
    structure: str = "exact"  # what ``procedure`` is: "editable" (floors of tiles: the model's or the lattice's)
    alternative: Procedure | None = None  # the other structure, where there are two
    alternative_accuracy: float | None = None
    candidates: int = 0  # how many candidates were decoded (the greedy one alone where the input is far off)

    def to_dict(self) -> dict[str, Any]:
        out = {"accuracy_decoded": self.accuracy_decoded, "accuracy": self.accuracy, "iou": self.iou,
               "timings": self.timings, "retried": self.retried, "source": self.source, "shortcut": self.shortcut,
               "denoised": self.denoised, "structure": self.structure, "candidates": self.candidates}
        if self.alternative is not None:
            out["alternative_accuracy"] = self.alternative_accuracy
        return out


def fit_to_model(seg: Segmentation, tokenizer: Tokenizer) -> Segmentation:
    """The segmentation, or, when it has more rectangles than the model reads, the same with its smallest
    elements left out until it fits (the sizing still fits against the full segmentation)."""
    limit = tokenizer.config.max_rects
    rows = flatten_array(seg.width, seg.height, seg.to_array(), wall="footprint")
    if len(rows) <= limit:
        return seg
    footprint = rows[rows[:, 0] == FACADE]
    elements = rows[rows[:, 0] != FACADE]
    area = (elements[:, 3] - elements[:, 1]) * (elements[:, 4] - elements[:, 2])
    keep = elements[np.argsort(-area, kind="stable")[: max(0, limit - len(footprint))]]
    return Segmentation.from_array(seg.width, seg.height, np.concatenate([footprint, keep]))


@lru_cache(maxsize=4)
def default_model(path: str = str(DEFAULT_CHECKPOINT)) -> tuple[FacaidModel, Tokenizer]:
    device = "cuda" if torch.cuda.is_available() else "cpu"
    return load_model(Path(path), device)


@dataclass(frozen=True)
class ReconstructOptions:
    """How `reconstruct` reads a segmentation (see the module's docstring). ``k``: the candidates decoded (best of
    K); ``sizing``: whether the winner is sized (off: the decoded structure as it is); ``seed``; ``prefix``: token
    ids the model continues from (a re-run that keeps a procedure's first nodes; the structure is then the
    model's); ``retry_below`` and ``retry_k``: the second chance; ``induce``: whether the induced structure
    competes; ``structure``: which of the two structures is returned first, "editable" or "exact"."""

    k: int = DEFAULT_K
    sizing: bool = True
    seed: int = 0
    prefix: tuple[int, ...] | None = None
    retry_below: float = 0.97
    retry_k: int = 8
    induce: bool = True
    structure: str = "editable"

    def __post_init__(self) -> None:
        if self.structure not in STRUCTURES:
            raise ValueError(f"structure must be one of {', '.join(STRUCTURES)}, got {self.structure!r}")
        if self.prefix is not None:
            object.__setattr__(self, "prefix", tuple(self.prefix))

    @property
    def prefix_ids(self) -> list[int] | None:
        """The prefix as the decoder takes it (a list), or None."""
        return list(self.prefix) if self.prefix is not None else None

    @property
    def free(self) -> bool:
        """Whether the structure is the reader's to choose: the model's, induced or read as a lattice (no prefix)."""
        return self.prefix is None


def reconstruct(segmentation: Segmentation | dict, options: ReconstructOptions | None = None, *,
                model: FacaidModel | None = None, tokenizer: Tokenizer | None = None,
                progress: Callable[[float, str], None] | None = None) -> Reconstruction:
    """Reconstruct a procedure for a segmentation (a `Segmentation` or its JSON object), as ``options`` say
    (default `ReconstructOptions`), with the shipped model unless ``model`` and ``tokenizer`` are given. The path
    it takes: reading (flatten, fit to what the model reads), candidates (decoded, and the induced structure where
    the greedy one is far off), sizing (the winner, the induced structure where it fits closer, the second
    chance), choice (the exact procedure and the lattice reading: which is returned first).

    ``progress(fraction, stage)``, when given, is told each stage as it starts (fractions from 0 to 1, roughly
    of the time taken)."""
    opts = options or ReconstructOptions()
    seg = segmentation if isinstance(segmentation, Segmentation) else Segmentation.from_dict(segmentation)
    if model is None or tokenizer is None:
        model, tokenizer = default_model()
    tell = progress or (lambda fraction, stage: None)
    clock = [time.perf_counter()]

    def lap() -> float:
        clock.append(time.perf_counter())
        return clock[-1] - clock[-2]

    k = opts.k
    tell(0.0, f"decoding {'up to ' if k > 1 else ''}{k} candidate{'s' if k > 1 else ''}")
    flat = flatten(seg)
    readable = fit_to_model(flat, tokenizer)
    timings = {"flatten": lap()}
    found = _candidates(model, tokenizer, readable, flat, opts)
    timings["decode"] = lap()
    if opts.sizing:
        tell(0.5, "sizing")
        result = _sized(found, model, tokenizer, readable, flat, opts, tell)
    else:
        decoded = found.ranked[0].procedure
        before = procedure_accuracy(decoded, flat)
        result = Reconstruction(decoded, before, before, procedure_iou(decoded, flat), candidates=found.drawn,
                                structure="editable")
    timings["sizing"] = lap()
    result.procedure.meta = {"source": "facaid.reconstruct", "structure": result.source, "k": k,
                             "accuracy": round(result.accuracy, 6)}
    result = _chosen(result, flat, opts, tell)
    forget_tables()  # the tables its sizings shared
    timings["lattice"] = lap()
    result.timings.update(timings, total=clock[-1] - clock[0])
    return result


@dataclass
class _Candidates:
    """What decoding found: the ranked candidates, the induced structure and whether it was read (it is read at
    most once a reconstruction), and how many candidates were decoded."""

    ranked: list[Candidate]
    induced: Procedure | None
    read: bool
    drawn: int


def _candidates(model: FacaidModel, tokenizer: Tokenizer, readable: Segmentation, flat: Segmentation,
                opts: ReconstructOptions) -> _Candidates:
    """The candidates (`ranked_candidates`). Where the structure is the reader's to choose and K > 1, the greedy
    candidate is decoded first, alone: where it is `FAR_OFF` and the induced structure `FAR_BEHIND` ahead of it
    (an annotation unlike the model's training data: a real facade), the samples are not drawn, as only the
    induced structure is sized then; else the K - 1 samples follow, the same as decoded in one batch with it."""
    k, seed, prefix = opts.k, opts.seed, opts.prefix_ids
    if not (opts.sizing and opts.induce and opts.free) or k == 1:
        return _Candidates(ranked_candidates(model, tokenizer, readable, k=k, seed=seed, prefix=prefix,
                                             reference=flat), None, False, k)
    greedy = decode(model, tokenizer, readable, k=1, temperature=TEMPERATURE, seed=seed)[0]
    greedy_before = procedure_accuracy(greedy.procedure, flat)
    induced, read = None, False
    if greedy_before < FAR_OFF:
        induced, read = induce_procedure(flat), True
        if induced is not None and procedure_accuracy(induced, flat) >= greedy_before + FAR_BEHIND:
            return _Candidates(ranked_candidates(model, tokenizer, readable, k=1, reference=flat, greedy=greedy),
                               induced, True, 1)
    return _Candidates(ranked_candidates(model, tokenizer, readable, k=k, seed=seed, reference=flat, greedy=greedy),
                       induced, read, k)


def _sized(found: _Candidates, model: FacaidModel, tokenizer: Tokenizer, readable: Segmentation,
           flat: Segmentation, opts: ReconstructOptions, tell: Callable[[float, str], None]) -> Reconstruction:
    """The best candidate sized (`fit_sizes`), or the induced structure where it fits closer (alone where the
    decoded one is far behind: the shortcut; not where the model's structure reads through an annotator's noise),
    or, below ``retry_below``, the best of ``retry_k`` more samples (the second chance)."""
    decoded = found.ranked[0].procedure
    before = procedure_accuracy(decoded, flat)
    induced, read, drawn = found.induced, found.read, found.drawn
    retried = shortcut = denoised = False
    source = "model"
    gate = opts.induce and opts.free
    if gate and before < FAR_OFF and not read:
        induced, read = induce_procedure(flat), True
    induced_before = procedure_accuracy(induced, flat) if induced is not None else None
    if induced_before is not None and induced_before >= before + FAR_BEHIND:
        fitted = fit_sizes(induced, flat, before=induced_before)  # the model's structure is not sized
        source, shortcut, before = "induced", True, induced_before
    else:
        fitted = fit_sizes(decoded, flat, before=before)
    if fitted.accuracy < opts.retry_below and gate and not shortcut:
        if not read:
            induced = induce_procedure(flat)
        if induced is not None:
            other = fit_sizes(induced, flat, before=induced_before)
            if other.accuracy > fitted.accuracy:
                if reads_through_noise(fitted.procedure, other.procedure, flat):
                    denoised = True  # the induced structure fits closer by copying the annotator's noise
                else:
                    fitted, before, source = other, other.accuracy_before, "induced"
    if fitted.accuracy < opts.retry_below and opts.retry_k and source == "model" and not denoised:
        tell(0.75, f"sampling {opts.retry_k} more candidates")
        retried, drawn = True, drawn + opts.retry_k
        more = decode(model, tokenizer, readable, k=opts.retry_k, sample=True, greedy=0, seed=opts.seed + 1,
                      prefix=opts.prefix_ids)
        other = _second_chance(found.ranked[1:] + more, found.ranked[0], flat)
        if other is not None and other.accuracy > fitted.accuracy:
            fitted, before = other, other.accuracy_before  # before sizing, of that candidate
    return Reconstruction(fitted.procedure, before, fitted.accuracy, fitted.iou, {}, retried, source, shortcut,
                          denoised, "editable" if source == "model" else "exact", candidates=drawn)


def _chosen(result: Reconstruction, flat: Segmentation, opts: ReconstructOptions,
            tell: Callable[[float, str], None]) -> Reconstruction:
    """Where the exact structure won (a real facade), the lattice reading beside it (`best_reading`), the one
    ``opts.structure`` names first."""
    if not (opts.sizing and result.source != "model" and opts.free):
        return result
    tell(0.9, "reading the floors and bays")
    editable = best_reading(flat)
    if editable is None:
        return result
    editable.procedure.meta = {"source": "facaid.reconstruct", "structure": "lattice", "k": opts.k,
                               "accuracy": round(editable.accuracy, 6), "group": editable.procedure.meta["group"]}
    return _with_editable(result, editable, opts.structure)


def best_reading(flat: Segmentation):
    """Of the lattice readings of a flattened segmentation (`facaid.reading.lattice.readings`), sized, the first
    whose `floors` + 1 and `bays` + 1 are clean (`facaid.editing.check`: the grid as read is tried first, the others
    only where its edits fail) and whose floor height is not off the floors' pitch, else the best by `reading_key`:
    the most clean edits and a floor height that is the floors' pitch (`facaid.editing.describes`), then the most
    accurate (a reading of floors two by two whose edits both fail is no better for being a little more accurate
    than the grid whose new floor is clean; one whose floor is two of the building's is worth an edit); a
    `SizingResult`, its procedure's meta naming its ``group``, or None where there is no lattice."""
    rows = flat.to_array()
    pitch = pitches(rows)  # the input's, judged against each reading
    best, key = None, None
    for group, proc in readings(flat):
        fitted = fit_sizes(proc, flat)
        verdicts = list(check_edits(fitted.procedure, MORE).values())
        fitted.procedure.meta["group"] = list(group)
        floor_pitch = describes(fitted.procedure, rows, pitch)["floor_height_ok"]
        mine = reading_key(verdicts, fitted.accuracy, floor_pitch)
        if key is None or mine > key:
            best, key = fitted, mine
        if all(v.clean for v in verdicts) and floor_pitch is not False:
            break
    return best


def reading_key(verdicts: list, accuracy: float, floor_pitch: bool | None = None) -> tuple[int, float]:
    """How `best_reading` ranks a reading: by how many of its edits' ``verdicts`` are clean, one more where its
    floor height is the floors' pitch (``floor_pitch``: True; None where there is no pitch to judge), then by
    accuracy."""
    return sum(v.clean for v in verdicts) + bool(floor_pitch), accuracy


def _with_editable(exact: Reconstruction, editable, structure: str) -> Reconstruction:
    """``exact`` with the lattice reading (a `SizingResult`) as its other structure, the one ``structure`` names
    first."""
    if structure == "exact":
        exact.alternative, exact.alternative_accuracy = editable.procedure, editable.accuracy
        return exact
    return Reconstruction(editable.procedure, editable.accuracy_before, editable.accuracy, editable.iou,
                          exact.timings, exact.retried, "lattice", False, False, "editable", exact.procedure,
                          exact.accuracy, exact.candidates)


def reads_through_noise(model: Procedure, induced: Procedure, seg: Segmentation) -> bool:
    """Whether the model's (sized) structure reads through an annotator's noise where the induced one copies it:
    it says the facade with fewer element leaves, and where it disagrees with the input it does so along the
    input's edges (within 1 % of the image: what a hand-drawn edge is off by) but for at most `NOISE_ONLY` of the
    pixels (a missed window it restores, a stray box it leaves out)."""
    if element_leaves(model) >= element_leaves(induced):
        return False
    return unexplained(rasterize(to_segmentation(model)), rasterize(seg)) <= NOISE_ONLY


def _second_chance(candidates: list[Candidate], first: Candidate, flat: Segmentation):
    """Screen the other distinct candidates with the geometric fit alone (it picks the same candidate as a short
    polish on generated facades, at half the cost); fully size the best one (None if none)."""
    seen = {tuple(first.ids)}
    best = None
    for c in candidates:
        if tuple(c.ids) in seen:
            continue
        seen.add(tuple(c.ids))
        quick = fit_sizes(c.procedure, flat, polish_steps=0)
        if best is None or quick.accuracy > best[0]:
            best = (quick.accuracy, c)
    return None if best is None else fit_sizes(best[1].procedure, flat)
