"""Model surgery: a trained model changed so that it computes (nearly) what it computed, the start of a fine-tune
that changes it. `adapt_to_tokenizer` reads another input (peer counts added, coordinates finer),
`with_box_bias` adds the box bias, `deepened` and `encoder_deepened` append decoder blocks and encoder layers, and
`initial_model` applies what a run's config asks of its ``train.init`` checkpoint.
"""

from __future__ import annotations

import copy
from dataclasses import replace

import torch

from facaid.model import FacaidConfig, FacaidModel, load_model
from facaid.tokenizer import Tokenizer, TokenizerConfig
from facaid.training.config import ARCHITECTURE


def widen_for_counts(model: FacaidModel, tokenizer: Tokenizer) -> tuple[FacaidModel, Tokenizer]:
    """The same model reading the peer counts too (``count_features``), their embeddings zero: it gives the
    same logits as ``model`` until training moves them. The start of a fine-tune that adds the counts."""
    if tokenizer.config.count_features:
        raise ValueError("this model reads the peer counts already")
    return adapt_to_tokenizer(model, tokenizer, replace(tokenizer.config, count_features=True))


def _refined(table: torch.Tensor, k: int, sizes: bool) -> torch.Tensor:
    """An embedding table for coordinates k times finer. Positions (floored) take the row of the coarse step they
    lie in (j // k). Sizes (rounded; row 0 unused, 1..n lengths) interpolate between the rows of the two coarse
    lengths beside j / k: a fine length halfway between two coarse ones could have been read as either, and the
    mean of the two reads as well as either (teacher-forced loss of the shipped weights, 64 validation facades,
    k = 2: 0.192 before; 0.227 with the nearer row, 0.183 with the mean)."""
    if not sizes:
        return table[torch.arange(table.shape[0] * k, device=table.device) // k].clone()
    pos = torch.arange(table.shape[0] * k - (k - 1), device=table.device, dtype=table.dtype) / k
    lo, hi = pos.floor().long().clamp(1, table.shape[0] - 1), pos.ceil().long().clamp(1, table.shape[0] - 1)
    frac = (pos - pos.floor())[:, None]
    out = (1 - frac) * table[lo] + frac * table[hi]
    out[0] = table[0]
    return out


def adapt_to_tokenizer(model: FacaidModel, tokenizer: Tokenizer, target: TokenizerConfig
                       ) -> tuple[FacaidModel, Tokenizer]:
    """The model reading inputs tokenized by ``target`` instead, computing (nearly) what it computed: the start
    of a fine-tune that changes the input. Two changes are possible, together:

    - more peer counts (``count_features`` on, or rules added after the existing ones to ``peer_rule``): their
      embeddings start at zero, so the logits are unchanged until training moves them;
    - coordinates k times finer (``coord_bins`` and ``aspect_bins`` both times k): every fine step gets the
      embedding of the coarse step it lies in, so positions read as before; sizes and the aspect ratio are
      rounded, not floored, so a size between two coarse steps gets their mean (`_refined`) and the aspect
      ratio may read one coarse step off.
    Anything else that differs is an error."""
    src = tokenizer.config
    if target == src:
        return model, tokenizer
    k = target.coord_bins // src.coord_bins
    if target.coord_bins != k * src.coord_bins or target.aspect_bins != k * src.aspect_bins:
        raise ValueError(f"coordinates can only get an integer factor finer, coord_bins and aspect_bins alike: "
                         f"{src.coord_bins}/{src.aspect_bins} -> {target.coord_bins}/{target.aspect_bins}")
    rules = src.peer_rules if src.count_features else ()
    new_rules = target.peer_rules if target.count_features else ()
    if new_rules[:len(rules)] != rules:
        raise ValueError(f"peer counts can only be added after the ones read now: {'+'.join(rules) or 'none'} "
                         f"-> {'+'.join(new_rules) or 'none'}")
    rest = replace(target, coord_bins=src.coord_bins, aspect_bins=src.aspect_bins,
                   count_features=src.count_features, peer_rule=src.peer_rule)
    if rest != src:
        wanted = rest.to_dict()
        differ = [f for f, v in src.to_dict().items() if wanted[f] != v]
        raise ValueError(f"cannot adapt the model to another {', '.join(differ)}")
    config = copy.deepcopy(model.config)
    config.tokenizer = target.to_dict()
    adapted = FacaidModel(config).to(next(model.parameters()).device)
    state = model.state_dict()
    if k > 1:
        for f in range(1, 5):  # x (and the aspect ratio), y, w, h
            state[f"fields.{f}.weight"] = _refined(state[f"fields.{f}.weight"], k, sizes=f >= 3)
    missing, unexpected = adapted.load_state_dict(state, strict=False)
    added = {f"count_fields.{i}.weight" for i in range(4 * len(rules), 4 * len(new_rules))}
    if unexpected or set(missing) != added:
        raise ValueError(f"cannot adapt: unexpected {unexpected}, missing {missing}")
    adapted.train(model.training)
    return adapted, Tokenizer(target)


def with_box_bias(model: FacaidModel) -> FacaidModel:
    """The same model with ``box_bias`` (its scales zero): the same logits until training moves them. The start
    of a fine-tune that adds the bias."""
    if model.config.box_bias:
        raise ValueError("this model has the box bias already")
    config = copy.deepcopy(model.config)
    config.box_bias = True
    biased = FacaidModel(config).to(next(model.parameters()).device)
    missing, unexpected = biased.load_state_dict(model.state_dict(), strict=False)
    if unexpected or missing != ["box_scale"]:
        raise ValueError(f"cannot add the box bias: unexpected {unexpected}, missing {missing}")
    biased.train(model.training)
    return biased


# the projections by which a GPT-2 block writes into the residual stream: zero, the block adds nothing
_BLOCK_OUTPUTS = ("attn.c_proj.", "crossattention.c_proj.", "mlp.c_proj.")


def _grown(model: FacaidModel, key: str, layers: int, stem: str, outputs: tuple[str, ...],
           norms: tuple[str, ...] = ()) -> tuple[FacaidModel, dict, dict]:
    """A model with ``layers`` blocks where ``model`` has ``config.<key>``, and the state that fills it: the
    blocks under ``stem`` appended after the last, each a copy of it whose ``outputs`` are zero and whose ``norms``
    are plain (gain 1, bias 0). Also the last block's own state, by name within the block."""
    have = getattr(model.config, key)
    if layers <= have:
        raise ValueError(f"a deepened model needs more than the {have} {key.replace('_', ' ')} it has, got {layers}")
    config = copy.deepcopy(model.config)
    setattr(config, key, layers)
    deep = FacaidModel(config).to(next(model.parameters()).device)
    state = model.state_dict()
    last = f"{stem}{have - 1}."
    block = {name[len(last):]: value for name, value in state.items() if name.startswith(last)}
    for i in range(have, layers):
        for name, value in block.items():
            new = value.clone()
            if name.startswith(outputs):
                new.zero_()
            elif name.startswith(norms):
                new.fill_(1.0 if name.endswith("weight") else 0.0)
            state[f"{stem}{i}.{name}"] = new
    return deep, state, block


def deepened(model: FacaidModel, decoder_layers: int) -> FacaidModel:
    """The same model with ``decoder_layers`` decoder blocks: the new ones are appended after the last, each a
    copy of it whose output projections are zero. The decoder's blocks are pre-layer-norm (GPT-2), so a block
    that writes nothing into the residual stream passes it on unchanged, and the logits are the same until
    training moves them; its attention and MLP inputs start as the last block's, not at random. The start of a
    fine-tune that gives a trained model more capacity."""
    deep, state, _ = _grown(model, "decoder_layers", decoder_layers, "decoder.h.", _BLOCK_OUTPUTS)
    deep.load_state_dict(state, strict=True)
    deep.train(model.training)
    return deep


# where each kind of encoder keeps its layers in the state dict
ENCODER_STEMS = {"bidirectional": "encoder.encoder.layer.", "causal": "encoder.h."}


# a BERT layer's projections into its residual sums and its two post-layer norms
_BERT_OUTPUTS = ("attention.output.dense.", "output.dense.")


_BERT_NORMS = ("attention.output.LayerNorm.", "output.LayerNorm.")


def encoder_deepened(model: FacaidModel, encoder_layers: int) -> FacaidModel:
    """The same model with ``encoder_layers`` encoder layers, the new ones appended after the last and computing
    nothing new until training moves them: the encoder's capacity grown at no cost to decoding (the encoder runs
    once per facade, the decoder once per token).

    Each new layer is a copy of the last whose output projections are zero. A causal (GPT-2) encoder is
    pre-layer-norm, so that is all (as in `deepened`). A bidirectional (BERT) encoder is post-layer-norm: a layer
    ends in ``LayerNorm(x + f(x))``, and with f zero it would normalize its input again. So the last trained layer's
    closing norm loses its gain and bias (it outputs the normalized vector), every new layer's norms are plain
    (normalizing a normalized vector changes it by the norm's epsilon only) and the last new layer's closing norm
    takes the gain and bias: the encoder's output is the same to float precision."""
    stem = ENCODER_STEMS[model.config.encoder]
    if model.config.encoder == "bidirectional":
        deep, state, block = _grown(model, "encoder_layers", encoder_layers, stem, _BERT_OUTPUTS, _BERT_NORMS)
        have = model.config.encoder_layers
        for part, plain in (("weight", 1.0), ("bias", 0.0)):
            closing = f"output.LayerNorm.{part}"
            state[f"{stem}{encoder_layers - 1}.{closing}"] = block[closing].clone()
            state[f"{stem}{have - 1}.{closing}"] = torch.full_like(block[closing], plain)
    else:
        deep, state, _ = _grown(model, "encoder_layers", encoder_layers, stem, _BLOCK_OUTPUTS)
    deep.load_state_dict(state, strict=True)
    deep.train(model.training)
    return deep


def initial_model(path: str, model_cfg: FacaidConfig, tok_cfg: TokenizerConfig, device) -> FacaidModel:
    """The weights of checkpoint ``path`` for a fine-tuning run; its architecture and tokenizer must be the
    config's, except that the config may add what starts out computing what the checkpoint computed: peer
    counts, finer coordinates (`adapt_to_tokenizer`), the box bias (`with_box_bias`), decoder blocks
    (`deepened`) and encoder layers (`encoder_deepened`)."""
    model, tokenizer = load_model(path, device)
    try:
        model, tokenizer = adapt_to_tokenizer(model, tokenizer, tok_cfg)
    except ValueError as e:
        raise ValueError(f"train.init {path} was trained with another tokenizer config: {e}") from e
    if model_cfg.box_bias and not model.config.box_bias:
        model = with_box_bias(model)
    if model_cfg.decoder_layers > model.config.decoder_layers:
        model = deepened(model, model_cfg.decoder_layers)
    if model_cfg.encoder_layers > model.config.encoder_layers:
        model = encoder_deepened(model, model_cfg.encoder_layers)
    differ = [k for k in ARCHITECTURE if getattr(model.config, k) != getattr(model_cfg, k)]
    if differ:
        raise ValueError(f"train.init {path} has another architecture ({', '.join(differ)} differ from [model])")
    return model
