"""An account's storage quota counts what is stored (issue 66): its photos' files (original and rectified), its
segmentations and drafts as JSON, its procedures' current trees as JSON and their versions compressed. A write
past it is a 400 that says how much is used by what, and nothing is written."""

from __future__ import annotations

import json

import pytest
from site_helpers import facade_png, image_bytes, upload

from facaid.generator import generate
from webapp.facades.fields import pack
from webapp.facades.models import Draft, Photo, Procedure, ProcedureVersion, Segmentation, json_size, stored_bytes

pytestmark = pytest.mark.django_db


def quota_at(settings, owner, room: int) -> None:
    """The quota set to what ``owner`` stores now and ``room`` bytes more."""
    settings.FACAID_STORAGE_QUOTA_MB = (sum(stored_bytes(owner.pk).values()) + room) / 2**20


def test_what_is_stored_is_what_is_counted(facade_photo, as_alice, alice):
    photo, seg = facade_photo
    row = Photo.objects.get(code=photo["code"])
    assert row.stored_bytes == row.image.size > 0
    tree = generate(3).procedure.to_dict()
    proc = as_alice.post("/api/v1/procedures/", {"data": tree}, format="json").json()
    for seed in (4, 5):
        assert as_alice.patch(f"/api/v1/procedures/{proc['code']}/", {"data": generate(seed).procedure.to_dict()},
                              format="json").status_code == 200
    stored = Procedure.objects.get(code=proc["code"])
    versions = ProcedureVersion.objects.filter(procedure=stored)
    assert stored.data_size == json_size(stored.data) == len(json.dumps(stored.data, separators=(",", ":")))
    assert stored_bytes(alice.pk) == {
        "photos": row.image.size,
        "segmentations": Segmentation.objects.get(code=seg["code"]).size,
        "procedures": stored.data_size + sum(len(pack(v.data)) for v in versions)}
    assert Segmentation.objects.get(code=seg["code"]).size == json_size(Segmentation.objects.get(code=seg["code"]).data)


def test_photos_past_the_quota_are_refused_and_nothing_is_written(as_alice, alice, settings, tmp_path):
    first = upload(as_alice, image_bytes(size=(400, 300)))
    assert first.status_code == 201
    quota_at(settings, alice, 100)
    r = upload(as_alice, image_bytes(size=(400, 300), color=(10, 200, 30)))
    assert r.status_code == 400 and "your account stores" in r.json()["detail"] and "photos 0.0 MB" in \
        r.json()["detail"] and "nothing was saved" in r.json()["detail"]
    assert Photo.objects.count() == 1
    files = [p for p in (tmp_path / "media").rglob("*") if p.is_file()]
    assert len(files) == 1  # the first photo's file only
    r = as_alice.post("/photos/new", {"image": __import__("io").BytesIO(image_bytes(size=(400, 300))),
                                      "title": "t", "visibility": "private"})
    assert r.status_code == 400 and "your account stores" in r.content.decode()


def test_rectifying_counts_the_new_image_in_place_of_the_old(as_alice, alice, settings):
    photo = upload(as_alice, image_bytes(size=(400, 300))).json()
    corners = {"corners": [[10, 10], [390, 5], [395, 295], [5, 290]]}
    url = f"/api/v1/photos/{photo['code']}/rectify"
    assert as_alice.post(url, corners, format="json").status_code == 200
    row = Photo.objects.get(code=photo["code"])
    assert row.stored_bytes == row.image.size + row.rectified.size
    quota_at(settings, alice, 0)  # full: a rectification of the same size again replaces what it stores
    assert as_alice.post(url, corners, format="json").status_code == 200
    quota_at(settings, alice, -1)
    r = as_alice.post(url, {"corners": [[0, 0], [400, 0], [400, 300], [0, 300]]}, format="json")
    assert r.status_code == 400 and "your account stores" in r.json()["detail"]


def test_segmentations_and_drafts_past_the_quota_are_refused(facade_photo, as_alice, alice, settings):
    photo, _ = facade_photo
    _, seg = facade_png(3)  # the photo's own size
    url = f"/api/v1/photos/{photo['code']}"
    assert as_alice.put(f"{url}/draft", seg, format="json").status_code == 200
    assert Draft.objects.get().size == json_size(Draft.objects.get().data)
    quota_at(settings, alice, 0)
    r = as_alice.put(f"{url}/draft", seg, format="json")
    assert r.status_code == 200, r.content  # in place of itself
    assert as_alice.post(f"{url}/segmentations/", seg, format="json").status_code == 201  # the draft it replaces
    versions = Segmentation.objects.count()
    r = as_alice.post(f"{url}/segmentations/", seg, format="json")
    assert r.status_code == 400 and "segmentations" in r.json()["detail"] and Segmentation.objects.count() == versions
    r = as_alice.put(f"{url}/draft", seg, format="json")
    assert r.status_code == 400 and not Draft.objects.exists()


def test_a_large_tree_counts_as_stored_not_as_compressed(as_alice, alice, settings):
    """The probe stored a 401 KB tree 30 times: 14.5 MB stored, 0.04 MB counted. Each save now counts its current
    tree as written, and a save past the quota changes nothing."""
    tree = generate(3).procedure.to_dict()
    tree["meta"] = {"notes": "x" * 60_000}  # a big tree that compresses well
    proc = as_alice.post("/api/v1/procedures/", {"data": tree}, format="json").json()
    stored = Procedure.objects.get(code=proc["code"])
    assert stored.data_size > 60_000 and stored_bytes(alice.pk)["procedures"] > 60_000
    quota_at(settings, alice, 30_000)
    r = as_alice.post("/api/v1/procedures/", {"data": tree}, format="json")
    assert r.status_code == 400 and "procedures" in r.json()["detail"]
    assert Procedure.objects.count() == 1


@pytest.mark.django_db(transaction=True)
def test_migration_0008_measures_what_every_row_stores(alice, tmp_path):
    from django.core.files.base import ContentFile
    from django.core.files.storage import default_storage
    from django.db import connection
    from django.db.migrations.executor import MigrationExecutor

    before = [("facades", "0007_compressed_versions")]
    executor = MigrationExecutor(connection)
    executor.migrate(before)
    old = executor.loader.project_state(before).apps
    name = default_storage.save("photos/p.png", ContentFile(image_bytes(size=(64, 48))))
    photo = old.get_model("facades", "Photo").objects.create(owner_id=alice.id, title="p", image=name, width=64,
                                                             height=48)
    _, data = facade_png(3)
    seg = old.get_model("facades", "Segmentation").objects.create(photo_id=photo.id, version=1, data=data)
    tree = generate(3).procedure.to_dict()
    proc = old.get_model("facades", "Procedure").objects.create(owner_id=alice.id, data=tree, digest="x")
    executor = MigrationExecutor(connection)
    executor.loader.build_graph()
    executor.migrate(executor.loader.graph.leaf_nodes())
    assert Photo.objects.get(id=photo.id).stored_bytes == len(image_bytes(size=(64, 48))) > 0
    assert Segmentation.objects.get(id=seg.id).size == json_size(data)
    assert Procedure.objects.get(id=proc.id).data_size == json_size(tree)
