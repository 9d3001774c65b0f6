"""Where the project's files live: the shipped checkpoint and the CMP annotations beside the repository."""

from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DEFAULT_CHECKPOINT = ROOT / "checkpoints" / "facaid-small"
DEFAULT_CMP = ROOT.parent / "shared" / "data" / "cmp" / "annotations.jsonl"
