"""The training loop: `facaid train --config FILE`, with validation, checkpoints and resume.

Batches are cut from pools sorted by length, which keeps padding low. A checkpoint (``OUT/last``: the model, its
tokenizer and ``state.pt``, the optimizer and the run's position) is written every ``save_every`` steps and at the
end; ``--resume`` continues from it exactly where it stopped.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import torch
from tqdm import tqdm

from facaid.model import FacaidConfig, FacaidModel, batch_inputs, batch_outputs, load_model, save_model
from facaid.tokenizer import Tokenizer
from facaid.training.config import load_config
from facaid.training.objective import lr_at, structure_weighted_loss, validation_loss
from facaid.training.samples import INPUTS, PooledBatches, SampleStream
from facaid.training.surgery import ENCODER_STEMS, initial_model


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
        model = initial_model(cfg.init, model_cfg, tok_cfg, device)
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
                          noise=(cfg.noise, cfg.noise_sigma), styles=cfg.styles,
                          **{name: getattr(cfg, name) for name in INPUTS})
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
