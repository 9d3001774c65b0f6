"""Permissions with three users: alice owns, bob is another user, charlie is anonymous."""

import pytest

from webapp.facades.models import Job, Procedure

pytestmark = pytest.mark.django_db


def make_procedure(photo, seg, owner, visibility="private"):
    from facaid.generator import generate

    return Procedure.objects.create(owner=owner, title="p", data=generate(3).procedure.to_dict(),
                                    photo_id=photo, segmentation_id=seg, visibility=visibility)


@pytest.fixture
def objects(facade_photo, alice):
    from webapp.facades.models import Photo, Segmentation

    photo = Photo.objects.get(code=facade_photo[0]["code"])
    seg = Segmentation.objects.get(code=facade_photo[1]["code"])
    proc = make_procedure(photo.id, seg.id, alice)
    job = Job.objects.create(owner=alice, segmentation=seg)
    return photo, seg, proc, job


def urls(photo, seg, proc, job):
    return [f"/api/v1/photos/{photo.code}/", f"/api/v1/photos/{photo.code}/image",
            f"/api/v1/photos/{photo.code}/segmentations/", f"/api/v1/segmentations/{seg.code}/",
            f"/api/v1/procedures/{proc.code}/", f"/api/v1/procedures/{proc.code}/download/procedure.json",
            f"/photos/{photo.code}", f"/procedures/{proc.code}"]


def test_private_objects_are_404_to_others_and_200_to_the_owner(objects, as_alice, as_bob, as_charlie):
    photo, seg, proc, job = objects
    for url in urls(*objects):
        assert as_alice.get(url).status_code == 200, url
        assert as_bob.get(url).status_code == 404, url
        assert as_charlie.get(url).status_code == 404, url
    for client in (as_bob, as_charlie):
        assert client.get(f"/api/v1/jobs/{job.code}/").status_code == 404
        assert client.get(f"/jobs/{job.code}").status_code in (302, 404)
        assert client.patch(f"/api/v1/procedures/{proc.code}/", {"title": "x"}, format="json").status_code in (
            403, 404)
        assert client.delete(f"/api/v1/photos/{photo.code}/").status_code in (403, 404)
    assert as_alice.get(f"/api/v1/jobs/{job.code}/").status_code == 200
    assert as_bob.get("/api/v1/photos/not-a-uuid/").status_code == 404


def test_public_objects_are_readable_but_only_the_owner_changes_them(objects, as_alice, as_bob, as_charlie):
    photo, seg, proc, job = objects
    assert as_alice.patch(f"/api/v1/photos/{photo.code}/", {"visibility": "public"}, format="json").status_code == 200
    assert as_alice.patch(f"/api/v1/procedures/{proc.code}/", {"visibility": "public"},
                          format="json").status_code == 200
    for url in urls(*objects)[:-2]:
        assert as_bob.get(url).status_code == 200, url
        assert as_charlie.get(url).status_code == 200, url
    assert as_bob.patch(f"/api/v1/procedures/{proc.code}/", {"title": "mine"}, format="json").status_code == 403
    assert as_bob.delete(f"/api/v1/photos/{photo.code}/").status_code == 403
    assert as_charlie.patch(f"/api/v1/procedures/{proc.code}/", {"title": "x"}, format="json").status_code in (
        401, 403)
    r = as_bob.post(f"/api/v1/photos/{photo.code}/segmentations/", seg.data, format="json")
    assert r.status_code == 403
    # the gallery lists public procedures only; unlisted ones are reachable by link but not listed
    assert [p["code"] for p in as_charlie.get("/api/v1/gallery/").json()["results"]] == [str(proc.code)]
    as_alice.patch(f"/api/v1/procedures/{proc.code}/", {"visibility": "unlisted"}, format="json")
    assert as_charlie.get("/api/v1/gallery/").json()["count"] == 0
    assert as_charlie.get(f"/api/v1/procedures/{proc.code}/").status_code == 200


def test_fork_makes_a_private_copy_with_lineage(objects, as_alice, as_bob):
    photo, seg, proc, job = objects
    assert as_bob.post(f"/api/v1/procedures/{proc.code}/fork").status_code == 404  # private
    as_alice.patch(f"/api/v1/procedures/{proc.code}/", {"visibility": "public"}, format="json")
    r = as_bob.post(f"/api/v1/procedures/{proc.code}/fork")
    assert r.status_code == 201
    fork = r.json()
    assert fork["owner"] == "bob" and fork["parent"] == str(proc.code) and fork["visibility"] == "private"
    assert fork["photo"] is None  # alice's photo is not bob's
    assert fork["data"] == proc.data
    r2 = as_bob.post(f"/api/v1/procedures/{fork['code']}/fork").json()
    page = as_bob.get(f"/procedures/{r2['code']}").content.decode()
    assert str(proc.code) in page and fork["code"] in page  # lineage shown
    assert as_bob.patch(f"/api/v1/procedures/{fork['code']}/", {"title": "bob's"}, format="json").status_code == 200


def test_lists_show_only_your_own(objects, as_alice, as_bob):
    assert as_alice.get("/api/v1/photos/").json()["count"] == 1
    assert as_bob.get("/api/v1/photos/").json()["count"] == 0
    assert as_bob.get("/api/v1/procedures/").json()["count"] == 0
    assert as_bob.get("/api/v1/jobs/").json()["count"] == 0
