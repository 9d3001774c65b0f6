"""The procedure page's history in Debian's Chromium through Playwright: the versions listed, two compared side by
side and reverted to, and a re-run that fits worse shown beside the version it continued."""

from __future__ import annotations

import os
import shutil

import pytest
from site_helpers import counted_repeats, faithful_procedure, open_as_alice

from facaid.editing.variation import vary
from facaid.grammar import Procedure as Tree
from webapp.facades.models import Procedure
from webapp.facades.services import versions

pytestmark = [pytest.mark.django_db(transaction=True),
              pytest.mark.skipif(shutil.which("chromium") is None, reason="needs Debian's chromium")]


def _pictures_loaded(page) -> None:
    page.wait_for_function("['compare-a', 'compare-b', 'compare-diff'].every(id => "
                           "{ const i = document.getElementById(id); return i.complete && i.naturalWidth > 0; })")


def test_history_lists_versions_compares_two_and_reverts(live_server, alice, facade_photo, browser, tmp_path):
    _, seg = facade_photo
    proc = faithful_procedure(alice, seg)
    page, errors = open_as_alice(browser, live_server, proc, {"width": 1280, "height": 900})
    page.wait_for_selector("#history tbody tr")
    assert page.locator("#history tbody tr").count() == 1 and page.text_content("#version") == "1"

    # an edit saved: version 2, its own accuracy shown at once (the server's), both versions listed
    first = counted_repeats(proc.data["root"])[0]
    page.locator("#tree li > input").first.fill(str(first["count"] + 1))
    page.wait_for_function("document.getElementById('render').src.startsWith('blob:')")
    page.click("#save")
    page.wait_for_function("document.getElementById('saved').textContent === 'saved as version 2'")
    page.wait_for_function("document.querySelectorAll('#history tbody tr').length === 2")
    saved = Procedure.objects.get(pk=proc.pk)
    assert saved.accuracy < 1.0 and page.text_content("#version") == "2"
    assert page.text_content("#figure").strip() == f"· pixel accuracy {100 * saved.accuracy:.2f} %"
    assert page.text_content("#history tbody tr.current").count(f"{100 * saved.accuracy:.2f} %") == 1

    # compare: by default the current version (B) against the one before (A)
    page.click("#compare")
    page.wait_for_selector("#comparison:not([hidden])")
    _pictures_loaded(page)
    assert page.text_content("#compare-a-caption") == "A: version 1 · pixel accuracy 100.00 %"
    assert page.text_content("#compare-b-caption") == f"B: version 2 · pixel accuracy {100 * saved.accuracy:.2f} %"
    assert "% of the pixels: their label differs" in page.text_content("#compare-diff-caption")
    page.locator("#history-panel").scroll_into_view_if_needed()
    path = os.environ.get("FACAID_HISTORY_SCREENSHOT") or str(tmp_path / "procedure-history.png")
    page.locator("#history-panel").screenshot(path=path)

    # revert to version 1: a third version equal to it, the page shows its figures
    page.click("#history button[data-revert='1']")
    page.wait_for_function("document.querySelectorAll('#history tbody tr').length === 3")
    assert page.text_content("#version") == "3" and "100.00 %" in page.text_content("#figure")
    assert "reverted to version 1" in page.text_content("#history tbody tr.current")
    assert Procedure.objects.get(pk=proc.pk).data == proc.data
    assert errors == []

    # someone who may see the procedure reads its history, with no revert
    Procedure.objects.filter(pk=proc.pk).update(visibility="public")
    other = browser.new_page()
    other.goto(f"{live_server.url}/procedures/{proc.code}")
    other.wait_for_function("document.querySelectorAll('#history tbody tr').length === 3")
    assert other.locator("#history button[data-revert]").count() == 0 and other.locator("#save").count() == 0


def test_a_re_run_that_fits_worse_is_shown_beside_the_version_it_continued(live_server, alice, facade_photo, browser,
                                                                          tmp_path):
    _, seg = facade_photo
    proc = faithful_procedure(alice, seg)
    tree = Tree.from_dict(proc.data)
    worse = next(v for v in vary(tree, 8, 0) if v.meta["variation"] == "swap" and (v.width, v.height) == (
        tree.width, tree.height)).to_dict()
    versions.add_rerun(proc, worse, 0.75, {"source": "model"}, based_on=1, nodes=3)  # as the worker stores one
    page, errors = open_as_alice(browser, live_server, proc, {"width": 1280, "height": 1100})
    assert "fits worse than version 1: pixel accuracy 75.00 % against 100.00 %" in page.text_content("#rerun-warning")
    page.wait_for_selector("#comparison:not([hidden])")  # opened by itself
    _pictures_loaded(page)
    assert page.text_content("#compare-a-caption") == "A: version 1 · pixel accuracy 100.00 %"
    assert page.text_content("#compare-b-caption") == "B: version 2 · pixel accuracy 75.00 %"
    assert "worse" in page.get_attribute("#history tbody tr.current td:nth-child(5)", "class")
    path = os.environ.get("FACAID_RERUN_SCREENSHOT") or str(tmp_path / "procedure-rerun-warning.png")
    page.screenshot(path=path, full_page=True)
    page.click("#rerun-warning button[data-revert='1']")
    page.wait_for_function("document.querySelectorAll('#history tbody tr').length === 3")
    assert page.locator("#rerun-warning").count() == 0 and page.text_content("#version") == "3"
    assert errors == []
