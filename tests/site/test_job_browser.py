"""The job page in Debian's Chromium through Playwright: it polls the job and shows its stage and progress while
it runs, then its procedure's link (no worker: the test moves the job along itself)."""

from __future__ import annotations

import shutil

import pytest
from site_helpers import collect_errors, login, screenshot

from facaid.generator import generate
from webapp.facades.models import Job, Procedure, Segmentation

pytestmark = [pytest.mark.django_db(transaction=True),
              pytest.mark.skipif(shutil.which("chromium") is None, reason="needs Debian's chromium")]


def test_job_page_follows_the_stages_to_the_procedure(live_server, alice, facade_photo, browser, tmp_path):
    _, seg = facade_photo
    segmentation = Segmentation.objects.get(photo__code=seg["photo"], version=seg["version"])
    job = Job.objects.create(owner=alice, segmentation=segmentation, status=Job.Status.RUNNING, progress=0.05,
                             stage="loading the model")
    page = browser.new_page(viewport={"width": 1200, "height": 800})
    errors = collect_errors(page, [])  # script errors, and what the page's CSP refused
    login(page, live_server.url, "alice", "alice-password-1")
    page.goto(f"{live_server.url}/jobs/{job.code}")
    assert page.text_content("#stage") == "loading the model"
    # the page's lines stack (the editor's job bar is a row of its own: its style is not the page's)
    top = page.evaluate("[...document.querySelectorAll('#job > *')].map(e => e.getBoundingClientRect())"
                        ".filter(r => r.height > 0).map(r => r.top)")
    assert top == sorted(top) and len(set(top)) == len(top)
    screenshot(page, "job-running.png", tmp_path)
    assert page.text_content("#attempts") == "0"
    Job.objects.filter(id=job.id).update(progress=0.6, stage="sizing", attempts=1)
    page.wait_for_function("document.getElementById('stage').textContent === 'sizing'", timeout=10_000)
    assert page.text_content("#attempts") == "1"  # followed as it runs, not only when the page is drawn
    assert page.evaluate("document.getElementById('progress').value") == pytest.approx(0.6)
    proc = Procedure.objects.create(owner=alice, data=generate(3).procedure.to_dict())
    Job.objects.filter(id=job.id).update(status=Job.Status.DONE, progress=1.0, stage="done", result=proc)
    page.wait_for_selector("#result a", timeout=10_000)
    assert page.text_content("#status") == "done" and page.text_content("#stage") == ""  # not "done done"
    page.click("#result a")
    page.wait_for_url(f"{live_server.url}/procedures/{proc.code}")
    page.goto(f"{live_server.url}/jobs/{job.code}")  # drawn by the server once done: the same
    assert page.text_content("#status") == "done" and page.text_content("#stage") == ""
    assert errors == []
