"""The editor's DOM-free modules agree with the library, and their own tests pass under node."""

import json
import shutil
import subprocess
from pathlib import Path

import pytest

from facaid.labels import LABELS, PAINT_ORDER, PALETTE

FRONTEND = Path(__file__).resolve().parents[2] / "frontend"
pytestmark = pytest.mark.skipif(shutil.which("node") is None, reason="needs node")


def node_eval(code: str) -> str:
    return subprocess.run(["node", "--input-type=module", "-e", code], cwd=FRONTEND, check=True,
                          capture_output=True, text=True).stdout


def test_labels_palette_and_paint_order_match_the_library():
    out = json.loads(node_eval("import * as L from './editor/labels.js'; console.log(JSON.stringify("
                               "{labels: L.LABELS, order: L.PAINT_ORDER, palette: L.PALETTE}))"))
    assert out["labels"] == list(LABELS)
    assert out["order"] == list(PAINT_ORDER)
    assert {k: tuple(v) for k, v in out["palette"].items()} == PALETTE


def test_node_unit_tests_pass():
    r = subprocess.run(["node", "--test", "tests/"], cwd=FRONTEND, capture_output=True, text=True)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-2000:]
    assert "# fail 0" in r.stdout
