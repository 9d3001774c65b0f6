"""The heuristic facade generator: style presets S, production picker H_p and argument picker H_a.

`generate(seed)` is deterministic: the same seed (and style) gives the same procedure on every machine.
"""

from __future__ import annotations

import random
from dataclasses import dataclass

from facaid.generator.heuristics import build_procedure
from facaid.generator.styles import PRESETS, STYLE_NAMES, Style, sample_style
from facaid.grammar.execute import execute, leaf_array
from facaid.grammar.procedure import Procedure
from facaid.segmentation import Segmentation, flatten_array

__all__ = ["PRESETS", "STYLE_NAMES", "TRAINING_STYLES", "Sample", "Style", "generate", "generate_procedure",
           "sample_style"]

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
    """A facade procedure for the seed; ``style`` picks a preset (random per seed when None) or "wing"."""
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
    proc = generate_procedure(seed, style)
    w, h = round(proc.width), round(proc.height)
    seg = Segmentation.from_array(w, h, flatten_array(w, h, leaf_array(proc, execute(proc))))
    return Sample(seed, proc.meta["style"], proc, seg)
