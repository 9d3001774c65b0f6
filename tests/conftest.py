import json
from pathlib import Path

import pytest

CMP = Path(__file__).resolve().parents[2] / "shared" / "data" / "cmp" / "annotations.jsonl"


@pytest.fixture(scope="session")
def cmp_records():
    """A few CMP annotations, used only to check that real data passes through the format code."""
    if not CMP.is_file():
        pytest.skip(f"CMP annotations not found at {CMP}")
    with open(CMP) as f:
        return [json.loads(next(f)) for _ in range(25)]
