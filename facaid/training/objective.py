"""What training minimizes and reports: the learning-rate schedule, the per-token NLL split into structure and
sizes, the structure-weighted loss and the validation loss."""

from __future__ import annotations

import math

import torch
import torch.nn.functional as F

from facaid.grammar.procedure import MODES
from facaid.model import FacaidModel, batch_inputs, batch_outputs
from facaid.tokenizer import Vocabulary
from facaid.training.config import TrainConfig


def lr_at(step: int, cfg: TrainConfig) -> float:
    if step < cfg.warmup:
        return cfg.lr * (step + 1) / cfg.warmup
    t = min(1.0, (step - cfg.warmup) / max(1, cfg.steps - cfg.warmup))
    return cfg.min_lr + 0.5 * (cfg.lr - cfg.min_lr) * (1 + math.cos(math.pi * t))


def token_log_probs(logits: torch.Tensor, targets: torch.Tensor, vocab: Vocabulary
                    ) -> tuple[torch.Tensor, torch.Tensor]:
    """log p of each target token and of its structure, both over the valid targets only (-100: ignored).

    A size token is a mode (abs, flt, rel) and a quantized value, so log p(size) = log P(mode) + log
    p(value | mode) and its structure is the mode; every other token (rule, label, role, count, centre, end) is
    structure whole."""
    lp = F.log_softmax(logits.float(), dim=-1)
    valid = targets != -100
    t = targets.masked_fill(~valid, 0)
    token_lp = lp.gather(-1, t.unsqueeze(-1)).squeeze(-1)
    structure_lp = token_lp
    for mode in MODES:  # the vocabulary's size tokens, one group a mode
        r = vocab.ranges[mode]
        in_mode = (t >= r.start) & (t < r.stop)
        structure_lp = torch.where(in_mode, torch.logsumexp(lp[..., r.start:r.stop], dim=-1), structure_lp)
    return token_lp[valid], structure_lp[valid]


def structure_weighted_loss(logits: torch.Tensor, targets: torch.Tensor, vocab: Vocabulary,
                            weight: float) -> torch.Tensor:
    """The mean NLL plus (weight - 1) x the mean NLL of the structure (`token_log_probs`): the structure weighs
    ``weight`` against the sizes' values, and at weight 1 this is the NLL. Why: the values held about 97 % of the
    NLL of the weights before configs/finetune-structure.toml, mostly the spread of a value within a bin or two
    that the sizing fit makes up for anyway, so their gradient drowned that of the structure, which is the tree."""
    token_lp, structure_lp = token_log_probs(logits, targets, vocab)
    return -(token_lp + (weight - 1.0) * structure_lp).mean()


@torch.no_grad()
def validation_loss(model: FacaidModel, examples: list, batch_size: int, device,
                    vocab: Vocabulary) -> tuple[float, float]:
    """The mean per-token NLL over the examples and the mean NLL of their structure (`token_log_probs`)."""
    model.eval()
    total, structure, count = 0.0, 0.0, 0
    examples = sorted(examples, key=lambda ex: len(ex[1][0]))
    for i in range(0, len(examples), batch_size):
        chunk = examples[i : i + batch_size]
        rects, mask = batch_inputs([ex[0] for ex in chunk], device)
        ids, local, targets, boxes = batch_outputs([ex[1] for ex in chunk], device)
        logits, _ = model(rects, mask, ids, local, boxes=boxes)
        token_lp, structure_lp = token_log_probs(logits, targets, vocab)
        total -= float(token_lp.sum())
        structure -= float(structure_lp.sum())
        count += len(token_lp)
    model.train()
    return total / count, structure / count
