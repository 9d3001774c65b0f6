"""A procedure's lineage told only to those who may see it: a parent made private, or unlisted, is not named to others
(nor in the gallery, the public's view, which follows every change), and a public procedure does not name its
private photo."""

from __future__ import annotations

import pytest
from site_helpers import wall

from facaid.generator import generate
from webapp.facades.models import Photo, Procedure, Segmentation

pytestmark = pytest.mark.django_db


def test_a_parent_made_private_is_hidden_from_its_forks(alice, bob, as_alice, as_bob):
    original = Procedure.objects.create(owner=alice, title="Rivoli 12", data=wall(100, 100), visibility="public")
    fork = as_bob.post(f"/api/v1/procedures/{original.code}/fork").json()
    assert fork["parent"] == str(original.code)
    page = as_bob.get(f"/procedures/{fork['code']}").content.decode()
    assert "Rivoli 12" in page and str(original.code) in page
    as_alice.patch(f"/api/v1/procedures/{original.code}/", {"visibility": "private", "title": "Secret plan"},
                   format="json")
    page = as_bob.get(f"/procedures/{fork['code']}").content.decode()
    assert "Secret plan" not in page and str(original.code) not in page and "forked from" not in page
    assert as_bob.get(f"/api/v1/procedures/{fork['code']}/").json()["parent"] is None
    assert as_bob.get("/api/v1/procedures/").json()["results"][0]["parent"] is None
    # the fork's own copy is untouched, and alice still sees her own procedure's lineage where she may
    assert as_bob.get(f"/api/v1/procedures/{fork['code']}/").json()["title"] == "Fork of Rivoli 12"


def test_an_unlisted_parent_is_named_only_to_the_forks_owner(alice, bob, as_bob, as_charlie, django_user_model):
    original = Procedure.objects.create(owner=alice, title="by link", data=wall(100, 100), visibility="unlisted")
    fork = as_bob.post(f"/api/v1/procedures/{original.code}/fork").json()
    assert as_bob.get(f"/api/v1/procedures/{fork['code']}/").json()["parent"] == str(original.code)
    as_bob.patch(f"/api/v1/procedures/{fork['code']}/", {"visibility": "public"}, format="json")
    assert as_charlie.get(f"/api/v1/procedures/{fork['code']}/").json()["parent"] is None  # the link stays private
    assert as_charlie.get("/api/v1/gallery/").json()["results"][0]["parent"] is None
    page = as_charlie.get(f"/procedures/{fork['code']}").content.decode()
    assert str(original.code) not in page and "forked from" not in page  # (its title was copied by the fork)
    assert str(original.code) in as_bob.get(f"/procedures/{fork['code']}").content.decode()


def test_a_public_procedure_does_not_name_its_private_photo(facade_photo, alice, as_charlie, as_alice):
    photo, seg = facade_photo
    proc = Procedure.objects.create(owner=alice, data=generate(3).procedure.to_dict(), visibility="public",
                                    photo=Photo.objects.get(code=photo["code"]),
                                    segmentation=Segmentation.objects.get(code=seg["code"]))
    body = as_charlie.get(f"/api/v1/procedures/{proc.code}/").json()
    assert body["photo"] is None and body["segmentation"] is None
    body = as_alice.get(f"/api/v1/procedures/{proc.code}/").json()
    assert body["photo"] == photo["code"] and body["segmentation"] == seg["code"]


def test_the_gallery_is_the_publics_view_and_follows_every_change(alice, as_alice, as_charlie):
    parent = Procedure.objects.create(owner=alice, title="draft", data=wall(100, 100))  # private
    child = Procedure.objects.create(owner=alice, title="final", data=wall(100, 100), parent=parent,
                                     visibility="public")
    for client in (as_alice, as_charlie):  # the same listing for everyone: no private parent named
        assert client.get("/api/v1/gallery/").json()["results"][0]["parent"] is None
    assert as_alice.get(f"/api/v1/procedures/{child.code}/").json()["parent"] == str(parent.code)
    as_alice.patch(f"/api/v1/procedures/{child.code}/", {"title": "final, renamed"}, format="json")
    assert as_charlie.get("/api/v1/gallery/").json()["results"][0]["title"] == "final, renamed"
    parent.visibility = "public"
    parent.save()
    listed = {p["title"]: p["parent"] for p in as_charlie.get("/api/v1/gallery/").json()["results"]}
    assert listed == {"draft": None, "final, renamed": str(parent.code)}
    Procedure.objects.filter(id=parent.id).delete()
    assert [p["title"] for p in as_charlie.get("/api/v1/gallery/").json()["results"]] == ["final, renamed"]
