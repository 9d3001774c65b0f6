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


def _table(lines: list[str], heading: str) -> list[str]:
    start = lines.index(heading)
    end = next((i for i in range(start + 1, len(lines)) if lines[i].startswith("## ")), len(lines))
    rows = [line for line in lines[start:end] if line.startswith("|")]
    assert rows[0] == "| what | figure (target) | command | date |"
    for row in rows[2:]:
        cells = [c.strip() for c in row.strip("|").split("|")]
        assert len(cells) == 4 and cells[2].startswith("`") and len(cells[3]) == 5, row  # commands, a date
    return rows[2:]


def test_the_readme_is_a_users_page_with_ten_headline_figures_and_the_rest_in_experiments():
    """Issues 59 and 69: at most 200 lines, and the measured figures one table of at most 10 headline rows, each
    with its command and date; every current figure is in experiments/figures.md's table, the README's among them,
    and the story of the figures lives there too."""
    lines = (ROOT / "README.md").read_text().splitlines()
    assert len(lines) <= 200
    headline = _table(lines, "## Measured figures")
    assert 3 <= len(headline) <= 10
    every = _table((ROOT / "experiments" / "figures.md").read_text().splitlines(), "## Every current figure")
    assert len(every) >= len(headline)
    commands = " ".join(row.split("|")[3] for row in every)
    for row in headline:  # each headline's command is in the full table too
        assert row.split("|")[3].split("`")[1] in commands, row


def test_every_experiment_is_indexed():
    index = (ROOT / "experiments" / "README.md").read_text()
    folders = [p.name for p in (ROOT / "experiments").iterdir() if p.is_dir()]
    assert [name for name in folders if f"]({name}/" not in index] == []
