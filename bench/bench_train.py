"""Where a training step's time goes: sample generation (in-process and with N worker processes), batching, and
the model's forward/backward/optimizer step (CUDA when present, bf16 autocast there as in training).

    .venv/bin/python bench/bench_train.py [--config configs/gpu.toml] [--workers 14] [--steps 20]

Prints medians per step of the config's batch size; the data rate needed per step is compared with the model's
step time, which says what bounds the run. With the box bias (``model.box_bias``) each batch is also stepped with
the box scales frozen (``train.box_lr_scale = 0``, the cross-attention in the fused kernel), alternating with the
learned ones on the same batches so that the ratio is measured under the same load.
"""

from __future__ import annotations

import argparse
import statistics
import time

import torch

from facaid.model import FacaidModel, batch_inputs, batch_outputs
from facaid.tokenizer import Tokenizer
from facaid.training import load_config
from facaid.training.samples import SampleStream


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--config", default="configs/gpu.toml")
    ap.add_argument("--workers", type=int, default=None, help="sample processes (default: the config's)")
    ap.add_argument("--steps", type=int, default=20, help="timed model steps (after 3 warm-up steps)")
    args = ap.parse_args()
    model_cfg, tok_cfg, cfg = load_config(args.config)
    workers = cfg.workers if args.workers is None else args.workers
    tokenizer = Tokenizer(tok_cfg)
    bs = cfg.batch_size
    device = torch.device("cuda" if torch.cuda.is_available() else "cpu")
    print(f"device {device}, batch {bs}, {torch.get_num_threads()} torch threads")

    one = SampleStream(tokenizer, seed=7)
    t0 = time.perf_counter()
    one.take(bs)
    in_process = (time.perf_counter() - t0) / bs
    print(f"generate + tokenize, one process: {1000 * in_process:.2f} ms/sample = "
          f"{1000 * in_process * bs:.0f} ms/batch")
    n = bs * (args.steps + 3)
    if workers:
        many = SampleStream(tokenizer, seed=1, workers=workers)
        try:
            many.take(workers)  # processes started and imported
            t0 = time.perf_counter()
            examples = many.take(n)
            per = (time.perf_counter() - t0) / n
        finally:
            many.close()
        print(f"generate + tokenize, {workers} processes: {1000 * per:.2f} ms/sample = {1000 * per * bs:.1f} ms/batch "
              f"({in_process / per:.1f}x one process)")
    else:
        examples = one.take(n)
    examples.sort(key=lambda ex: len(ex[1][0]))  # as training's length-sorted pools
    batches = [examples[i : i + bs] for i in range(0, n, bs)]

    torch.manual_seed(0)
    model = FacaidModel(model_cfg).to(device).train()
    opt = torch.optim.AdamW(model.parameters(), lr=1e-4)
    sync = torch.cuda.synchronize if device.type == "cuda" else (lambda: None)
    modes = ("learned", "frozen") if model.box_scale is not None else ("learned",)
    batching: list[float] = []
    stepping: dict[str, list[float]] = {mode: [] for mode in modes}
    for i, batch in enumerate(batches):
        t0 = time.perf_counter()
        rects, mask = batch_inputs([ex[0] for ex in batch], device)
        ids, local, targets, boxes = batch_outputs([ex[1] for ex in batch], device)
        sync()
        t1 = time.perf_counter()
        if i >= 3:
            batching.append(t1 - t0)
        for mode in modes:
            if model.box_scale is not None:
                model.box_scale.requires_grad_(mode == "learned")
            t2 = time.perf_counter()
            with torch.autocast(device.type, dtype=torch.bfloat16, enabled=device.type == "cuda"):
                _, loss = model(rects, mask, ids, local, targets, boxes)
            opt.zero_grad(set_to_none=True)
            loss.backward()
            torch.nn.utils.clip_grad_norm_(model.parameters(), 1.0)
            opt.step()
            loss.item()
            sync()
            if i >= 3:
                stepping[mode].append(time.perf_counter() - t2)
    print(f"batching (pad, to device): median {1000 * statistics.median(batching):.1f} ms/step")
    learned = statistics.median(stepping["learned"])
    print(f"forward + backward + AdamW: median {1000 * learned:.1f} ms/step over {len(stepping['learned'])} steps "
          f"(output length up to {ids.shape[1]}, {rects.shape[1]} rectangles)")
    if "frozen" in stepping:
        frozen = statistics.median(stepping["frozen"])
        total = sum(stepping["learned"]) / sum(stepping["frozen"])  # what a run of such batches gains
        print(f"the same, box scales frozen (train.box_lr_scale = 0): median {1000 * frozen:.1f} ms/step, "
              f"{learned / frozen:.2f}x the median, {total:.2f}x the total time of these steps")


if __name__ == "__main__":
    main()
