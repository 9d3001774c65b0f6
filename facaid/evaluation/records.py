"""A resumable log of per-facade evaluation records: `facaid evaluate --records FILE`.

A long evaluation (10,000 facades takes hours on two CPU cores) appends each facade's figures to a JSON-lines
file as soon as they are measured. The first line holds the run's settings, including a digest of the weights;
a run started again on the file with the same settings reads the records back and measures only the facades
after them, so a run stopped at any point (a killed process, the end of a working session) loses at most the
facade it was measuring. A file of other settings or other weights is refused rather than mixed in.
"""

from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path
from typing import TYPE_CHECKING

import torch

if TYPE_CHECKING:
    from facaid.model import FacaidModel
    from facaid.tokenizer import Tokenizer


class RecordsError(ValueError):
    """A records file that cannot be resumed: other settings, other weights, or not a records file."""


def model_digest(model: FacaidModel, tokenizer: Tokenizer) -> str:
    """SHA-256 of the weights (names, shapes, values) and the tokenizer's configuration: the same for the same
    checkpoint wherever it is loaded."""
    h = hashlib.sha256(json.dumps(tokenizer.config.to_dict(), sort_keys=True).encode())
    for name, value in model.state_dict().items():
        h.update(name.encode())
        h.update(str(tuple(value.shape)).encode())
        h.update(value.detach().to("cpu", torch.float32).contiguous().numpy().tobytes())
    return h.hexdigest()


class RecordLog:
    """The records of one evaluation run in ``path``; `append` writes one and flushes it to disk."""

    def __init__(self, path: str | Path, settings: dict):
        self.path = Path(path)
        self.settings = settings
        self.records: list[dict] = []
        if self.path.is_file() and self.path.stat().st_size > 0:
            self._read()
        else:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self.path.write_text(json.dumps({"settings": settings}) + "\n")

    def _read(self) -> None:
        raw = self.path.read_bytes()
        header, self.records, whole = _parse(self.path, raw)
        if header["settings"] != self.settings:
            differ = sorted(k for k in set(header["settings"]) | set(self.settings)
                            if header["settings"].get(k) != self.settings.get(k))
            raise RecordsError(f"{self.path} holds records of other settings ({', '.join(differ)} differ); "
                               "give another file, or delete this one to start over")
        if whole != raw:  # drop a cut-off record, end the last line, before appending
            self.path.write_bytes(whole)

    def append(self, record: dict) -> None:
        with self.path.open("a") as f:
            f.write(json.dumps(record) + "\n")
            f.flush()
            os.fsync(f.fileno())
        self.records.append(record)


def read_records(path: str | Path) -> tuple[dict, list[dict]]:
    """The settings and records of a records file, read only: a record cut off by a stopped run is left out."""
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"no records file at {path}")
    header, records, _ = _parse(path, path.read_bytes())
    return header["settings"], records


def _parse(path: Path, raw: bytes) -> tuple[dict, list[dict], bytes]:
    """The file ``path`` read as ``raw``: (header, records, its bytes without a cut-off last record and with the
    last line ended)."""
    lines = raw.split(b"\n")
    try:
        header = json.loads(lines[0])
    except (json.JSONDecodeError, UnicodeDecodeError):
        raise RecordsError(f"{path} is not an evaluation records file (its first line is not JSON)") from None
    if not isinstance(header, dict) or not isinstance(header.get("settings"), dict):
        raise RecordsError(f"{path} is not an evaluation records file (no settings on its first line)")
    body = lines[1:]
    last = max((k for k, line in enumerate(body) if line.strip()), default=-1)
    kept = last + 1
    records: list[dict] = []
    for k, line in enumerate(body[:kept]):
        try:
            rec = json.loads(line)
        except (json.JSONDecodeError, UnicodeDecodeError):
            if k < last:
                raise RecordsError(f"{path}: line {k + 2} is not JSON") from None
            kept = k  # the line a stopped run was cut off writing
            break
        if not isinstance(rec, dict) or rec.get("i") != len(records):
            raise RecordsError(f"{path}: line {k + 2} is not record {len(records)} in order")
        records.append(rec)
    return header, records, b"\n".join([lines[0], *body[:kept]]) + b"\n"
