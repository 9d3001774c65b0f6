"""Sharded datasets of generated facades, written in parallel and read back lazily.

A dataset directory holds ``manifest.json`` and ``shard-NNNNN.jsonl.gz`` files; each line is one sample:
``{"id", "seed", "style", "segmentation", "procedure"}``. Sample ``i`` of a dataset made with seed ``S`` has
its own seed derived from ``(S, i)``, so a dataset is the same whatever the number of workers.
"""

from __future__ import annotations

import gzip
import hashlib
import json
import os
from collections.abc import Iterator
from multiprocessing import get_context
from pathlib import Path

import orjson
from tqdm import tqdm

from facaid.generator import STYLE_NAMES, generate_rows
from facaid.grammar.procedure import GRAMMAR_VERSION
from facaid.segmentation import rect_dicts, rects_json

MANIFEST = "manifest.json"


def sample_seed(seed: int, index: int) -> int:
    """The seed of sample ``index`` in a dataset made with ``seed`` (64 bits, stable across machines)."""
    digest = hashlib.blake2b(f"{seed}:{index}".encode(), digest_size=8).digest()
    return int.from_bytes(digest, "big")


def sample_record(seed: int, index: int, style: str | None = None) -> dict:
    """Sample ``index`` of the dataset as its JSON record (the segmentation as `Segmentation.to_dict` writes it)."""
    return _record(seed, index, style, lambda rows: rect_dicts(rows.tolist()))


def sample_line(seed: int, index: int, style: str | None = None) -> bytes:
    """`sample_record` as the JSON line a shard holds (without the newline), the rectangles written in one call
    (`rects_json`): what orjson writes for the record."""
    return orjson.dumps(_record(seed, index, style, lambda rows: orjson.Fragment(rects_json(rows))))


def _record(seed: int, index: int, style: str | None, rects) -> dict:
    proc, rows = generate_rows(sample_seed(seed, index), style)
    return {
        "id": f"s{seed}-{index:08d}",
        "seed": proc.meta["seed"],
        "style": proc.meta["style"],
        "segmentation": {"width": round(proc.width), "height": round(proc.height), "rects": rects(rows)},
        "procedure": proc.to_dict(),
    }


def _write_shard(job: tuple[str, int, int, int, int, str | None]) -> tuple[str, int]:
    out_dir, shard, start, stop, seed, style = job
    path = Path(out_dir) / f"shard-{shard:05d}.jsonl.gz"
    tmp = path.with_suffix(".tmp")
    with gzip.open(tmp, "wb", compresslevel=1) as f:
        for i in range(start, stop):
            f.write(sample_line(seed, i, style) + b"\n")
    os.replace(tmp, path)
    return str(path), stop - start


def write_dataset(out_dir: str | Path, count: int, seed: int, *, style: str | None = None,
                  shard_size: int = 1000, workers: int | None = None, progress: bool = True) -> list[Path]:
    """Generate ``count`` facades into sharded files under ``out_dir``; returns the shard paths."""
    if count < 1:
        raise ValueError(f"count must be at least 1, got {count}")
    if shard_size < 1:
        raise ValueError(f"shard size must be at least 1, got {shard_size}")
    if style is not None and style not in STYLE_NAMES:
        raise ValueError(f"unknown style {style!r}; expected one of {', '.join(STYLE_NAMES)}")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    jobs = [(str(out), k, start, min(start + shard_size, count), seed, style)
            for k, start in enumerate(range(0, count, shard_size))]
    workers = max(1, min(workers or os.cpu_count() or 1, len(jobs)))
    paths: list[Path] = []
    with tqdm(total=count, unit="facade", disable=not progress, desc="generate") as bar:
        if workers == 1:
            results: Iterator[tuple[str, int]] = map(_write_shard, jobs)
            for path, n in results:
                paths.append(Path(path))
                bar.update(n)
        else:
            with get_context("spawn").Pool(workers) as pool:
                for path, n in pool.imap(_write_shard, jobs):
                    paths.append(Path(path))
                    bar.update(n)
    manifest = {"count": count, "seed": seed, "style": style, "shard_size": shard_size,
                "grammar": GRAMMAR_VERSION, "shards": [p.name for p in paths]}
    (out / MANIFEST).write_text(json.dumps(manifest, indent=2) + "\n")
    return paths


def read_dataset(path: str | Path) -> Iterator[dict]:
    """Every sample record of a dataset directory (or of one shard file), in order."""
    path = Path(path)
    if path.is_dir():
        manifest = json.loads((path / MANIFEST).read_text())
        files = [path / name for name in manifest["shards"]]
    else:
        files = [path]
    for file in files:
        with gzip.open(file, "rb") as f:
            for line in f:
                yield orjson.loads(line)
