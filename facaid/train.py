"""Training: `facaid train --config FILE` on freshly generated facades, with validation, checkpoints, resume.

The config is TOML with three tables, ``[model]`` (FacaidConfig fields), ``[tokenizer]`` (TokenizerConfig
fields) and ``[train]`` (TrainConfig fields). Every sample is generated on the fly from its own seed, so a run
never sees the same facade twice and the validation facades (another dataset seed) are held out. Batches are
cut from pools sorted by length, which keeps padding low. A checkpoint (``OUT/last``) is written every
``save_every`` steps and at the end; ``--resume`` continues from it exactly where it stopped.
"""

from __future__ import annotations

import json
import math
import multiprocessing
import random
import time
import tomllib
from dataclasses import dataclass, field, fields
from pathlib import Path

import numpy as np
import torch
import torch.nn.functional as F
from tqdm import tqdm

from facaid.augmentation import jitter
from facaid.generator import TRAINING_STYLES, generate
from facaid.generator.dataset import sample_seed
from facaid.grammar.procedure import MODES
from facaid.model import (
    ENCODER_STEMS,
    FacaidConfig,
    FacaidModel,
    adapt_to_tokenizer,
    batch_inputs,
    batch_outputs,
    deepened,
    encoder_deepened,
    load_model,
    save_model,
    with_box_bias,
)
from facaid.tokenizer import Tokenizer, TokenizerConfig, Vocabulary


def _nonnegative(value) -> bool:
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
    init: str = ""  # a checkpoint directory whose weights start the run (fine-tuning); fresh optimizer and schedule
    count_lr_scale: float = 1.0  # the peer counts' embeddings learn at this multiple of the learning rate (a
    # model widened for them starts them at zero while the rest is trained already)
    box_lr_scale: float = 1.0  # the same for the box bias's per-head scales (`FacaidConfig.box_bias`)
    grown_lr_scale: float = 1.0  # the same for the decoder blocks and encoder layers appended to the ``init``
    # checkpoint's (`facaid.model.deepened`, `encoder_deepened`), with weight decay as the rest
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
        if not all(_nonnegative(w) for w in weights):
            raise ValueError(f"style_weights must be finite numbers >= 0, got {self.style_weights}")
        if self.style_weights and sum(self.styles) <= 0:
            raise ValueError("style_weights: at least one style must weigh more than 0")
        for name in ("count_lr_scale", "box_lr_scale", "grown_lr_scale"):
            value = getattr(self, name)
            if not _nonnegative(value):
                raise ValueError(f"{name} must be a finite number >= 0 (0 freezes those parameters), got {value!r}")
        if not _nonnegative(self.structure_weight) or self.structure_weight == 0:
            raise ValueError(f"structure_weight must be a finite number > 0 (1: the plain NLL), got "
                             f"{self.structure_weight!r}")

    @property
    def styles(self) -> tuple[float, ...] | None:
        """The weight of each of `TRAINING_STYLES` in order, or None for the generator's own choice. "wing" weighs 0
        unless named: drawn last with no weight, it leaves every other draw as it was."""
        if not self.style_weights:
            return None
        return tuple(float(self.style_weights.get(name, 0.0 if name == "wing" else 1.0)) for name in TRAINING_STYLES)


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


_worker: dict = {}


def _init_worker(tok_config: dict, noise: tuple[float, float], styles: tuple[float, ...] | None) -> None:
    torch.set_num_threads(1)
    _worker.update(tokenizer=Tokenizer(TokenizerConfig(**tok_config)), noise=noise, styles=styles)


def sample_style(seed: int, index: int, styles: tuple[float, ...] | None) -> str | None:
    """The style of sample ``index`` of dataset ``seed`` drawn with weights ``styles`` (one per `TRAINING_STYLES`),
    seeded by the sample; None (the generator's own choice) without weights."""
    if styles is None:
        return None
    return random.Random(f"facaid-style:{seed}:{index}").choices(TRAINING_STYLES, weights=styles)[0]


def make_example(tokenizer: Tokenizer, seed: int, index: int, noise: tuple[float, float] = (0.0, 0.0),
                 styles: tuple[float, ...] | None = None):
    """The training example of sample ``index`` of dataset ``seed``: (rows, (ids, local, boxes)), or None when
    the facade is too long for the model. ``noise`` = (share, sigma): that share of the inputs get their edges
    jittered (`facaid.augmentation.jitter`, sigma uniform in [0, sigma]), seeded by the sample. ``styles``:
    weights of the generator styles (`sample_style`)."""
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
    try:
        rows = tokenizer.encode_segmentation(seg)
    except ValueError:  # too many rectangles
        return None
    return rows, target


def _worker_example(args: tuple[int, int]):
    return make_example(_worker["tokenizer"], *args, noise=_worker["noise"], styles=_worker["styles"])


class SampleStream:
    """Endless (rects, (ids, local, boxes)) examples from generated facades, skipping those too long for the model.

    With ``workers`` > 0, ``take`` generates in that many processes; the examples are the same, in the same
    order, as in one process."""

    def __init__(self, tokenizer: Tokenizer, seed: int, start: int = 0, workers: int = 0,
                 noise: tuple[float, float] = (0.0, 0.0), styles: tuple[float, ...] | None = None):
        self.tokenizer = tokenizer
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
                                 initargs=(tokenizer.config.to_dict(), noise, styles))

    def example(self, index: int):
        return make_example(self.tokenizer, self.seed, index, self.noise, self.styles)

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


_ARCHITECTURE = ("d_model", "encoder_layers", "decoder_layers", "heads", "ffn", "dropout", "encoder", "node_boxes",
                 "box_bias")


def _initial_model(path: str, model_cfg: FacaidConfig, tok_cfg: TokenizerConfig, device) -> FacaidModel:
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
    differ = [k for k in _ARCHITECTURE if getattr(model.config, k) != getattr(model_cfg, k)]
    if differ:
        raise ValueError(f"train.init {path} has another architecture ({', '.join(differ)} differ from [model])")
    return model


def train(config_path: str | Path, out: str | None = None, resume: bool = False, steps: int | None = None,
          until: int | None = None, max_hours: float | None = None, workers: int | None = None,
          progress: bool = True) -> Path:
    """Train per the config; returns the checkpoint directory (OUT/last).

    ``steps`` overrides the schedule's length; ``until`` stops (and saves) after that step without changing
    the schedule, so that a long run can be done in parts with ``resume``."""
    model_cfg, tok_cfg, cfg = load_config(config_path)
    if out is not None:
        cfg.out = out
    if steps is not None:
        cfg.steps = steps
    if max_hours is not None:
        cfg.max_hours = max_hours
    if workers is not None:
        if workers < 0:
            raise ValueError(f"workers must be >= 0 (0: samples made in the training process), got {workers}")
        cfg.workers = workers
    out_dir = Path(cfg.out)
    last = out_dir / "last"
    device = torch.device("cuda" if torch.cuda.is_available() else "cpu")
    if device.type == "cpu" and cfg.threads:
        torch.set_num_threads(cfg.threads)
    torch.manual_seed(cfg.seed)
    tokenizer = Tokenizer(tok_cfg)
    # grown_from / encoder_grown_from: the decoder blocks / encoder layers of the init checkpoint, when the config
    # appends more (they learn at grown_lr_scale); kept in the state so that a resumed run has the same groups
    state = {"step": 0, "sample_index": 0, "skipped": 0, "elapsed": 0.0, "batches": None, "grown_from": None,
             "encoder_grown_from": None}
    if resume and (last / "state.pt").is_file():
        model, tokenizer = load_model(last, device)
        if tokenizer.config != tok_cfg:
            raise ValueError(f"{last} was trained with another tokenizer config than {config_path}")
        saved = torch.load(last / "state.pt", map_location=device, weights_only=False)
        state.update(saved["state"])
    elif cfg.init:
        model = _initial_model(cfg.init, model_cfg, tok_cfg, device)
        init_cfg = FacaidConfig.from_pretrained(cfg.init)
        have = init_cfg.decoder_layers
        state["grown_from"] = have if have < model.config.decoder_layers else None
        have = init_cfg.encoder_layers
        state["encoder_grown_from"] = have if have < model.config.encoder_layers else None
        saved = None
    else:
        model = FacaidModel(model_cfg).to(device)
        saved = None
    model.train()
    # parameters added to a trained model (at zero) learn at their own multiple of the rate, without decay
    added = (("count_fields.", cfg.count_lr_scale), ("box_scale", cfg.box_lr_scale))
    # decoder blocks and encoder layers appended to a trained model learn at their own multiple of the rate, with
    # decay
    grown = tuple(f"decoder.h.{i}." for i in range(state["grown_from"] or model.config.decoder_layers,
                                                    model.config.decoder_layers))
    encoder = ENCODER_STEMS[model.config.encoder]
    grown += tuple(f"{encoder}{i}." for i in range(state["encoder_grown_from"] or model.config.encoder_layers,
                                                   model.config.encoder_layers))

    def decayed(params: list, scale: float) -> list[dict]:  # weight decay on matrices only
        return [{"params": [p for p in params if p.dim() >= 2], "weight_decay": cfg.weight_decay, "scale": scale},
                {"params": [p for p in params if p.dim() < 2], "weight_decay": 0.0, "scale": scale}]

    skip = tuple(a for a, _ in added) + grown
    groups = decayed([p for n, p in model.named_parameters() if not n.startswith(skip)], 1.0)
    if grown:
        groups += decayed([p for n, p in model.named_parameters() if n.startswith(grown)], cfg.grown_lr_scale)
    for prefix, scale in added:
        params = [p for n, p in model.named_parameters() if n.startswith(prefix)]
        if params:
            groups.append({"params": params, "weight_decay": 0.0, "scale": scale})
    for group in groups:  # same groups either way, so a resumed run's optimizer state fits
        if group["scale"] == 0:
            for p in group["params"]:
                p.requires_grad_(False)
    opt = torch.optim.AdamW(groups, lr=cfg.lr, betas=(0.9, 0.98))
    if saved is not None:
        opt.load_state_dict(saved["optimizer"])
    out_dir.mkdir(parents=True, exist_ok=True)
    (out_dir / "config.toml").write_text(Path(config_path).read_text())
    log_path = out_dir / "log.jsonl"

    # clean inputs, in this process (a second or two): the loss stays comparable across runs
    val = SampleStream(tokenizer, cfg.val_seed).take(cfg.val_count)
    stream = SampleStream(tokenizer, cfg.seed, start=state["sample_index"], workers=cfg.workers,
                          noise=(cfg.noise, cfg.noise_sigma), styles=cfg.styles)
    stream.skipped = state["skipped"]
    batches = PooledBatches(stream, cfg.batch_size, cfg.pool_batches, cfg.seed, state["batches"])
    stop = min(cfg.steps, until) if until is not None else cfg.steps
    use_amp = device.type == "cuda"
    started = time.perf_counter()
    elapsed0 = state["elapsed"]
    step = state["step"]
    bar = tqdm(total=cfg.steps, initial=step, disable=not progress, desc="train", unit="step")
    loss_avg = None

    def checkpoint() -> None:
        state.update(step=step, sample_index=stream.index, skipped=stream.skipped, batches=batches.position(),
                     elapsed=elapsed0 + time.perf_counter() - started)
        tmp = out_dir / "last.tmp"
        save_model(model, tokenizer, tmp)
        torch.save({"state": state, "optimizer": opt.state_dict()}, tmp / "state.pt")
        if last.exists():
            for f in last.iterdir():
                f.unlink()
            last.rmdir()
        tmp.rename(last)

    try:
        while step < stop:
            if time.perf_counter() - started > cfg.max_hours * 3600:
                break
            batch = next(batches)
            rects, mask = batch_inputs([ex[0] for ex in batch], device)
            ids, local, targets, boxes = batch_outputs([ex[1] for ex in batch], device)
            for group in opt.param_groups:
                group["lr"] = lr_at(step, cfg) * group["scale"]
            with torch.autocast(device.type, dtype=torch.bfloat16, enabled=use_amp):
                if cfg.structure_weight == 1.0:
                    _, loss = model(rects, mask, ids, local, targets, boxes)
                else:
                    logits, _ = model(rects, mask, ids, local, boxes=boxes)
                    loss = structure_weighted_loss(logits, targets, tokenizer.vocab, cfg.structure_weight)
            opt.zero_grad(set_to_none=True)
            loss.backward()
            torch.nn.utils.clip_grad_norm_(model.parameters(), cfg.grad_clip)
            opt.step()
            step += 1
            loss_value = loss.item()
            loss_avg = loss_value if loss_avg is None else 0.98 * loss_avg + 0.02 * loss_value
            bar.update(1)
            bar.set_postfix(loss=f"{loss_avg:.3f}", lr=f"{lr_at(step, cfg):.1e}")
            if step % cfg.eval_every == 0 or step == cfg.steps:
                val_loss, val_structure = validation_loss(model, val, cfg.batch_size, device, tokenizer.vocab)
                record = {"step": step, "train_loss": loss_avg, "val_loss": val_loss, "val_structure": val_structure,
                          "samples": stream.index,
                          "skipped": stream.skipped, "hours": (elapsed0 + time.perf_counter() - started) / 3600}
                with open(log_path, "a") as f:
                    f.write(json.dumps(record) + "\n")
                bar.write(json.dumps(record))
            if step % cfg.save_every == 0:
                checkpoint()
        bar.close()
        checkpoint()
    finally:
        stream.close()
    return last
