"""The procedure page in Debian's Chromium through Playwright: the parameter tree shows rounded values without
changing the stored ones, an edit re-renders at once and saves as a new version, variations come back as eight
cards, a facade width in metres scales the CGA rules and the mesh, the named parameters come first and the picture
and the tree select each other. (The history is checked in `test_procedure_history_browser.py`, sharing and the
overlay in `test_procedure_sharing_browser.py`; the procedure beside its overlay on a photo in
`test_editor_end_to_end.py`, which makes a photo's procedure through the worker.)"""

from __future__ import annotations

import os
import re
import shutil

import pytest
from grammar_helpers import probe
from site_helpers import counted_repeats, open_as_alice

from facaid.generator import generate
from facaid.grammar import Procedure as Tree
from webapp.facades.models import Procedure, Segmentation

pytestmark = [pytest.mark.django_db(transaction=True),
              pytest.mark.skipif(shutil.which("chromium") is None, reason="needs Debian's chromium")]


def _sizes(node: dict) -> list[float]:
    return [s[1] for s in node.get("sizes", [])] + [v for c in node.get("children", []) for v in _sizes(c)]


def test_edit_a_count_render_and_save_then_vary(live_server, alice, browser):
    data = generate(3).procedure.to_dict()
    proc = Procedure.objects.create(owner=alice, data=data, visibility="private")
    page, errors = open_as_alice(browser, live_server, proc, {"width": 1400, "height": 1000})
    page.wait_for_selector("#tree input")
    shown = page.eval_on_selector_all("#tree input", "els => els.map(e => e.value)")
    assert all(len(v.split(".")[1]) <= 4 for v in shown if "." in v)  # no run of float digits
    assert any("." in v for v in shown)

    # the first repeat's count, one more: the render is replaced at once, and saving stores it
    first = counted_repeats(data["root"])[0]
    count = page.locator("#tree li > input").first  # a count sits in its node's item, a size in a span
    assert count.input_value() == str(first["count"])
    count.fill(str(first["count"] + 1))
    page.wait_for_function("document.getElementById('render').src.startsWith('blob:')")
    assert page.text_content("#saved") == "unsaved changes"
    page.click("#save")
    page.wait_for_function("document.getElementById('saved').textContent === 'saved as version 2'")
    stored = Procedure.objects.get(pk=proc.pk).data
    assert counted_repeats(stored["root"])[0]["count"] == first["count"] + 1
    assert _sizes(stored["root"]) == _sizes(data["root"])  # the rounded display did not round the values

    page.click("#vary")
    page.wait_for_function("document.querySelectorAll('#variants .card img').length === 8")
    # issue 68: a caption says what the variant is, "7 upper floors, 8 tiles a floor · resized to 828 × 739 px"
    captions = page.eval_on_selector_all("#variants .card .meta", "els => els.map(e => e.textContent)")
    said = (r"\d+ upper floors?, \d+ tiles? a floor · (resized to \d+ × \d+ px|one repeat's count changed|"
            r"a floor or tile swapped for another)")
    assert all(re.fullmatch(said, c) for c in captions), captions
    if shot := os.environ.get("FACAID_PAGE_SCREENSHOT"):  # docs/img/procedure-page.png: the page, tree closed
        page.click("#advanced summary")
        page.screenshot(path=shot, full_page=True)
        page.click("#advanced summary")

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


def test_variations_within_ranges_of_named_parameters(live_server, alice, browser, tmp_path):
    """The Variations panel takes a range per named parameter: the eight variations draw within it and say what they
    drew; a range with one end, or one the parameter cannot take, is refused with the reason."""
    proc = Procedure.objects.create(owner=alice, data=generate(3).procedure.to_dict(), visibility="private")
    page, errors = open_as_alice(browser, live_server, proc, {"width": 1400, "height": 1000}, advanced=False)
    page.click("#ranges-panel summary")
    page.wait_for_selector("#ranges tr[data-name=floors] input")
    names = page.eval_on_selector_all("#ranges tbody tr", "rows => rows.map(r => r.dataset.name)")
    assert {"floors", "floor_height", "bays", "window_width"} <= set(names)
    page.fill("input[name=floors-from]", "5")
    page.fill("input[name=floors-to]", "7")
    page.click("#vary")
    page.wait_for_function("document.querySelectorAll('#variants .card img').length === 8")
    page.fill("input[name=floor_height-from]", "80")
    page.click("#vary")
    page.wait_for_function("document.getElementById('vary-status').textContent !== ''")
    assert page.text_content("#vary-status") == "floor height: give both ends of the range"
    page.fill("input[name=floor_height-to]", "90")
    page.click("#vary")
    page.wait_for_function("(c => c.length === 8 && c.every(e => e.textContent.includes('floor height')))("
                           "[...document.querySelectorAll('#variants .card .meta')])")
    captions = page.eval_on_selector_all("#variants .card .meta", "els => els.map(e => e.textContent)")
    floors = [int(c.split("upper floors ")[1].split(",")[0]) for c in captions]
    heights = [float(c.split("floor height ")[1].split(" px")[0]) for c in captions]
    assert len(captions) == 8 and set(floors) <= {5, 6, 7} and len(set(floors)) > 1
    assert all(80 <= h <= 90 for h in heights)
    shot = os.environ.get("FACAID_RANGES_SCREENSHOT") or str(tmp_path / "procedure-ranges.png")
    page.locator("#vary").locator("xpath=ancestor::div[contains(@class, 'panel')]").screenshot(path=shot)
    page.fill("input[name=floors-from]", "0")
    page.click("#vary")
    page.wait_for_function("document.getElementById('vary-status').textContent.startsWith('no variations')")
    assert "floors: the range 0-7 leaves 1-256" in page.text_content("#vary-status")
    assert not errors


def test_nodes_are_numbered_breadth_first_and_a_click_picks_the_re_run_prefix(live_server, alice, facade_photo,
                                                                               browser):
    _, seg = facade_photo
    data = generate(3).procedure.to_dict()
    proc = Procedure.objects.create(owner=alice, data=data, segmentation=Segmentation.objects.get(
        photo__code=seg["photo"], version=seg["version"]))
    page, _ = open_as_alice(browser, live_server, proc, {"width": 1400, "height": 1000})
    page.wait_for_selector("#tree .bfs")
    shown = page.eval_on_selector_all("#tree li", "els => els.map(li => li.firstChild.textContent + ' ' + "
                                                  "li.querySelector(':scope > .node-label').textContent)")
    bfs = list(Tree.from_dict(data).root.bfs())
    assert len(shown) == len(bfs)
    by_index = {int(t.split(" ", 1)[0][1:]): t.split(" ", 2)[1] for t in shown}
    assert sorted(by_index) == list(range(len(bfs)))
    for k, node in enumerate(bfs):  # "#k rule_axis" or "#k label": the k-th node breadth first
        assert by_index[k] == (node.label if node.is_leaf else f"{node.rule}_{node.axis}")
    page.click('#tree .bfs >> text="#5"')
    assert page.input_value("#id_nodes") == "6"


def test_named_parameters_first_the_tree_in_advanced(live_server, alice, browser, tmp_path):
    """The named parameters are shown first and the raw tree is closed; a floor more re-renders a facade a floor
    taller, the tree follows, and saving keeps it as version 2."""
    from facaid.editing.parameters import named_parameters

    data = generate(3).procedure.to_dict()
    proc = Procedure.objects.create(owner=alice, data=data, visibility="private")
    page, errors = open_as_alice(browser, live_server, proc, {"width": 1280, "height": 900}, advanced=False)
    page.wait_for_selector("#named input[name=floors]")
    assert not page.is_visible("#tree") and page.is_visible("#named")
    before = {p.name: p for p in named_parameters(Tree.from_dict(data))}
    labels = page.eval_on_selector_all("#named th", "els => els.map(e => e.textContent)")
    assert labels[0] == "upper floors" and "floor height" in labels
    floors = page.locator("#named input[name=floors]")
    assert floors.input_value() == str(before["floors"].value)
    assert page.get_attribute("#named tr[data-name=floors]", "data-nodes").split() == before["floors"].nodes
    floors.fill(str(before["floors"].value + 1))
    floors.dispatch_event("change")
    page.wait_for_function("document.getElementById('render').src.startsWith('blob:')")
    page.wait_for_function(f"document.querySelector('#named input[name=floors]').value === "
                           f"'{before['floors'].value + 1}'")
    assert page.text_content("#saved") == "unsaved changes"
    path = os.environ.get("FACAID_PARAMETERS_SCREENSHOT") or str(tmp_path / "procedure-parameters.png")
    page.locator("#named").screenshot(path=path)
    page.click("#advanced summary")
    assert page.is_visible("#tree input")
    page.click("#save")
    page.wait_for_function("document.getElementById('saved').textContent === 'saved as version 2'")
    stored = Tree.from_dict(Procedure.objects.get(pk=proc.pk).data)
    after = {p.name: p.value for p in named_parameters(stored)}
    assert after["floors"] == before["floors"].value + 1 and stored.height > data["height"]
    assert after["ground_height"] == pytest.approx(before["ground_height"].value, abs=0.01)
    bad = page.locator("#named input[name=floor_height]")
    bad.fill("0")
    bad.dispatch_event("change")
    page.wait_for_function("document.getElementById('named-status').textContent.includes('floor_height')")
    assert not errors, errors


def test_picture_and_tree_select_each_other(live_server, alice, browser, tmp_path):
    """A click on a window in the picture selects its node in the tree (the advanced panel opens on it) and the
    parameters that stand for it, and outlines every copy it draws; a click on a parameter's name or on a node
    outlines what it stands for; a click on no element clears the selection."""
    from facaid.editing.parameters import named_parameters
    from facaid.formats.relief import drawn_leaves

    tree = generate(3).procedure
    proc = Procedure.objects.create(owner=alice, data=tree.to_dict(), visibility="private")
    page, errors = open_as_alice(browser, live_server, proc, {"width": 1280, "height": 900}, advanced=False)
    page.wait_for_selector("#named input[name=floors]")
    page.wait_for_function("document.getElementById('render').complete")
    rows, paths = drawn_leaves(tree)
    i = next(k for k, r in enumerate(rows.tolist()) if r[0] == 2)  # the first window
    label, x0, y0, x1, y1 = rows[i].tolist()
    box = page.locator("#render").bounding_box()

    def click_at(x, y):  # a point of the procedure, on the picture wherever it is scrolled to
        page.locator("#render").click(position={"x": x / tree.width * box["width"],
                                                "y": y / tree.height * box["height"]})

    click_at((x0 + x1) / 2, (y0 + y1) / 2)
    path = paths[i]
    page.wait_for_selector(f'#tree li.selected[data-path="{path}"]')
    assert page.evaluate("document.getElementById('advanced').open")
    copies = sum(p == path or p.startswith(path + "/") for p in paths)
    assert copies > 1 and page.get_attribute("#selection", "data-outlined") == str(copies)  # every copy
    named = {p.name: p for p in named_parameters(tree)}
    over = {n for n, p in named.items() if any(path == q or path.startswith(q + "/") for q in p.nodes)}
    chosen = set(page.eval_on_selector_all("#named tr.selected", "rows => rows.map(r => r.dataset.name)"))
    assert chosen == over and {"window_width", "floor_height"} <= chosen
    assert page.text_content("#selection-info").startswith(f"Selected: window · {path} · window width")
    path_shot = os.environ.get("FACAID_SELECTION_SCREENSHOT") or str(tmp_path / "procedure-selection.png")
    page.locator(".cols .panel").first.screenshot(path=path_shot)

    # the reverse: a parameter's name outlines every leaf of the nodes it stands for
    page.click("#named tr[data-name=floor_height] th")
    under = sum(any(p == q or p.startswith(q + "/") for q in named["floor_height"].nodes) for p in paths)
    page.wait_for_function(f"document.getElementById('selection').dataset.outlined === '{under}'")
    assert page.eval_on_selector_all("#named tr.selected", "rows => rows.map(r => r.dataset.name)") == [
        "floor_height"]
    # and a node of the tree outlines what it draws: the window's parent, every copy
    parent = path.rsplit("/", 1)[0]
    page.click(f'#tree li[data-path="{parent}"] > .node-label')
    under = sum(p == parent or p.startswith(parent + "/") for p in paths)
    page.wait_for_function(f"document.getElementById('selection').dataset.outlined === '{under}'")
    assert page.get_attribute('#tree li.selected', "data-path") == parent and under > copies
    # a click where the tree draws nothing (the sky, background) clears the selection
    sky = next((x, y) for y in range(0, round(tree.height), 4) for x in range(0, round(tree.width), 4)
               if not any(r[1] <= x + 0.5 < r[3] and r[2] <= y + 0.5 < r[4] for r in rows.tolist()))
    click_at(sky[0] + 0.5, sky[1] + 0.5)
    page.wait_for_function("document.getElementById('selection-info').textContent === ''")
    assert not page.query_selector("#tree li.selected") and not page.query_selector("#named tr.selected")
    assert not errors, errors


WINDOW_ROWS_JS = """async (src) => {
  const img = new Image(); img.src = src; await img.decode();
  const c = document.createElement('canvas'); c.width = img.naturalWidth; c.height = img.naturalHeight;
  const g = c.getContext('2d'); g.drawImage(img, 0, 0);
  const d = g.getImageData(0, 0, c.width, c.height).data;
  let rows = 0, inside = false;  // bands of image rows that hold a window pixel (52, 101, 164)
  for (let y = 0; y < c.height; y++) {
    let any = false;
    for (let x = 0; x < c.width && !any; x++) {
      const i = 4 * (y * c.width + x);
      any = d[i] === 52 && d[i + 1] === 101 && d[i + 2] === 164;
    }
    if (any && !inside) rows++;
    inside = any;
  }
  return rows;
}"""


def test_floors_plus_one_on_a_real_like_facade_adds_a_row_of_windows(live_server, alice, browser, tmp_path):
    """A real-like facade (drawn as people draw CMP's) reconstructed as a job does it: the editable procedure is
    the page's, and floors + 1 in its parameters draws one more row of windows at once."""
    from grammar_helpers import real_like
    from site_helpers import screenshot

    from facaid.pipeline import ReconstructOptions, reconstruct

    seg = real_like()
    result = reconstruct(seg, ReconstructOptions(k=2))
    assert result.structure == "editable"
    proc = Procedure.objects.create(owner=alice, title="Real-like facade", data=result.procedure.to_dict(),
                                    accuracy=result.accuracy, metrics={"source": result.source,
                                                                       "structure": result.structure})
    page, errors = open_as_alice(browser, live_server, proc, {"width": 1300, "height": 1450}, advanced=False)
    page.wait_for_selector("#named input[name=floors]")
    before = page.evaluate(WINDOW_ROWS_JS, page.get_attribute("#render", "src"))
    assert page.input_value("#named input[name=floors]") == "5" and before == 5
    page.fill("#named input[name=floors]", "6")
    page.dispatch_event("#named input[name=floors]", "change")
    page.wait_for_function("document.getElementById('render').src.startsWith('blob:')")
    assert page.evaluate(WINDOW_ROWS_JS, page.get_attribute("#render", "src")) == before + 1
    assert page.input_value("#named input[name=bays]") == "6"
    screenshot(page, "procedure-floors-plus-one.png", tmp_path)
    page.click("#advanced summary")  # the raw tree lists the exceptions: the closed blind among them
    listed = page.eval_on_selector_all("#tree .exception", "els => els.map(e => e.parentElement.textContent)")
    assert any("exception: copy " in text and "blind" in text for text in listed), listed
    assert not errors


def test_a_tree_that_cannot_be_drawn_is_shown_without_its_picture(live_server, alice, browser, tmp_path):
    """Issue 66: a tree stored before the cost model counted exceptions (the probe's shape, 100 copies) is refused
    when read; its page says so in place of the picture, the parameters are not asked for, and nothing fails."""
    proc = Procedure.objects.create(owner=alice, title="stored before", data=probe(rows=100, columns=1),
                                   visibility="public")
    page, errors = open_as_alice(browser, live_server, proc, {"width": 1280, "height": 900}, advanced=False)
    page.wait_for_selector("#picture-note")
    assert "This procedure cannot be drawn" in page.inner_text("#picture-note")
    assert not page.is_visible("#render") and page.get_attribute("#render", "src") is None
    assert page.inner_text("#named-status") == "The named parameters are not read: see above."
    page.screenshot(path=str(tmp_path / "not-drawn.png"))
    assert errors == []


def test_at_1280x800_the_picture_stays_whole_in_view_beside_the_parameters(live_server, alice, browser, tmp_path):
    """Issue 68, item 5: at 1280 x 800 only the bottom 190 px of the picture showed while the parameters were
    edited. The picture sits beside the overlay and the parameters and stays in view, whole, wherever the page is
    scrolled to edit them."""
    from site_helpers import screenshot

    data = generate(3).procedure.to_dict()  # a tall facade: at the panel's width it would be taller than the window
    assert data["height"] > data["width"]
    proc = Procedure.objects.create(owner=alice, data=data, visibility="private")
    page, errors = open_as_alice(browser, live_server, proc, {"width": 1280, "height": 800}, advanced=False)
    page.wait_for_selector("#named input[name=floors]")
    page.wait_for_function("document.getElementById('render').naturalWidth > 0")

    def in_view() -> dict:
        box = page.locator("#render").bounding_box()
        assert box["y"] >= 0 and box["y"] + box["height"] <= 800 and box["x"] + box["width"] <= 1280, box
        return box

    in_view()  # as the page opens, under its title
    for selector in ("#named input[name=floors]", "#named tr:last-child input", "#advanced summary"):
        page.locator(selector).scroll_into_view_if_needed()
        field = page.locator(selector).bounding_box()
        box = in_view()
        assert box["x"] + box["width"] <= field["x"], (box, field)  # beside the fields, not over them
    assert abs(box["width"] / box["height"] - data["width"] / data["height"]) < 0.02  # whole, not squeezed
    screenshot(page, "procedure-parameters-1280x800.png", tmp_path)

    # a floor more: the taller picture still fits
    floors = page.locator("#named input[name=floors]")
    floors.fill(str(int(floors.input_value()) + 2))
    floors.press("Enter")
    page.wait_for_function("document.getElementById('saved').textContent === 'unsaved changes'")
    page.wait_for_function("document.getElementById('render').complete")
    in_view()
    assert errors == []
