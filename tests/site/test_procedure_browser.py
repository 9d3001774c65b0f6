"""The procedure page in Debian's Chromium through Playwright: the parameter tree shows rounded values without
changing the stored ones, an edit re-renders at once and saves, variations come back as eight cards, a facade width
in metres scales the CGA rules and the mesh. (The
procedure beside its overlay on a photo is checked in `test_editor_end_to_end.py`, which makes a photo's
procedure through the worker.)"""

from __future__ import annotations

import shutil

import pytest
from site_helpers import login

from facaid.generator import generate
from facaid.grammar import Procedure as Tree
from webapp.facades.models import Procedure, Segmentation

pytestmark = [pytest.mark.django_db(transaction=True),
              pytest.mark.skipif(shutil.which("chromium") is None, reason="needs Debian's chromium")]


def _repeats(node: dict) -> list[dict]:
    out = [node] if node["rule"] == "repeat" and node["count"] != "fill" else []
    for child in node.get("children", []):
        out += _repeats(child)
    return out


def _sizes(node: dict) -> list[float]:
    return [s[1] for s in node.get("sizes", [])] + [v for c in node.get("children", []) for v in _sizes(c)]


def test_edit_a_count_render_and_save_then_vary(live_server, alice, browser):
    data = generate(3).procedure.to_dict()
    proc = Procedure.objects.create(owner=alice, data=data, visibility="private")
    page = browser.new_page(viewport={"width": 1400, "height": 1000})
    errors = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    login(page, live_server.url, "alice", "alice-password-1")
    page.goto(f"{live_server.url}/procedures/{proc.code}")
    page.wait_for_selector("#tree input")
    shown = page.eval_on_selector_all("#tree input", "els => els.map(e => e.value)")
    assert all(len(v.split(".")[1]) <= 4 for v in shown if "." in v)  # no run of float digits
    assert any("." in v for v in shown)

    # the first repeat's count, one more: the render is replaced at once, and saving stores it
    first = _repeats(data["root"])[0]
    count = page.locator("#tree li > input").first  # a count sits in its node's item, a size in a span
    assert count.input_value() == str(first["count"])
    count.fill(str(first["count"] + 1))
    page.wait_for_function("document.getElementById('render').src.startsWith('blob:')")
    assert page.text_content("#saved") == "unsaved changes"
    page.click("#save")
    page.wait_for_function("document.getElementById('saved').textContent === 'saved'")
    stored = Procedure.objects.get(pk=proc.pk).data
    assert _repeats(stored["root"])[0]["count"] == first["count"] + 1
    assert _sizes(stored["root"]) == _sizes(data["root"])  # the rounded display did not round the values

    page.click("#vary")
    page.wait_for_function("document.querySelectorAll('#variants .card img').length === 8")

    # a facade width in metres sets the scale of the CGA rules and the 3D models; cleared, the default again
    cga = page.locator("a[href*='/procedure.cga']")
    page.fill("#width-m", "20")
    assert cga.get_attribute("href").endswith(f"/procedure.cga?metres_per_pixel={20 / data['width']}")
    for name in ("mesh.zip", "facade.glb", "facade.ifc", "facade.city.json"):  # and every 3D model
        assert page.get_attribute(f"a[href*='/{name}']", "href").endswith(f"?metres_per_pixel={20 / data['width']}")
    with page.expect_download() as d:
        cga.click()
    assert "20 m x" in d.value.path().read_text()
    with page.expect_download() as d:
        page.click("a[href*='/mesh.zip']")
    assert d.value.suggested_filename.endswith("-mesh.zip")
    page.fill("#width-m", "")
    assert cga.get_attribute("href").endswith("/procedure.cga")
    page.fill("#width-m", str(1000 * data["width"]))  # past the server's 100 m per pixel: the default, and a message
    assert cga.get_attribute("href").endswith("/procedure.cga")
    assert page.eval_on_selector("#width-m", "e => e.validationMessage").startswith("a width from 0.1 to")
    assert errors == []


def test_nodes_are_numbered_breadth_first_and_a_click_picks_the_re_run_prefix(live_server, alice, facade_photo,
                                                                               browser):
    _, seg = facade_photo
    data = generate(3).procedure.to_dict()
    proc = Procedure.objects.create(owner=alice, data=data, segmentation=Segmentation.objects.get(
        photo__code=seg["photo"], version=seg["version"]))
    page = browser.new_page(viewport={"width": 1400, "height": 1000})
    login(page, live_server.url, "alice", "alice-password-1")
    page.goto(f"{live_server.url}/procedures/{proc.code}")
    page.wait_for_selector("#tree .bfs")
    shown = page.eval_on_selector_all("#tree li", "els => els.map(li => li.firstChild.textContent + "
                                                  "li.childNodes[1].textContent)")
    bfs = list(Tree.from_dict(data).root.bfs())
    assert len(shown) == len(bfs)
    by_index = {int(t.split(" ", 1)[0][1:]): t.split(" ", 2)[1] for t in shown}
    assert sorted(by_index) == list(range(len(bfs)))
    for k, node in enumerate(bfs):  # "#k rule_axis" or "#k label": the k-th node breadth first
        assert by_index[k] == (node.label if node.is_leaf else f"{node.rule}_{node.axis}")
    page.click('#tree .bfs >> text="#5"')
    assert page.input_value("#id_nodes") == "6"
