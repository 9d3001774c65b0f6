"""A procedure's pictures (labels.png and the gallery's thumbnail) are rendered when it is saved, kept in
storage under a digest of its tree, replaced when the tree changes, deleted with it, and served as files with
an ETag and a cache policy by visibility."""

from __future__ import annotations

import io

import pytest
from django.core.files.storage import default_storage
from PIL import Image

from facaid.generator import generate
from webapp.facades import pictures
from webapp.facades.models import Procedure

pytestmark = pytest.mark.django_db


def kept(proc) -> list[str]:
    folder = f"pictures/{proc.code}"
    return sorted(default_storage.listdir(folder)[1]) if default_storage.exists(folder) else []


def test_pictures_are_kept_from_the_save_and_follow_the_tree(alice, as_alice):
    tree = generate(3).procedure
    proc = Procedure.objects.create(owner=alice, data=tree.to_dict())
    tag = pictures.digest(proc.data)
    assert kept(proc) == [f"{tag}-labels.png", f"{tag}-thumbnail.png"]  # rendered by the save itself
    thumb = Image.open(default_storage.open(f"pictures/{proc.code}/{tag}-thumbnail.png"))
    assert max(thumb.size) == 320 and abs(thumb.width / thumb.height - tree.width / tree.height) < 0.02
    edited = generate(4).procedure.to_dict()
    assert as_alice.patch(f"/api/v1/procedures/{proc.code}/", {"data": edited}, format="json").status_code == 200
    new = pictures.digest(Procedure.objects.get(id=proc.id).data)
    assert new != tag and kept(proc) == [f"{new}-labels.png", f"{new}-thumbnail.png"]  # the old ones are gone
    as_alice.patch(f"/api/v1/procedures/{proc.code}/", {"title": "renamed"}, format="json")
    assert kept(proc) == [f"{new}-labels.png", f"{new}-thumbnail.png"]
    r = as_alice.get(f"/api/v1/procedures/{proc.code}/download/labels.png")
    served = Image.open(io.BytesIO(r.getvalue()))
    assert r.status_code == 200 and served.size == (round(edited["width"]), round(edited["height"]))
    as_alice.delete(f"/api/v1/procedures/{proc.code}/")
    assert kept(proc) == []


def test_a_missing_picture_is_rendered_on_its_first_request(alice, as_alice):
    proc = Procedure.objects.create(owner=alice, data=generate(5).procedure.to_dict())
    for name in kept(proc):
        default_storage.delete(f"pictures/{proc.code}/{name}")
    r = as_alice.get(f"/api/v1/procedures/{proc.code}/thumbnail.png")
    assert r.status_code == 200 and r["Content-Type"] == "image/png" and len(kept(proc)) == 1


def test_pictures_are_cached_by_visibility_and_revalidated_by_digest(alice, as_alice, as_bob, as_charlie):
    private = Procedure.objects.create(owner=alice, data=generate(3).procedure.to_dict())
    public = Procedure.objects.create(owner=alice, data=generate(4).procedure.to_dict(), visibility="public")
    assert as_bob.get(f"/api/v1/procedures/{private.code}/thumbnail.png").status_code == 404
    assert as_charlie.get(f"/api/v1/procedures/{private.code}/thumbnail.png").status_code == 404
    r = as_alice.get(f"/api/v1/procedures/{private.code}/thumbnail.png")
    assert r["Cache-Control"] == "private, no-cache" and r["ETag"] == f'"{pictures.digest(private.data)}"'
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
