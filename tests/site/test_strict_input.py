"""JSON bodies are read strictly: a string that is not text (an unpaired surrogate) is a 400 naming its field
wherever it is sent, not a 500 when the answer echoes it; a boolean is ``true`` or ``false``, not 0, 1 or "true";
and the API's answers are written even where they hold text UTF-8 cannot write."""

from __future__ import annotations

import json

import pytest
from hypothesis import given
from hypothesis import strategies as st
from site_helpers import facade_png

from facaid.generator import generate
from webapp.facades.jsonbody import JSONRenderer
from webapp.facades.models import Job, Photo, Procedure, ProcedureVersion, Segmentation

pytestmark = pytest.mark.django_db

SURROGATE = "\ud800"


def raw(client, method: str, path: str, body):
    """``body`` sent as JSON written with escapes, as any client may send it (``"\\ud800"``): the test client's own
    encoder cannot write an unpaired surrogate."""
    return client.generic(method, path, json.dumps(body), content_type="application/json")


def state() -> list:
    return [list(m.objects.order_by("pk").values_list()) for m in (Photo, Segmentation, Procedure, ProcedureVersion,
                                                                    Job)]


@pytest.fixture
def world(as_alice, alice, facade_photo):
    photo, seg = facade_photo
    proc = Procedure.objects.create(owner=alice, title="mine", data=generate(3).procedure.to_dict())
    return {"photo": photo["code"], "segmentation": seg["code"], "procedure": str(proc.code)}


def bodies(world, bad):
    """The five places the probe found (a choice echoed in its error message), each with ``bad`` in its choice."""
    tree = generate(4).procedure.to_dict()
    return [
        ("POST", "/api/v1/convert", {"text": json.dumps(facade_png()[1]), "format": bad}, "format"),
        ("POST", "/api/v1/jobs/", {"segmentation": world["segmentation"], "structure": bad}, "structure"),
        ("PATCH", f"/api/v1/photos/{world['photo']}/", {"visibility": bad}, "visibility"),
        ("POST", "/api/v1/procedures/", {"data": tree, "visibility": bad}, "visibility"),
        ("PATCH", f"/api/v1/procedures/{world['procedure']}/", {"visibility": bad}, "visibility"),
    ]


@pytest.mark.parametrize("place", range(5))
@pytest.mark.parametrize("bad, code", [(SURROGATE, "D800"), (f"public{SURROGATE}", "D800"), ("\udfff", "DFFF"),
                                       ("\udc00\ud800", "DC00"), ("sideways", None)])
def test_an_unpaired_surrogate_is_a_400_naming_the_field_in_each_place_the_probe_found(as_alice, world, place, bad,
                                                                                       code):
    method, path, body, field = bodies(world, bad)[place]
    before = state()
    r = raw(as_alice, method, path, body)
    assert r.status_code == 400, (path, r.status_code, r.content[:300])
    if code is None:  # a plain bad choice: the field's own message, as before
        assert r.json()[field] == ['"sideways" is not a valid choice.'], r.content
    else:
        assert r.json() == {"detail": f"JSON parse error - {field} holds an unpaired surrogate (U+{code}): not plain "
                                      "JSON text"}
    assert state() == before


@pytest.mark.parametrize("place", range(5))
def test_a_nul_is_text_that_the_field_refuses_itself(as_alice, world, place):
    method, path, body, field = bodies(world, "pub\x00lic")[place]
    before = state()
    r = raw(as_alice, method, path, body)
    assert r.status_code == 400 and field in r.json() and "\\u0000" in r.content.decode(), r.content[:300]
    assert state() == before


@pytest.mark.parametrize("body, where", [
    ({"title": "a", "data": {"root": {"children": [{}, {"label": SURROGATE}]}}}, "data.root.children[1].label"),
    ({"title": "a", "data": {"meta": {f"k{SURROGATE}": 1}}}, "a key of data.meta"),
    ([SURROGATE], "[0]"),
    ({"title": f"x{SURROGATE}"}, "title"),
])
def test_any_field_at_any_depth_is_named(as_alice, world, body, where):
    r = raw(as_alice, "POST", "/api/v1/procedures/", body)
    assert r.status_code == 400 and r.json()["detail"].startswith(f"JSON parse error - {where} holds an unpaired"), \
        r.content


def test_paired_surrogates_are_text_and_kept(as_alice, world):
    """A character beyond the basic plane (written in JSON as a pair of escapes) is text like any other."""
    title = "façade \U0001f3e0"
    r = raw(as_alice, "PATCH", f"/api/v1/procedures/{world['procedure']}/", {"title": title})
    assert r.status_code == 200 and r.json()["title"] == title
    assert Procedure.objects.get(code=world["procedure"]).title == title


def test_the_pages_pasted_json_refuses_it_too(as_alice, world):
    seg = facade_png()[1]
    seg["rects"][0]["label"] = SURROGATE
    r = as_alice.post(f"/photos/{world['photo']}/segmentation", {"text": json.dumps(seg)}, follow=True)
    assert r.status_code == 200 and "rects[0].label holds an unpaired surrogate" in r.content.decode()
    assert Segmentation.objects.count() == 1


def test_the_renderer_writes_what_utf8_cannot():
    """Defence in depth: an answer holding an unpaired surrogate (from anywhere) is escaped JSON, not a 500."""
    assert JSONRenderer().render({"detail": f"\"{SURROGATE}\" is not a valid choice, façade"}) == \
        b'{"detail":"\\"\\ud800\\" is not a valid choice, fa\\u00e7ade"}'
    assert JSONRenderer().render({"detail": "façade"}) == '{"detail":"façade"}'.encode()


# --- booleans are true or false -------------------------------------------------------------------------------------

@pytest.mark.parametrize("bad", [0, 1, "true", "false", "yes", "on", None, [], {}])
def test_a_boolean_is_true_or_false_only(as_alice, alice, world, bad):
    code = world["procedure"]
    before = state()
    for path, body, field in ((f"/api/v1/procedures/{code}/", {"visibility": "public", "share_photo": bad},
                               "share_photo"),
                              (f"/api/v1/procedures/{code}/parameters", {"values": {}, "save": bad}, "save")):
        r = raw(as_alice, "PATCH" if field == "share_photo" else "POST", path, body)
        assert r.status_code == 400 and field in r.json(), (field, bad, r.status_code, r.content[:300])
        assert state() == before
    r = raw(as_alice, "PATCH", f"/api/v1/procedures/{code}/", {"visibility": "public", "share_photo": False})
    assert r.status_code == 200 and r.json()["visibility"] == "public"
    r = raw(as_alice, "POST", f"/api/v1/procedures/{code}/parameters", {"values": {}, "save": False})
    assert r.status_code == 200, r.content[:300]


_JSON = st.recursive(st.none() | st.booleans() | st.integers() | st.text(), lambda inner: st.lists(inner, max_size=4)
                     | st.dictionaries(st.text(max_size=5), inner, max_size=4), max_leaves=40)


@given(_JSON, st.integers(1, 8))
def test_the_quick_scan_passes_only_what_the_walk_passes(value, limit):
    """`plainly_fine` reads the text (brackets outside strings, surrogates written or escaped) in C-speed scans:
    whatever it passes, the walk over every value passes too (it may leave one to the walk, never pass a bad one)."""
    from webapp.facades.jsonbody import document_error, plainly_fine

    for text in (json.dumps(value), json.dumps(value, ensure_ascii=False)):
        if plainly_fine(text, limit):
            assert document_error(json.loads(text), limit) is None, text


def test_the_quick_scan_counts_brackets_outside_strings_only():
    from webapp.facades.jsonbody import plainly_fine

    assert plainly_fine('{"a": "[[[[[[[[[[{{{{{{{{{{", "b": [[1]]}', 3)
    assert not plainly_fine('{"a": [[[[1]]]]}', 3)
    assert not plainly_fine('{"a": "\\udfff"}') and not plainly_fine('["\\ud83d\\ude00"]')  # left to the walk
    assert plainly_fine('{"a": "\\\\[\\"]"}', 1)
    assert not plainly_fine('{"note":"\\ud800"}'.encode("utf-16-le"))  # read as UTF-8: NULs, escapes misread
