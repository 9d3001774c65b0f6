"""Where the project's files live: the shipped checkpoint and the CMP annotations (evaluation only).

Both default to this checkout's layout: the checkpoint under ``checkpoints/`` in the repository, the CMP data in
``shared/data/cmp/`` beside the repository (where this project's machines keep it). Elsewhere, point at them with
``FACAID_CHECKPOINT`` (a checkpoint directory) and ``FACAID_CMP`` (the annotations JSON-lines file); the commands
that read them take ``--checkpoint`` and ``--cmp`` too.
"""

import os
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
DEFAULT_CHECKPOINT = Path(os.environ.get("FACAID_CHECKPOINT") or ROOT / "checkpoints" / "facaid-small")
DEFAULT_CMP = Path(os.environ.get("FACAID_CMP") or ROOT.parent / "shared" / "data" / "cmp" / "annotations.jsonl")
