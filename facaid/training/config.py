"""A training run's config: a TOML file with three tables, ``[model]`` (`FacaidConfig` fields), ``[tokenizer]``
(`TokenizerConfig` fields) and ``[train]`` (`TrainConfig` fields). Unknown tables and keys are refused by name."""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field, fields
from pathlib import Path

from facaid.generator import TRAINING_STYLES
from facaid.model import FacaidConfig
from facaid.tokenizer import TokenizerConfig


def nonnegative(value) -> bool:
    """A finite number >= 0 (a TOML string, NaN or a negative number is not)."""
    return isinstance(value, int | float) and math.isfinite(value) and value >= 0


@dataclass
class TrainConfig:
    out: str = "runs/default"
    seed: int = 1  # training dataset seed
    val_seed: int = 2  # validation dataset seed (held out)
    val_count: int = 256
    batch_size: int = 32
    pool_batches: int = 32  # batches per length-sorted pool
    lr: float = 1e-3
    min_lr: float = 1e-4
    weight_decay: float = 0.01
    warmup: int = 300
    steps: int = 10000
    max_hours: float = 3.0  # stop (and save) when this much wall time has passed in this run
    eval_every: int = 500
    save_every: int = 500
    grad_clip: float = 1.0
    threads: int = 0  # torch threads on CPU; 0: all cores
    workers: int = 0  # processes generating samples; 0: in the training process (results are identical)
    noise: float = 0.0  # share of examples whose input edges are jittered (the target stays the clean procedure)
    noise_sigma: float = 0.006  # the jitter's standard deviation is uniform in [0, this] x the long side
    annotate: float = 0.0  # share of examples whose input is annotated as people annotate: edges moved as on CMP,
    # some elements left out, spurious boxes added (`facaid.training.samples.make_example`); the target stays clean
    partial: float = 0.0  # share of examples whose input keeps only part of its elements (10-80 % left out): the
    # facade a person has begun to draw, conditioning the model to continue it; the target is the whole procedure
    irregular: float = 0.0  # share of examples whose floors and bays are spaced as irregularly as on CMP
    outline: float = 0.0  # share of examples whose facade rectangle is missing or covers part of the building
    init: str = ""  # a checkpoint directory whose weights start the run (fine-tuning); fresh optimizer and schedule
    count_lr_scale: float = 1.0  # the peer counts' embeddings learn at this multiple of the learning rate (a
    # model widened for them starts them at zero while the rest is trained already)
    box_lr_scale: float = 1.0  # the same for the box bias's per-head scales (`FacaidConfig.box_bias`)
    grown_lr_scale: float = 1.0  # the same for the decoder blocks and encoder layers appended to the ``init``
    # checkpoint's (`facaid.training.surgery.deepened`, `encoder_deepened`), with weight decay as the rest
    # A scale of 0 freezes those parameters: no gradient is computed for them. With the box scales frozen the
    # cross-attention's bias needs none, so it runs in the fused attention kernel (bench/bench_train.py: a CPU
    # step 1.2x as fast at the median, a run of long batches 1.4x).
    style_weights: dict[str, float] = field(default_factory=dict)  # relative weight of generator styles in the
    # training samples (a style not named weighs 1, "wing" 0; empty: the generator's own choice, each style alike)
    structure_weight: float = 1.0  # the training loss weighs the structure this much against the sizes' values
    # (`structure_weighted_loss`); 1: the plain per-token NLL. Validation always reports the plain NLL.

    def __post_init__(self) -> None:
        unknown = set(self.style_weights) - set(TRAINING_STYLES)
        if unknown:
            raise ValueError(f"style_weights: unknown style(s) {', '.join(sorted(unknown))}; expected some of "
                             f"{', '.join(TRAINING_STYLES)}")
        weights = self.style_weights.values()
        if not all(nonnegative(w) for w in weights):
            raise ValueError(f"style_weights must be finite numbers >= 0, got {self.style_weights}")
        if self.style_weights and sum(self.styles) <= 0:
            raise ValueError("style_weights: at least one style must weigh more than 0")
        for name in ("count_lr_scale", "box_lr_scale", "grown_lr_scale"):
            value = getattr(self, name)
            if not nonnegative(value):
                raise ValueError(f"{name} must be a finite number >= 0 (0 freezes those parameters), got {value!r}")
        for name in ("noise", "annotate", "partial", "irregular", "outline"):
            value = getattr(self, name)
            if not (nonnegative(value) and value <= 1):
                raise ValueError(f"{name} must be a share between 0 and 1, got {value!r}")
        if not nonnegative(self.structure_weight) or self.structure_weight == 0:
            raise ValueError(f"structure_weight must be a finite number > 0 (1: the plain NLL), got "
                             f"{self.structure_weight!r}")

    @property
    def styles(self) -> tuple[float, ...] | None:
        """The weight of each of `TRAINING_STYLES` in order, or None for the generator's own choice. "wing" weighs 0
        unless named: drawn last with no weight, it leaves every other draw as it was."""
        if not self.style_weights:
            return None
        return tuple(float(self.style_weights.get(name, 0.0 if name == "wing" else 1.0)) for name in TRAINING_STYLES)


ARCHITECTURE = ("d_model", "encoder_layers", "decoder_layers", "heads", "ffn", "dropout", "encoder", "node_boxes",
                 "box_bias")


def load_config(path: str | Path) -> tuple[FacaidConfig, TokenizerConfig, TrainConfig]:
    with open(path, "rb") as f:
        raw = tomllib.load(f)
    unknown = set(raw) - {"model", "tokenizer", "train"}
    if unknown:
        raise ValueError(f"{path}: unknown table(s) {', '.join(sorted(unknown))}")

    def build(cls, table: str):
        values = raw.get(table, {})
        names = {f.name for f in fields(cls)}
        bad = set(values) - names
        if bad:
            raise ValueError(f"{path}: unknown key(s) in [{table}]: {', '.join(sorted(bad))}")
        return cls(**values)

    tok = build(TokenizerConfig, "tokenizer")
    train = build(TrainConfig, "train")
    model_values = raw.get("model", {})
    allowed = {"d_model", "encoder_layers", "decoder_layers", "heads", "ffn", "dropout", "encoder", "node_boxes",
               "box_bias"}
    bad = set(model_values) - allowed
    if bad:
        raise ValueError(f"{path}: unknown key(s) in [model]: {', '.join(sorted(bad))}")
    return FacaidConfig(tokenizer=tok.to_dict(), **model_values), tok, train
