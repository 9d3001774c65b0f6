from pathlib import Path

import numpy as np
from PIL import Image

from facaid.docs import DOCS_IMG, write_figures
from facaid.grammar.procedure import ROLES, RULES
from facaid.labels import LABELS

DOC = Path(__file__).resolve().parents[1] / "docs" / "grammar.md"


def test_committed_figures_are_up_to_date(tmp_path):
    for fresh in write_figures(tmp_path):
        committed = DOCS_IMG / fresh.name
        assert committed.is_file(), f"{committed} missing: run python -m facaid.docs"
        assert np.array_equal(np.asarray(Image.open(fresh)), np.asarray(Image.open(committed))), (
            f"{committed.name} is stale: run python -m facaid.docs")


def test_grammar_doc_covers_every_rule_role_label_and_picture():
    text = DOC.read_text()
    for rule in RULES:
        assert f"### `{rule}`" in text
    for role in ROLES:
        assert f"| `{role}` |" in text
    for label in LABELS:
        assert label in text
    every_doc = "".join(p.read_text() for p in DOC.parent.glob("*.md"))
    for image in DOCS_IMG.glob("*.png"):  # no picture without a page that shows it
        assert f"img/{image.name}" in every_doc, image.name
