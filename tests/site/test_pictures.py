"""A procedure's pictures (labels.png and the gallery's thumbnail) are rendered when it is saved, kept in
storage under a digest of its tree, replaced when the tree changes, deleted with it, and served as files with
an ETag and a cache policy by visibility."""

from __future__ import annotations

import io

import pytest
from django.core.files.storage import default_storage
from PIL import Image

from facaid.generator import generate
from webapp.facades import picture_store
from webapp.facades.models import Procedure, tree_digest

pytestmark = pytest.mark.django_db


def kept(proc) -> list[str]:
    folder = f"pictures/{proc.code}"
    return sorted(default_storage.listdir(folder)[1]) if default_storage.exists(folder) else []


def test_pictures_are_kept_from_the_save_and_follow_the_tree(alice, as_alice, django_capture_on_commit_callbacks):
    tree = generate(3).procedure
    with django_capture_on_commit_callbacks(execute=True):  # rendered once the save commits
        proc = Procedure.objects.create(owner=alice, data=tree.to_dict())
    tag = tree_digest(proc.data)
    assert kept(proc) == [f"{tag}-labels.png", f"{tag}-thumbnail.png"]  # rendered by the save itself
    thumb = Image.open(default_storage.open(f"pictures/{proc.code}/{tag}-thumbnail.png"))
    assert max(thumb.size) == 320 and abs(thumb.width / thumb.height - tree.width / tree.height) < 0.02
    edited = generate(4).procedure.to_dict()
    with django_capture_on_commit_callbacks(execute=True):
        r = as_alice.patch(f"/api/v1/procedures/{proc.code}/", {"data": edited}, format="json")
    assert r.status_code == 200
    new = tree_digest(Procedure.objects.get(id=proc.id).data)
    assert new != tag and kept(proc) == [f"{new}-labels.png", f"{new}-thumbnail.png"]  # the old ones are gone
    with django_capture_on_commit_callbacks(execute=True):
        as_alice.patch(f"/api/v1/procedures/{proc.code}/", {"title": "renamed"}, format="json")
    assert kept(proc) == [f"{new}-labels.png", f"{new}-thumbnail.png"]
    r = as_alice.get(f"/api/v1/procedures/{proc.code}/download/labels.png")
    served = Image.open(io.BytesIO(r.getvalue()))
    assert r.status_code == 200 and served.size == (round(edited["width"]), round(edited["height"]))
    with django_capture_on_commit_callbacks(execute=True):
        as_alice.delete(f"/api/v1/procedures/{proc.code}/")
    assert kept(proc) == [] and not default_storage.exists(f"pictures/{proc.code}")


def test_a_missing_picture_is_rendered_on_its_first_request(alice, as_alice):
    proc = Procedure.objects.create(owner=alice, data=generate(5).procedure.to_dict())  # not committed: none kept
    assert kept(proc) == []
    r = as_alice.get(f"/api/v1/procedures/{proc.code}/thumbnail.png")
    assert r.status_code == 200 and r["Content-Type"] == "image/png" and len(kept(proc)) == 1
    again = as_alice.get(f"/api/v1/procedures/{proc.code}/thumbnail.png")
    assert again.getvalue() == r.content and again.streaming  # now served from the kept file


def test_refresh_keeps_the_pictures_of_the_committed_tree(alice):
    """Two saves' refreshes running late, in either order: the pictures left are those of the tree stored."""
    proc = Procedure.objects.create(owner=alice, data=generate(3).procedure.to_dict())
    first = tree_digest(proc.data)
    picture_store.refresh(proc.id)
    proc.data = generate(4).procedure.to_dict()
    proc.save()
    second = tree_digest(proc.data)
    picture_store.refresh(proc.id)
    picture_store.refresh(proc.id)  # the first save's refresh, late: it reads the stored tree, not its own
    assert kept(proc) == [f"{second}-labels.png", f"{second}-thumbnail.png"] and first != second


def test_a_procedure_stored_past_the_size_cap_is_scaled_by_the_migration(alice, as_alice):
    import importlib

    from django.apps import apps

    from facaid.grammar import Procedure as Tree

    deep = generate(4).procedure.to_dict()
    deep["root"]["sizes"] = [[m, 30_000.0 if m == "abs" else v] for m, v in deep["root"]["sizes"]]
    too_big = Procedure.objects.create(owner=alice, data=deep)  # an inner size past the cap, the facade not
    data = generate(3).procedure.to_dict()
    factor = 20_000 / data["width"]
    data["width"], data["height"] = 20_000, data["height"] * factor
    for node in [data["root"]]:
        node["sizes"] = [[m, v * factor if m == "abs" else v] for m, v in node.get("sizes", [])]
    proc = Procedure.objects.create(owner=alice, data=data)  # as stored before the cap (the model checks nothing)
    r = as_alice.get(f"/api/v1/procedures/{proc.code}/thumbnail.png")
    assert r.status_code == 400 and "cannot be drawn" in r.json()["data"]  # a 400 naming it, not a 500
    importlib.import_module("webapp.facades.migrations.0002_procedures_within_the_size_cap").scale_down(apps, None)
    scaled = Tree.from_dict(Procedure.objects.get(id=proc.id).data)
    shrink = 16384 / max(data["width"], data["height"])
    assert max(scaled.width, scaled.height) == 16384
    assert abs(scaled.width - data["width"] * shrink) < 1e-6 and abs(scaled.height - data["height"] * shrink) < 1e-6
    assert as_alice.get(f"/api/v1/procedures/{proc.code}/thumbnail.png").status_code == 200
    assert deep["root"]["sizes"][0][0] == "abs"
    Tree.from_dict(Procedure.objects.get(id=too_big.id).data)  # parses now
    assert Procedure.objects.get(id=too_big.id).accuracy is None


def test_pictures_are_cached_by_visibility_and_revalidated_by_digest(alice, as_alice, as_bob, as_charlie):
    private = Procedure.objects.create(owner=alice, data=generate(3).procedure.to_dict())
    public = Procedure.objects.create(owner=alice, data=generate(4).procedure.to_dict(), visibility="public")
    assert as_bob.get(f"/api/v1/procedures/{private.code}/thumbnail.png").status_code == 404
    assert as_charlie.get(f"/api/v1/procedures/{private.code}/thumbnail.png").status_code == 404
    r = as_alice.get(f"/api/v1/procedures/{private.code}/thumbnail.png")
    assert r["Cache-Control"] == "private, no-cache" and r["ETag"] == f'"{tree_digest(private.data)}"'
    r = as_charlie.get(f"/api/v1/procedures/{public.code}/thumbnail.png")
    assert r.status_code == 200 and r["Cache-Control"] == "public, max-age=60"
    again = as_charlie.get(f"/api/v1/procedures/{public.code}/thumbnail.png", HTTP_IF_NONE_MATCH=r["ETag"])
    assert again.status_code == 304 and not again.content
    stale = as_charlie.get(f"/api/v1/procedures/{public.code}/thumbnail.png", HTTP_IF_NONE_MATCH='"0123"')
    assert stale.status_code == 200


def test_gallery_cards_show_thumbnails(alice, as_charlie):
    proc = Procedure.objects.create(owner=alice, title="card", data=generate(3).procedure.to_dict(),
                                    visibility="public")
    page = as_charlie.get("/").content.decode()
    assert f"/api/v1/procedures/{proc.code}/thumbnail.png" in page


def test_a_picture_drawn_after_an_edit_is_filed_under_the_tree_it_shows(alice, as_alice):
    from webapp.facades import access

    proc = Procedure.objects.create(owner=alice, data=generate(3).procedure.to_dict())
    seen = access.get_procedure_picture_for_user(alice, proc.code)  # digest read, tree not
    proc.data = generate(4).procedure.to_dict()
    proc.save()  # an edit commits before the picture is drawn
    name, tag, png = picture_store.stored(seen, "thumbnail.png")
    assert tag == tree_digest(proc.data) and name.endswith(f"{tag}-thumbnail.png") and png
    r = as_alice.get(f"/api/v1/procedures/{proc.code}/thumbnail.png")
    assert r["ETag"] == f'"{tree_digest(proc.data)}"'
    Procedure.objects.filter(id=proc.id).delete()
    with pytest.raises(LookupError):
        picture_store.stored(seen, "labels.png")
