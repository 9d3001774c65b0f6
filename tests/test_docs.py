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


ROOT = DOC.parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md")),
         *(ROOT / "experiments" / name for name in ("README.md", "diary.md", "figures.md"))]


def test_every_relative_link_of_the_docs_leads_somewhere():
    import re

    broken = [(page.name, url) for page in PAGES for url in re.findall(r"\]\(([^)\s]+)\)", page.read_text())
              if not url.startswith(("http", "#", "mailto")) and not (page.parent / url.split("#")[0]).exists()]
    assert broken == []


def test_the_readme_is_a_users_page_with_one_table_of_current_figures():
    """Issue 59: at most 200 lines, and the measured figures one table of at most 40 lines, each row with its
    command and date; the story of the figures lives in experiments/figures.md."""
    lines = (ROOT / "README.md").read_text().splitlines()
    assert len(lines) <= 200
    start = lines.index("## Measured figures")
    end = next((i for i in range(start + 1, len(lines)) if lines[i].startswith("## ")), len(lines))
    rows = [line for line in lines[start:end] if line.startswith("|")]
    assert 3 <= len(rows) <= 40 and end - start <= 50
    assert rows[0] == "| what | figure (target) | command | date |"
    for row in rows[2:]:
        cells = [c.strip() for c in row.strip("|").split("|")]
        assert len(cells) == 4 and cells[2].startswith("`") and len(cells[3]) == 5, row  # commands, a date
