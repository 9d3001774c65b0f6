"""Training samples: freshly generated facades, tokenized, optionally jittered or annotated as people annotate, in
length-sorted batches.

Every sample is generated from its own seed (`facaid.generator.dataset.sample_seed`), so a run never sees the same
facade twice, the validation facades (another dataset seed) are held out, and samples made in worker processes
are those one process would make, in the same order.
"""

from __future__ import annotations

import multiprocessing
import random

import numpy as np
import torch

from facaid.augmentation import (
    ANNOTATOR_DROP,
    ANNOTATOR_SPURIOUS,
    CMP_SPACING_X,
    CMP_SPACING_Y,
    annotator_noise,
    cmp_annotation,
    jitter,
)
from facaid.augmentation import outline as drawn_outline
from facaid.generator import TRAINING_STYLES, generate
from facaid.generator.dataset import sample_seed
from facaid.labels import FACADE
from facaid.tokenizer import Tokenizer, TokenizerConfig

_worker: dict = {}
PARTIAL_DROP = (0.1, 0.8)  # a partial input leaves out a share of its elements drawn uniformly from this range
INPUTS = ("annotate", "partial", "irregular", "outline")  # the shares of inputs made as people draw (`make_example`)


def _init_worker(tok_config: dict, noise: tuple[float, float], styles: tuple[float, ...] | None,
                 inputs: dict[str, float]) -> None:
    torch.set_num_threads(1)
    _worker.update(tokenizer=Tokenizer(TokenizerConfig(**tok_config)), noise=noise, styles=styles, inputs=inputs)


def sample_style(seed: int, index: int, styles: tuple[float, ...] | None) -> str | None:
    """The style of sample ``index`` of dataset ``seed`` drawn with weights ``styles`` (one per `TRAINING_STYLES`),
    seeded by the sample; None (the generator's own choice) without weights."""
    if styles is None:
        return None
    return random.Random(f"facaid-style:{seed}:{index}").choices(TRAINING_STYLES, weights=styles)[0]


def make_example(tokenizer: Tokenizer, seed: int, index: int, noise: tuple[float, float] = (0.0, 0.0),
                 styles: tuple[float, ...] | None = None, annotate: float = 0.0, partial: float = 0.0,
                 irregular: float = 0.0, outline: float = 0.0):
    """The training example of sample ``index`` of dataset ``seed``: (rows, (ids, local, boxes)), or None when
    the facade is too long for the model. The target is always the clean procedure; the input is changed, each
    change drawn for a share of the inputs, seeded by the sample, in this order:
    ``noise`` = (share, sigma): edges jittered (`facaid.augmentation.jitter`, sigma uniform in [0, sigma]).
    ``annotate``: annotated as people annotate (`cmp_annotation`: the edge spread calibrated on CMP, up to
    `ANNOTATOR_DROP` of the elements left out and up to `ANNOTATOR_SPURIOUS` boxes added).
    ``partial``: only part of the elements kept (a share uniform in `PARTIAL_DROP` left out, the rest's edges moved
    as on CMP): the facade a person has begun to draw.
    ``irregular``: floors and bays spaced as irregularly as on CMP (`annotator_noise`'s spacing warp alone, with
    `CMP_SPACING_X`, `CMP_SPACING_Y`).
    ``outline``: the facade rectangle missing (half of those) or covering part of the building
    (`facaid.augmentation.outline`).
    ``styles``: weights of the generator styles (`sample_style`)."""
    s = generate(sample_seed(seed, index), sample_style(seed, index, styles))
    c = tokenizer.config
    target = tokenizer.encode_target(s.procedure)
    if len(target[0]) > c.max_out:
        return None
    seg = s.segmentation
    share, sigma = noise
    if share > 0:
        rng = np.random.default_rng([seed, index, 1])
        if rng.random() < share:
            seg = jitter(seg, rng.uniform(0.0, sigma), rng)
    if annotate > 0:
        rng = np.random.default_rng([seed, index, 2])
        if rng.random() < annotate:
            drop, spurious = rng.uniform(0.0, ANNOTATOR_DROP), int(rng.integers(ANNOTATOR_SPURIOUS + 1))
            seg = cmp_annotation(seg, int(rng.integers(2**31)), drop=drop, spurious=spurious)
    if partial > 0:
        rng = np.random.default_rng([seed, index, 3])
        if rng.random() < partial:
            seg = cmp_annotation(seg, int(rng.integers(2**31)), drop=rng.uniform(*PARTIAL_DROP))
    if irregular > 0:
        rng = np.random.default_rng([seed, index, 4])
        if rng.random() < irregular:
            seg = annotator_noise(seg, int(rng.integers(2**31)), edge=0.0, drop=0.0, spurious=0,
                                  spacing=CMP_SPACING_X, spacing_y=CMP_SPACING_Y)
    if outline > 0:
        rng = np.random.default_rng([seed, index, 5])
        if rng.random() < outline:
            seg = drawn_outline(seg, int(rng.integers(2**31)), missing=bool(rng.random() < 0.5))
    if not any(r.label != FACADE for r in seg.rects):  # every element left out: nothing to continue
        return None
    try:
        rows = tokenizer.encode_segmentation(seg)
    except ValueError:  # too many rectangles
        return None
    return rows, target


def _worker_example(args: tuple[int, int]):
    return make_example(_worker["tokenizer"], *args, noise=_worker["noise"], styles=_worker["styles"],
                        **_worker["inputs"])


class SampleStream:
    """Endless (rects, (ids, local, boxes)) examples from generated facades, skipping those too long for the model.

    With ``workers`` > 0, ``take`` generates in that many processes; the examples are the same, in the same
    order, as in one process."""

    def __init__(self, tokenizer: Tokenizer, seed: int, start: int = 0, workers: int = 0,
                 noise: tuple[float, float] = (0.0, 0.0), styles: tuple[float, ...] | None = None,
                 **inputs: float):
        unknown = set(inputs) - set(INPUTS)
        if unknown:
            raise TypeError(f"unknown input share(s): {', '.join(sorted(unknown))}")
        self.tokenizer = tokenizer
        self.inputs = inputs
        self.styles = styles
        self.seed = seed
        self.index = start
        self.skipped = 0
        self.noise = noise
        self.workers = workers
        self.pool = None
        if workers > 0:
            ctx = multiprocessing.get_context("spawn")  # no fork after CUDA or torch threads have started
            self.pool = ctx.Pool(workers, initializer=_init_worker,
                                 initargs=(tokenizer.config.to_dict(), noise, styles, inputs))

    def example(self, index: int):
        return make_example(self.tokenizer, self.seed, index, self.noise, self.styles, **self.inputs)

    def __next__(self):
        while True:
            ex = self.example(self.index)
            self.index += 1
            if ex is not None:
                return ex
            self.skipped += 1

    def take(self, n: int) -> list:
        """The next ``n`` examples."""
        if self.pool is None:
            return [next(self) for _ in range(n)]
        out: list = []
        while len(out) < n:
            want = n - len(out)
            indices = range(self.index, self.index + want + max(4, want // 20))  # a few spare for skips
            chunk = max(1, len(indices) // (4 * self.workers))
            for ex in self.pool.imap(_worker_example, [(self.seed, i) for i in indices], chunksize=chunk):
                if len(out) == n:
                    break
                self.index += 1
                if ex is None:
                    self.skipped += 1
                else:
                    out.append(ex)
        return out

    def close(self) -> None:
        if self.pool is not None:
            self.pool.terminate()
            self.pool = None


class PooledBatches:
    """Batches of similar length: fill a pool, sort it by output length, cut it, shuffle the batches.

    Its position (where the current pool starts in the stream, which pool, how many of its batches were
    used) is saved with a checkpoint, so a resumed run sees exactly the batches an uninterrupted one would."""

    def __init__(self, stream: SampleStream, batch_size: int, pool_batches: int, seed: int,
                 position: dict | None = None):
        self.stream, self.batch_size, self.pool_batches, self.seed = stream, batch_size, pool_batches, seed
        self.pool_start, self.pool_number, self.used = stream.index, 0, 0
        self.batches: list = []
        if position:
            self.pool_start, self.pool_number, self.used = (position["pool_start"], position["pool_number"],
                                                            position["used"])
            self.stream.index = self.pool_start
            self._fill()

    def _fill(self) -> None:
        self.pool_start = self.stream.index
        pool = self.stream.take(self.batch_size * self.pool_batches)
        pool.sort(key=lambda ex: (len(ex[1][0]), len(ex[0])))
        self.batches = [pool[i : i + self.batch_size] for i in range(0, len(pool), self.batch_size)]
        random.Random(f"{self.seed}:{self.pool_number}").shuffle(self.batches)

    def position(self) -> dict:
        return {"pool_start": self.pool_start, "pool_number": self.pool_number, "used": self.used}

    def __next__(self) -> list:
        if not self.batches:
            self._fill()
        elif self.used == len(self.batches):
            self.pool_number += 1
            self.used = 0
            self._fill()
        batch = self.batches[self.used]
        self.used += 1
        return batch
