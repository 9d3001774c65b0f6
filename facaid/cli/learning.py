"""`facaid train`, `evaluate`, `compare` and `evaluate-real`: the model trained and measured."""

from __future__ import annotations

import argparse
from pathlib import Path

from facaid.cli.common import CliError, write_json
from facaid.defaults import DEFAULT_K, STRUCTURES
from facaid.paths import DEFAULT_CHECKPOINT, DEFAULT_CMP


def cmd_train(args: argparse.Namespace) -> None:
    from facaid.training import train

    last = train(args.config, out=args.out, resume=args.resume, steps=args.steps, until=args.until,
                 max_hours=args.max_hours, workers=args.workers, progress=not args.quiet)
    print(f"checkpoint: {last}")


def add_train(sub) -> None:
    t = sub.add_parser("train", help="train the transformer on freshly generated facades",
                       description="Train the encoder-decoder transformer per a TOML config ([model], [tokenizer], "
                                   "[train]); checkpoints to OUT/last, resumable.")
    t.add_argument("--config", required=True, help="TOML config, e.g. configs/small.toml")
    t.add_argument("--out", help="run directory (default: the config's train.out)")
    t.add_argument("--resume", action="store_true", help="continue from OUT/last")
    t.add_argument("--steps", type=int, help="override train.steps (the schedule's length)")
    t.add_argument("--until", type=int, help="stop after this step (resume later with --resume)")
    t.add_argument("--max-hours", type=float, help="override train.max_hours: stop and save after this much "
                                                     "wall time (resume later with --resume)")
    t.add_argument("--workers", type=int, help="override train.workers: processes generating samples (0: in the "
                                               "training process; on a GPU machine, about its CPU cores)")
    t.add_argument("--quiet", action="store_true", help="no progress bar")
    t.set_defaults(func=cmd_train)


def cmd_evaluate(args: argparse.Namespace) -> None:
    import torch

    from facaid.evaluation.synthetic import evaluate_synthetic
    from facaid.evaluation.synthetic_report import write_report
    from facaid.model import load_model

    if args.ceiling and args.best_of < 2:
        raise CliError("--ceiling measures the candidates of best of K: give --best-of K (K >= 2) too")
    if args.threads:
        torch.set_num_threads(args.threads)
    model, tokenizer = load_model(args.checkpoint)
    result = evaluate_synthetic(model, tokenizer, args.count, args.seed, noise_count=args.noise_count,
                                unconstrained_count=args.unconstrained_count, best_of=args.best_of,
                                ceiling=args.ceiling, progress=not args.quiet, records=args.records)
    result["checkpoint"] = str(args.checkpoint)
    report = write_report(result, args.report)
    print(report.read_text().split("## Noise")[0].strip())
    print(f"report: {report}")
    write_json(args.json, result)


def add_evaluate(sub) -> None:
    e = sub.add_parser("evaluate", help="evaluate a checkpoint on held-out generated facades",
                       description="NLL with and without nullification, validity, exact structure rate, tree edit "
                                   "distance, production frequencies, noise robustness, latency; writes a "
                                   "Markdown report with PNG plots.")
    e.add_argument("--checkpoint", default=str(DEFAULT_CHECKPOINT), help="checkpoint directory (default: shipped)")
    e.add_argument("--count", type=int, default=1000, help="facades (default 1000)")
    e.add_argument("--seed", type=int, default=1000, help="held-out dataset seed (default 1000)")
    e.add_argument("--noise-count", type=int, default=100, help="facades in the noise curve (default 100)")
    e.add_argument("--unconstrained-count", type=int, default=200,
                   help="facades decoded without the grammar mask (default 200)")
    e.add_argument("--best-of", type=int, default=0, metavar="K",
                   help=f"also decode best of K (greedy + K-1 samples ranked by reproduction), as reconstruct does "
                        f"(which decodes {DEFAULT_K})")
    e.add_argument("--ceiling", action="store_true",
                   help="with --best-of: also the figures of the truth's pick among the trees best of K chose from "
                        "(how far a better ranking of the same candidates could go)")
    e.add_argument("--report", default="out/evaluate", help="report directory (default out/evaluate)")
    e.add_argument("--json", help="write the figures to this JSON file")
    e.add_argument("--records", metavar="FILE",
                   help="append each facade's figures to FILE (JSON lines) as they are measured, and resume from "
                        "it: a stopped run started again with the same arguments goes on where it stopped")
    e.add_argument("--threads", type=int, default=0, help="torch threads (default: all cores)")
    e.add_argument("--quiet", action="store_true", help="no progress bar")
    e.set_defaults(func=cmd_evaluate)


def cmd_compare(args: argparse.Namespace) -> None:
    from facaid.evaluation.compare import compare_records, format_comparison

    result = compare_records(args.a, args.b)
    print(format_comparison(result))
    write_json(args.json, result)


def add_compare(sub) -> None:
    p = sub.add_parser("compare", help="compare two evaluation runs facade by facade",
                       description="Paired comparison of two `evaluate --records` files of the same held-out "
                                   "facades (same --seed): per figure, how many facades B decodes better and "
                                   "worse than A, and the mean change of the tree edit distance (B - A) with a "
                                   "bootstrap 95 % interval.")
    p.add_argument("a", help="records file of run A (the reference)")
    p.add_argument("b", help="records file of run B")
    p.add_argument("--json", help="write the figures to this JSON file")
    p.set_defaults(func=cmd_compare)


def cmd_evaluate_real(args: argparse.Namespace) -> None:
    from facaid.evaluation.real import evaluate_real, format_summary
    from facaid.model import load_model

    if not Path(args.data).is_file():
        raise CliError(f"annotations not found at {args.data} (pass --data PATH)")
    gallery = args.gallery or None  # --gallery "": none
    if gallery and Path(gallery).suffix.lower() != ".png":  # refused now, not after the whole run
        raise CliError(f"--gallery must name a .png file (or be empty for none), got {gallery!r}")
    model, tokenizer = load_model(args.checkpoint)
    result = evaluate_real(model, tokenizer, args.data, k=args.k, limit=args.limit, gallery=gallery,
                           progress=not args.quiet, induce=not args.no_induce, perturb=args.perturb,
                           structure=args.structure, start=args.start)
    result["checkpoint"] = str(args.checkpoint)
    print(format_summary(result))
    if gallery:
        print(f"gallery (input | reconstruction): {gallery}")
    write_json(args.json, result)


def add_evaluate_real(sub) -> None:
    r2 = sub.add_parser("evaluate-real", help="reconstruct the CMP facades and compare (evaluation only)",
                        description="Reconstruct every facade of an annotations.jsonl (CMP format) and report mean "
                                    "pixel accuracy, per-class IoU and time per facade beside the all-wall "
                                    "baseline, with a gallery PNG (input | reconstruction).")
    r2.add_argument("--data", default=str(DEFAULT_CMP), help="annotations.jsonl (default: the shared CMP file)")
    r2.add_argument("--checkpoint", default=str(DEFAULT_CHECKPOINT), help="checkpoint directory")
    r2.add_argument("--k", type=int, default=DEFAULT_K, help=f"candidates per facade (default {DEFAULT_K})")
    r2.add_argument("--limit", type=int, help="only the first N facades")
    r2.add_argument("--start", type=int, default=0, help="skip the first N facades (--start 189: the test half)")
    r2.add_argument("--structure", choices=STRUCTURES, default="editable",
                    help="which procedure to score (default editable); the other's accuracy is reported beside")
    r2.add_argument("--no-induce", action="store_true", help="only the model's structures (the model alone)")
    r2.add_argument("--perturb", type=int, metavar="SEED",
                    help="annotate each input as people do first (edges moved up to 1 %% of the side, 10 %% of the "
                         "elements left out, 2 spurious boxes), seeded; compare with the clean annotation")
    r2.add_argument("--gallery", default="out/evaluate-real/gallery.png",
                    help='gallery PNG of the first 20 ("" for none)')
    r2.add_argument("--json", help="write the figures to this JSON file")
    r2.add_argument("--quiet", action="store_true", help="no progress bar")
    r2.set_defaults(func=cmd_evaluate_real)
