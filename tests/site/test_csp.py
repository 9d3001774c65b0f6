"""The Content-Security-Policy: on every response (pages, the API, scripts, errors), with a nonce of its own
per request; and no template writes what it refuses (an inline script but the import map, a style attribute or
element, an event handler attribute), so the policy breaks no page. The browser tests count what Chromium refused
as a page error (`site_helpers.collect_errors`)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest
from django.test import Client

from facaid.generator import generate
from webapp.facades.models import Procedure

pytestmark = pytest.mark.django_db

ROOT = Path(__file__).resolve().parents[2]
TEMPLATES = sorted(p for folder in ("webapp", "frontend") for p in (ROOT / folder).rglob("*.html"))


def policy(response) -> dict[str, str]:
    header = response["Content-Security-Policy"]
    return {d.split()[0]: " ".join(d.split()[1:]) for d in header.split("; ")}


def test_every_response_carries_the_policy(alice, as_alice, settings):
    proc = Procedure.objects.create(owner=alice, title="t", data=generate(3).procedure.to_dict(), visibility="public")
    settings.FACAID_MAX_UPLOAD_BYTES = 10
    anyone = Client()
    answers = [anyone.get("/"), anyone.get(f"/procedures/{proc.code}"), as_alice.get("/photos/new"),
               anyone.get("/api/v1/gallery/"), anyone.get("/nowhere"), anyone.get("/api/v1/nowhere"),
               anyone.get("/api/v1/docs"), anyone.get("/api/v1/docs?script="),
               as_alice.post("/api/v1/photos/", {"image": "x" * 2_000_000})]  # a 413 before anything reads it
    assert [r.status_code for r in answers] == [200, 200, 200, 200, 404, 404, 200, 200, 413]
    nonces = set()
    for r in answers:
        p = policy(r)
        assert p["default-src"] == "'self'" and p["style-src"] == "'self'" and p["object-src"] == "'none'"
        assert p["frame-ancestors"] == "'none'" and p["base-uri"] == "'none'" and p["form-action"] == "'self'"
        script = p["script-src"].split()
        assert script[0] == "'self'" and len(script) == 2 and re.fullmatch(r"'nonce-[\w-]{20,}'", script[1])
        nonces.add(script[1])
    assert len(nonces) == len(answers)  # one per request


def test_no_template_writes_what_the_policy_refuses():
    """No <script> without a src but the nonced import map, no <style> element, no style="" and no on...=""
    attribute, no javascript: URL, in any template of the site, nor a style attribute given a form's widget."""
    assert len(TEMPLATES) >= 15
    for path in TEMPLATES:
        html = path.read_text()
        where = path.relative_to(ROOT)
        for tag in re.findall(r"<script\b[^>]*>", html):
            assert "src=" in tag or tag == '<script type="importmap" nonce="{{ request.csp_nonce }}">', (where, tag)
        assert not re.search(r"<style\b", html), where
        assert not re.search(r"""<[^>]*\sstyle\s*=""", html), where
        assert not re.search(r"""<[^>]*\son[a-z]+\s*=""", html), where
        assert "javascript:" not in html, where
    for path in sorted((ROOT / "webapp").rglob("*.py")):  # a form widget's attributes
        assert not re.search(r"""["']style["']\s*:""", path.read_text()), path.relative_to(ROOT)


def test_no_script_writes_markup_the_policy_refuses():
    """The page modules set styles as properties: a style attribute in markup they write (innerHTML) is refused."""
    for path in sorted((ROOT / "frontend").rglob("*.js")):
        if "tests" in path.parts:
            continue
        text = path.read_text()
        for markup in re.findall(r"(?:innerHTML|outerHTML|insertAdjacentHTML)[^;]*", text):
            assert "style=" not in markup and not re.search(r"\son[a-z]+=", markup), (path.name, markup)
        assert 'setAttribute("style"' not in text and "setAttribute('style'" not in text, path.name
