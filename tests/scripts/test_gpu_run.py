"""`scripts/gpu-run --dry-run`: the GPU machine's one command, all of it on the CPU with tiny figures: the
reconstruction and a worker job against the CPU's, decoding timed, a few training steps that a second call
resumes, the report, all within its time limit."""

import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def run(out: Path, *extra: str) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHON": sys.executable}
    return subprocess.run(["bash", str(ROOT / "scripts" / "gpu-run"), str(out), "--dry-run", *extra],
                          capture_output=True, text=True, timeout=600, env=env)


def test_the_dry_run_checks_times_trains_and_resumes(tmp_path):
    done = run(tmp_path, "--limit", "300")
    assert done.returncode == 0, done.stdout + done.stderr
    report = json.loads((tmp_path / "report.json").read_text())
    assert report["ok"] and report["device"] == "cpu (dry run)"
    facade, = report["reconstruction"]["facades"]
    assert facade["same_tree"] and facade["largest_size_difference"] <= 0.5
    assert report["reconstruction"]["worker_job"]["ok"]
    assert {"greedy_cpu_ms", "best_of_16_cpu_ms"} <= set(report["decoding"])
    assert report["training"]["step"] == 2 and (tmp_path / "run" / "last" / "model.safetensors").is_file()
    assert report["seconds"] < 300 and "device: cpu (dry run)" in (tmp_path / "gpu-run.log").read_text()
    again = run(tmp_path, "--limit", "300")  # a second call goes on from the checkpoint
    assert again.returncode == 0 and "(resumed)" in again.stdout


def test_a_limit_too_short_for_training_skips_it_and_says_so(tmp_path):
    done = run(tmp_path, "--limit", "1")
    assert done.returncode == 0, done.stderr
    report = json.loads((tmp_path / "report.json").read_text())
    assert "no time left under the 1 s limit" in report["training"]["skipped"]


def test_without_cuda_and_without_dry_run_it_says_so(tmp_path):
    import torch

    if torch.cuda.is_available():
        return
    done = subprocess.run(["bash", str(ROOT / "scripts" / "gpu-run"), str(tmp_path)], capture_output=True, text=True,
                          timeout=120, env={**os.environ, "PYTHON": sys.executable})
    assert done.returncode == 2 and "CUDA is not available here" in done.stdout
