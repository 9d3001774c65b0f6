"""What a session lent a GPU machine runs, as it is: `scripts/gpu-run OUT [--limit SECONDS]`.

1. Installs what the machine lacks (transformers, orjson, safetensors, tqdm at the versions pyproject.toml asks
   for) from the wheels it carries (`--wheels`, default var/gpu-wheels, made here by `scripts/gpu-wheels`): nothing
   is downloaded there; then starts again, so that nothing imported before the install lingers.
2. Checks CUDA and prints the device.
3. Reconstructs generated facades with `facaid.reconstruct` on CUDA and on the CPU, and runs one worker job
   (`worker.compute.reconstruct`, the Celery task's work) on CUDA: each must give the CPU's procedure (the same tree,
   sizes within `SIZE_TOLERANCE` px) and pixel accuracy (within `ACCURACY_TOLERANCE`).
4. Times greedy and best-of-16 decoding on CUDA beside the CPU (medians over held-out generated facades).
5. Spends the time left on the prepared training run (`--config`, default configs/gpu.toml), resumable: its
   checkpoint and log go to OUT/run every `save_every` steps (a few minutes), and a later call goes on from them
   (in the same OUT, or from a copy brought back, `--resume-from`).

Everything it measures goes to OUT/report.json, and the whole run keeps under `--limit` seconds. `--dry-run` does
all of it on the CPU with tiny figures and a few training steps of configs/small.toml: the test suite runs it.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # the working tree as it is: the machine has the project's files, not it installed

REQUIRED = ("transformers", "orjson", "safetensors", "tqdm")  # at pyproject's versions (scripts/gpu-wheels)
SIZE_TOLERANCE = 0.5  # pixels: a size of the CUDA tree may differ from the CPU's by this much (float sums)
ACCURACY_TOLERANCE = 0.002
TRAIN_MARGIN = 45  # seconds kept back from training to save, evaluate nothing more and write the report


def _pins() -> dict[str, str]:
    """pyproject.toml's requirement of each of `REQUIRED` ("transformers>=5.24,<6"), or the bare name."""
    import re
    import tomllib

    deps = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["dependencies"]
    named = {re.split(r"[\[<>=!~ ]", d, maxsplit=1)[0]: d.split(";")[0].strip() for d in deps}
    return {name: named.get(name, name) for name in REQUIRED}


def missing() -> list[str]:
    """The requirements of `REQUIRED` this Python does not meet, read from the installed metadata with nothing
    imported (an old version's modules must not linger into the new one's)."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        from packaging.requirements import Requirement
    except ImportError:  # pip's own copy, where the machine has no packaging of its own
        from pip._vendor.packaging.requirements import Requirement

    out = []
    for pin in _pins().values():
        requirement = Requirement(pin)
        try:
            have = version(requirement.name)
        except PackageNotFoundError:
            out.append(pin)
            continue
        if not requirement.specifier.contains(have, prereleases=True):
            out.append(pin)
    return out


def install(wheels: Path, log) -> list[str]:
    """Install what is missing from the wheels carried here; what is still missing after."""
    needed = missing()
    if not needed:
        return []
    if not wheels.is_dir():
        log(f"missing {', '.join(needed)} and no wheels at {wheels} (scripts/gpu-wheels makes them)")
        return needed
    log(f"installing {', '.join(needed)} from {wheels}")
    subprocess.run([sys.executable, "-m", "pip", "install", "--no-index", "--find-links", str(wheels), "--quiet",
                    *needed], check=False)
    return missing()


def _same_tree(a: dict, b: dict) -> tuple[bool, float]:
    """Whether two procedure JSONs are one tree, and the largest difference of their numbers (sizes, in pixels)."""
    worst = 0.0

    def walk(x, y) -> bool:
        nonlocal worst
        if isinstance(x, dict) and isinstance(y, dict):
            return x.keys() == y.keys() and all(walk(x[k], y[k]) for k in x)
        if isinstance(x, list) and isinstance(y, list):
            return len(x) == len(y) and all(walk(p, q) for p, q in zip(x, y, strict=True))
        if isinstance(x, float | int) and isinstance(y, float | int) and not isinstance(x, bool):
            worst = max(worst, abs(x - y))
            return True
        return x == y

    a, b = dict(a), dict(b)
    a.pop("meta", None), b.pop("meta", None)
    return walk(a, b), worst


def check_reconstruction(device: str, count: int, k: int, log) -> dict:
    """`facaid.reconstruct` and one worker job on ``device`` against the CPU, on generated facades."""
    import torch

    from facaid.generator import generate
    from facaid.generator.dataset import sample_seed
    from facaid.model import load_model
    from facaid.paths import DEFAULT_CHECKPOINT
    from facaid.pipeline import ReconstructOptions, reconstruct
    from worker.compute import reconstruct as job

    cpu = load_model(DEFAULT_CHECKPOINT, "cpu")
    here = load_model(DEFAULT_CHECKPOINT, device)
    rows = []
    for i in range(count):
        seg = generate(sample_seed(4242, i)).segmentation
        torch.manual_seed(0)
        a = reconstruct(seg, ReconstructOptions(k=k, seed=i), model=cpu[0], tokenizer=cpu[1])
        torch.manual_seed(0)
        b = reconstruct(seg, ReconstructOptions(k=k, seed=i), model=here[0], tokenizer=here[1])
        same, worst = _same_tree(a.procedure.to_dict(), b.procedure.to_dict())
        rows.append({"facade": i, "same_tree": same, "largest_size_difference": round(worst, 4),
                     "accuracy_cpu": a.accuracy, "accuracy_device": b.accuracy,
                     "ok": same and worst <= SIZE_TOLERANCE and abs(a.accuracy - b.accuracy) <= ACCURACY_TOLERANCE})
        log(f"reconstruct facade {i}: {'the same' if rows[-1]['ok'] else 'DIFFERENT'} (tree {same}, sizes within "
            f"{worst:.3f} px, accuracy {a.accuracy:.4f} on the CPU, {b.accuracy:.4f} on {device})")
    seg = generate(sample_seed(4242, 0)).segmentation
    done = job(seg.to_dict(), str(DEFAULT_CHECKPOINT), k=k, seed=0)
    job_ok = abs(done["accuracy"] - rows[0]["accuracy_device"]) <= ACCURACY_TOLERANCE
    log(f"worker job on {device}: accuracy {done['accuracy']:.4f} ({'as' if job_ok else 'NOT as'} reconstruct)")
    return {"facades": rows, "worker_job": {"accuracy": done["accuracy"], "ok": job_ok},
            "ok": all(r["ok"] for r in rows) and job_ok}


def time_decoding(device: str, count: int, log) -> dict:
    """Median seconds of greedy and best-of-16 decoding on ``device`` and on the CPU (the torch step on CUDA; the
    C step on the CPU, as the site decodes there)."""
    from facaid.decoding import decode
    from facaid.defaults import TEMPERATURE
    from facaid.generator import generate
    from facaid.generator.dataset import sample_seed
    from facaid.model import load_model
    from facaid.paths import DEFAULT_CHECKPOINT

    out = {}
    for where in dict.fromkeys(("cpu", device)):
        model, tok = load_model(DEFAULT_CHECKPOINT, where)
        for name, rows in (("greedy", {}), ("best_of_16", {"k": 16, "sample": True, "greedy": 1,
                                                            "temperature": TEMPERATURE})):
            seg = generate(sample_seed(999, 0)).segmentation
            decode(model, tok, seg, native=where == "cpu", **rows)  # warm-up
            seconds = []
            for i in range(count):
                s = generate(sample_seed(1000, i)).segmentation
                t0 = time.perf_counter()
                decode(model, tok, s, native=where == "cpu", seed=i, **rows)
                if where != "cpu":
                    import torch

                    torch.cuda.synchronize()
                seconds.append(time.perf_counter() - t0)
            out[f"{name}_{where}_ms"] = round(1000 * statistics.median(seconds), 1)
            log(f"{name} on {where}: {out[f'{name}_{where}_ms']:.0f} ms median over {count} facades")
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="scripts/gpu-run", description=__doc__.split("\n\n")[0])
    ap.add_argument("out", help="the output folder: report.json, the log, the training run")
    ap.add_argument("--limit", type=float, default=540, help="seconds the whole run may take (default 540)")
    ap.add_argument("--wheels", default=str(ROOT / "var" / "gpu-wheels"), help="wheels to install what is missing")
    ap.add_argument("--config", default=str(ROOT / "configs" / "gpu.toml"), help="the training config")
    ap.add_argument("--resume-from", help="a run folder an earlier call wrote (OUT/run, carried back): training "
                                          "goes on from its checkpoint")
    ap.add_argument("--dry-run", action="store_true", help="on the CPU, tiny: what the test suite runs")
    args = ap.parse_args(argv)
    start = time.monotonic()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    log_file = open(out / "gpu-run.log", "a", encoding="utf-8")  # noqa: SIM115 (written to the end)

    def log(line: str) -> None:
        stamped = f"[{time.monotonic() - start:6.1f} s] {line}"
        print(stamped, flush=True)
        log_file.write(stamped + "\n")
        log_file.flush()

    report: dict = {"limit_s": args.limit, "dry_run": args.dry_run}
    before = missing()
    left_over = install(Path(args.wheels), log)
    if before and not left_over and not os.environ.get("FACAID_GPU_RUN_REEXEC"):
        # installed now: started again, so that nothing imported before the install lingers
        log_file.close()
        os.execve(sys.executable, [sys.executable, __file__, *(argv if argv is not None else sys.argv[1:])],
                  {**os.environ, "FACAID_GPU_RUN_REEXEC": "1"})
    if left_over:
        report["error"] = f"missing {', '.join(left_over)}"
        (out / "report.json").write_text(json.dumps(report, indent=1))
        log(f"error: {report['error']}")
        return 2
    import torch

    if args.dry_run:
        device = "cpu"
        report["device"] = "cpu (dry run)"
    elif not torch.cuda.is_available():
        log("error: CUDA is not available here (use --dry-run to try the script on the CPU)")
        return 2
    else:
        device = "cuda"
        props = torch.cuda.get_device_properties(0)
        report["device"] = f"{props.name}, {props.total_memory / 2**30:.0f} GiB, torch {torch.__version__}"
    log(f"device: {report['device']}")
    report["reconstruction"] = check_reconstruction(device, 1 if args.dry_run else 4, 2 if args.dry_run else 16, log)
    report["decoding"] = time_decoding(device, 2 if args.dry_run else 10, log)
    (out / "report.json").write_text(json.dumps(report, indent=1))

    from facaid.training import train

    left = args.limit - (time.monotonic() - start) - TRAIN_MARGIN
    run = out / "run"
    if args.resume_from and not (run / "last" / "state.pt").is_file():
        shutil.copytree(args.resume_from, run, dirs_exist_ok=True)
        log(f"resuming the run of {args.resume_from}")
    if left > 0:
        config = ROOT / "configs" / "small.toml" if args.dry_run else Path(args.config)
        resume = (run / "last" / "state.pt").is_file()
        log(f"training {config.name} for {left:.0f} s into {run}{' (resumed)' if resume else ''}")
        extra = {"steps": 2, "workers": 0} if args.dry_run else {}
        last = train(config, out=str(run), resume=resume, max_hours=left / 3600, progress=False, **extra)
        saved = torch.load(last / "state.pt", map_location="cpu", weights_only=False)
        step = saved["state"]["step"]
        report["training"] = {"config": config.name, "checkpoint": str(last), "step": step, "seconds": round(left),
                              "log": str(run / "log.jsonl")}
        log(f"training stopped at step {step}; checkpoint {last}")
    else:
        report["training"] = {"skipped": f"no time left under the {args.limit:g} s limit"}
        log(report["training"]["skipped"])
    report["seconds"] = round(time.monotonic() - start, 1)
    report["ok"] = report["reconstruction"]["ok"]
    (out / "report.json").write_text(json.dumps(report, indent=1))
    log(f"done in {report['seconds']} s: report {out / 'report.json'}")
    return 0 if report["ok"] else 1


if __name__ == "__main__":
    os.environ.setdefault("TOKENIZERS_PARALLELISM", "false")
    sys.exit(main())
