"""A generated facade from its seed: its style (or a building of several wings), the tree the heuristics grow
(`facaid.generator.image`), validated (`generate_procedure`), or executed and flattened (`generate`,
`generate_rows`)."""


from __future__ import annotations

import random
from dataclasses import dataclass

import numpy as np

from facaid.generator.image import build_procedure
from facaid.generator.styles import STYLE_NAMES, sample_style
from facaid.grammar.execute import flat_rows
from facaid.grammar.procedure import Procedure, validate
from facaid.segmentation import Segmentation

__all__ = ["TRAINING_STYLES", "WING_STYLES", "Sample", "generate", "generate_procedure", "generate_rows"]

WING_STYLES = ("tenement", "modernist", "commercial", "house", "wings")
# "wing": one building of the `wings` preset drawn as a facade of its own. Never the generator's own choice (held-out
# facades keep their distribution); training may draw it (`train.style_weights`) to learn the buildings that
# `wings` facades are made of, half of them of this preset, which no other style draws alone.
TRAINING_STYLES = (*STYLE_NAMES, "wing")


@dataclass
class Sample:
    seed: int
    style: str
    procedure: Procedure
    segmentation: Segmentation  # the executed procedure, flattened (wall as pieces)


def generate_procedure(seed: int, style: str | None = None) -> Procedure:
    """A facade procedure for the seed, validated; ``style`` picks a preset (random per seed when None) or
    "wing"."""
    proc = _build(seed, style)
    validate(proc)
    return proc


def _build(seed: int, style: str | None) -> Procedure:
    rng = random.Random(f"facaid-generator:{seed}")
    name = style if style is not None else rng.choice(STYLE_NAMES)
    main = sample_style(rng, "wings" if name == "wing" else name)
    if name == "wing":
        main.wings = 1
    styles = [main]
    if main.wings > 1:
        for _ in range(main.wings - 1):
            other = sample_style(rng, rng.choice(WING_STYLES))
            other.wings = 1
            other.sky, other.side_bg = main.sky, main.side_bg
            styles.append(other)
        rng.shuffle(styles)
    long_side = rng.uniform(480.0, 1024.0)
    proc = build_procedure(rng, styles, long_side)
    proc.meta = {"style": name, "seed": seed}
    return proc


def generate(seed: int, style: str | None = None) -> Sample:
    """The procedure of `generate_procedure` with its flat segmentation."""
    proc, rows = generate_rows(seed, style)
    return Sample(seed, proc.meta["style"], proc, Segmentation.from_array(round(proc.width), round(proc.height),
                                                                          rows))


def generate_rows(seed: int, style: str | None = None) -> tuple[Procedure, np.ndarray]:
    """The procedure and its flat segmentation as int rows (label, x0, y0, x1, y1) (`flatten_array`), without
    the `Segmentation` objects a dataset file does not need."""
    proc = _build(seed, style)
    return proc, flat_rows(proc)
