"""Versions of procedures: every save is a new version and none is lost; revert; compare with a difference picture
and both accuracies; figures fresh after each save; save as a new procedure with lineage; a re-run from a prefix
as a version with a warning when it fits worse; the access rules and bad input. (A version's named parameters and a
real facade's two readings are checked in `test_versions_parameters.py`; how versions are stored, migrations 0006
and 0007 and the quota, in `test_versions_storage.py`.)"""

from __future__ import annotations

import io
import json

import numpy as np
import pytest
from PIL import Image
from site_helpers import faithful_procedure, procedure_url, same_size_variant, version_history

from facaid.editing.variation import vary
from facaid.generator import generate
from facaid.grammar import Procedure as Tree
from facaid.metrics import measure
from facaid.segmentation import Segmentation as SegmentationData
from facaid.segmentation import flatten
from webapp.facades.drawing import DIFFERENT
from webapp.facades.models import Job, Procedure, ProcedureVersion, Segmentation

pytestmark = pytest.mark.django_db


def _faithful(alice, seg, **fields) -> Procedure:
    """Alice's procedure of the generated facade the photo shows, its own true tree (accuracy 1), titled as the
    lineage's titles below read."""
    return faithful_procedure(alice, seg, title="Rivoli", **fields)


def _edited_once(facade_photo, as_alice, alice) -> tuple[Procedure, dict, dict]:
    """The faithful procedure and a worse tree of its size saved over it: the procedure and its two versions."""
    _, seg = facade_photo
    proc = _faithful(alice, seg)
    as_alice.patch(procedure_url(proc), {"data": same_size_variant(proc.data)}, format="json")
    [v2, v1] = version_history(as_alice, proc)
    return proc, v2, v1


def test_a_save_is_a_new_version_and_the_first_is_unchanged(facade_photo, as_alice, alice):
    _, seg = facade_photo
    proc = _faithful(alice, seg)
    first = generate(3).procedure.to_dict()
    [v1] = version_history(as_alice, proc)
    assert v1["version"] == 1 and v1["kind"] == "created" and v1["picture"].endswith("/versions/1/labels.png")
    edited = same_size_variant(first)
    r = as_alice.patch(procedure_url(proc), {"data": edited}, format="json")
    assert r.status_code == 200 and r.json()["version"] == 2
    assert [v["version"] for v in version_history(as_alice, proc)] == [2, 1]
    again = as_alice.get(procedure_url(proc, "versions/1/")).json()
    assert again["data"] == first and again["digest"] == v1["digest"]  # version 1 is as it was
    assert as_alice.get(procedure_url(proc, "versions/2/")).json()["data"] == Tree.from_dict(edited).to_dict()
    # a title or visibility change alone records no version, and neither does the same tree saved again
    assert as_alice.patch(procedure_url(proc), {"title": "Rivoli 12", "visibility": "unlisted"}, format="json").json()[
        "version"] == 2
    for _ in range(20):
        assert as_alice.patch(procedure_url(proc), {"data": edited}, format="json").json()["version"] == 2
    for values in ({}, {"width": proc.data["width"]}):  # parameters set to what they are: the same tree
        r = as_alice.post(procedure_url(proc, "parameters"), {"values": values, "save": True}, format="json")
        assert r.status_code == 200 and r.json()["version"] == 2, r.content[:300]
    assert [v["version"] for v in version_history(as_alice, proc)] == [2, 1]
    r = as_alice.post(procedure_url(proc, "parameters"), {"values": {"width": proc.data["width"] + 10}, "save": True},
                      format="json")
    assert r.json()["version"] == 3


def test_figures_are_measured_again_on_every_save_and_never_left_stale(facade_photo, as_alice, alice):
    _, seg = facade_photo
    proc = _faithful(alice, seg, accuracy=0.5, metrics={"iou": {"window": 0.1}, "timings": {"decode": 1.0},
                                                          "source": "model"})
    worse = same_size_variant(proc.data)
    body = as_alice.patch(procedure_url(proc), {"data": worse}, format="json").json()
    accuracy, iou = measure(Tree.from_dict(worse), flatten(SegmentationData.from_dict(seg["data"])))
    assert body["accuracy"] == accuracy < 0.99 and body["metrics"]["iou"] == iou
    assert "timings" not in body["metrics"] and body["metrics"]["source"] == "model"  # the job's figures go
    assert as_alice.get(procedure_url(proc)).json()["accuracy"] == accuracy  # stored, not only answered
    assert version_history(as_alice, proc)[0]["accuracy"] == accuracy
    page = as_alice.get(f"/procedures/{proc.code}").content.decode()
    assert f"{100 * accuracy:.2f} %" in page and "50.00 %" not in page
    # a resized tree is not comparable with the segmentation: no figure, and a reason in its place
    resized = next(v.to_dict() for v in vary(Tree.from_dict(proc.data), 8, 0) if v.meta["variation"] == "resize")
    body = as_alice.patch(procedure_url(proc), {"data": resized}, format="json").json()
    assert body["accuracy"] is None and "iou" not in body["metrics"]
    assert body["metrics"]["unmeasured"].startswith(f"the tree is {round(resized['width'])}x")
    page = as_alice.get(f"/procedures/{proc.code}").content.decode()
    assert "not measured" in page and f"{100 * accuracy:.2f} %" not in page.split('id="history"')[0]


def test_revert_makes_a_new_version_equal_to_the_old_one(facade_photo, as_alice, alice):
    proc, v2, v1 = _edited_once(facade_photo, as_alice, alice)
    r = as_alice.post(procedure_url(proc, "versions/1/revert"))
    assert r.status_code == 201 and r.json()["version"] == 3
    v3 = as_alice.get(procedure_url(proc, "versions/3/")).json()
    assert v3["data"] == as_alice.get(procedure_url(proc, "versions/1/")).json()["data"] == r.json()["data"]
    assert v3["accuracy"] == v1["accuracy"] == pytest.approx(1.0) and v3["digest"] == v1["digest"]
    assert v3["kind"] == "revert" and v3["based_on"] == 1 and v3["note"] == "reverted to version 1"
    assert [v["version"] for v in version_history(as_alice, proc)] == [3, 2, 1]  # nothing deleted
    assert as_alice.get(procedure_url(proc, "versions/2/")).json()["digest"] == v2["digest"]
    r = as_alice.post(procedure_url(proc, "versions/1/revert"))  # the tree it holds now: nothing to do, said so
    assert r.status_code == 400 and "holds now" in r.json()["version"]
    assert ProcedureVersion.objects.filter(procedure=proc).count() == 3


def test_compare_two_versions_gives_both_accuracies_and_a_difference_picture(facade_photo, as_alice, alice):
    _, seg = facade_photo
    proc, v2, v1 = _edited_once(facade_photo, as_alice, alice)
    r = as_alice.get(procedure_url(proc, "versions/compare?a=1&b=2"))
    assert r.status_code == 200, r.content
    body = r.json()
    assert body["a"]["accuracy"] == v1["accuracy"] == pytest.approx(1.0)
    assert body["b"]["accuracy"] == v2["accuracy"] < 1.0 and body["segmentation"] == seg["code"]
    assert 0 < body["differing"] < 1 and body["differing_pixels"] == round(body["differing"] * body["pixels"])
    assert (body["a"]["width"], body["a"]["height"]) == (proc.data["width"], proc.data["height"])
    picture = as_alice.get(body["overlay"])
    assert picture.status_code == 200 and picture["Content-Type"] == "image/png"
    pixels = np.asarray(Image.open(io.BytesIO(picture.content)).convert("RGB"))
    assert pixels.shape[0] * pixels.shape[1] == body["pixels"]
    assert (pixels == DIFFERENT).all(axis=2).sum() == body["differing_pixels"]  # highlighted: those and no others
    same = as_alice.get(procedure_url(proc, "versions/compare?a=1&b=1")).json()
    assert same["differing_pixels"] == 0
    for n in (1, 2):
        png = as_alice.get(procedure_url(proc, f"versions/{n}/labels.png"))
        assert png.status_code == 200 and png["ETag"] == f'"{body["ab"[n - 1]]["digest"]}"'
        assert as_alice.get(procedure_url(proc, f"versions/{n}/labels.png"),
                            HTTP_IF_NONE_MATCH=png["ETag"]).status_code == 304


def test_bad_input_is_a_clear_4xx_and_changes_nothing(facade_photo, as_alice, as_bob, as_charlie, alice):
    _, seg = facade_photo
    proc = _faithful(alice, seg)
    for path in ("versions/9/", "versions/0/", "versions/abc/", "versions/1e3/labels.png", "versions/-1/revert"):
        r = (as_alice.post(procedure_url(proc, path)) if path.endswith("revert")
             else as_alice.get(procedure_url(proc, path)))
        assert r.status_code == 404, path
    assert "it has versions 1 to 1" in as_alice.get(procedure_url(proc, "versions/9/")).json()["detail"]
    assert as_alice.post(procedure_url(proc, "versions/9/revert")).status_code == 404
    for query, field in (("a=1", "b"), ("a=x&b=1", "a"), ("a=1&b=7", "b"), ("a=1&b=" + "9" * 30, "b")):
        r = as_alice.get(procedure_url(proc, f"versions/compare?{query}"))
        assert r.status_code == 400 and field in r.json(), (query, r.content)
    bad = generate(3).procedure.to_dict()
    bad["root"]["rule"] = "explode"
    r = as_alice.patch(procedure_url(proc), {"data": bad}, format="json")
    assert r.status_code == 400 and "explode" in json.dumps(r.json())
    r = as_alice.post(procedure_url(proc, "save-as-new"), {"data": bad}, format="json")
    assert r.status_code == 400 and "explode" in json.dumps(r.json())
    assert as_alice.post(procedure_url(proc, "save-as-new"), {"title": 5}, format="json").status_code == 400
    # someone else's private procedure is not there; a visible one's history is theirs to read, not to change
    assert as_bob.get(procedure_url(proc, "versions/")).status_code == 404
    assert as_bob.post(procedure_url(proc, "versions/1/revert")).status_code == 404
    assert as_bob.get(procedure_url(proc, "versions/compare?a=1&b=1")).status_code == 404
    assert as_bob.post(procedure_url(proc, "save-as-new"), {}, format="json").status_code == 404
    as_alice.patch(procedure_url(proc), {"data": same_size_variant(proc.data), "visibility": "public"}, format="json")
    assert [v["version"] for v in version_history(as_bob, proc)] == [2, 1] == [v["version"] for v in
                                                                        version_history(as_charlie, proc)]
    assert as_charlie.get(procedure_url(proc, "versions/compare?a=1&b=2")).status_code == 200
    assert as_bob.post(procedure_url(proc, "versions/1/revert")).status_code == 403
    assert as_charlie.post(procedure_url(proc, "versions/1/revert")).status_code in (401, 403)
    assert as_bob.patch(procedure_url(proc), {"data": generate(3).procedure.to_dict()},
                        format="json").status_code == 403
    assert ProcedureVersion.objects.filter(procedure=proc).count() == 2
    assert Procedure.objects.count() == 1


def test_save_as_new_and_saved_variations_have_lineage_and_titles_of_their_own(facade_photo, as_alice, as_bob,
                                                                               alice):
    _, seg = facade_photo
    proc = _faithful(alice, seg, visibility="public")
    variant = same_size_variant(proc.data)
    r = as_alice.post(procedure_url(proc, "save-as-new"), {"data": variant}, format="json")
    assert r.status_code == 201, r.content
    copy = r.json()
    assert copy["parent"] == str(proc.code) and copy["owner"] == "alice" and copy["visibility"] == "private"
    assert copy["title"] == "Rivoli · swap variant (seed 0, #{})".format(variant["meta"]["variation_index"] + 1)
    # issue 68: it starts at version 1, the variation, which says whence it came
    assert copy["version"] == 1 and copy["data"] == Tree.from_dict(variant).to_dict()
    accuracy, _ = measure(Tree.from_dict(variant), flatten(SegmentationData.from_dict(seg["data"])))
    assert copy["accuracy"] == accuracy and copy["segmentation"] == seg["code"]  # her photo: measured against it
    copies = Procedure.objects.get(code=copy["code"])
    assert [v.data for v in copies.versions.order_by("version")] == [copy["data"]]
    first = copies.versions.get(version=1)
    assert first.note == "saved from a variation of version 1 of “Rivoli”" and first.kind == "created"
    assert first.accuracy == accuracy and copies.metrics["edits"]
    plain = as_alice.post(procedure_url(proc, "save-as-new"), {}, format="json").json()
    assert plain["title"] == "Rivoli · variant 2" and plain["version"] == 1 and plain["data"] == proc.data
    assert version_history(as_alice, Procedure.objects.get(code=plain["code"]))[0]["note"] == \
        "saved as a new procedure from version 1 of “Rivoli”"
    unedited = as_alice.post(procedure_url(proc, "save-as-new"), {"data": proc.data},
                             format="json").json()  # as the page
    assert version_history(as_alice, Procedure.objects.get(code=unedited["code"]))[0]["note"] == \
        "saved as a new procedure from version 1 of “Rivoli”"  # sends it, not edited: no edit is said
    fork = as_bob.post(procedure_url(proc, "fork"), {}, format="json").json()
    assert version_history(as_bob, Procedure.objects.get(code=fork["code"]))[0]["note"] == (
        "forked from version 1 of “Rivoli”")
    named = as_alice.post(procedure_url(proc, "save-as-new"), {"title": "Rivoli, five floors"}, format="json").json()
    assert named["title"] == "Rivoli, five floors"
    assert Procedure.objects.get(id=proc.id).data == proc.data  # the original is untouched
    assert [v["version"] for v in version_history(as_alice, proc)] == [1]
    theirs = as_bob.post(procedure_url(proc, "save-as-new"), {"data": variant}, format="json").json()
    assert theirs["owner"] == "bob" and theirs["parent"] == str(proc.code)
    assert theirs["title"].startswith("Rivoli · swap variant")


def test_a_re_run_from_a_prefix_is_a_new_version_with_a_warning_when_it_fits_worse(facade_photo, as_alice, alice,
                                                                                  monkeypatch):
    """The job runs in this process, as the worker runs it (`tasks.run_job`), with the shipped model."""
    from worker import tasks

    monkeypatch.setenv("FACAID_HEARTBEAT_SECONDS", "3600")  # the progress beats are enough here
    _, seg = facade_photo
    proc = _faithful(alice, seg)

    def rerun(nodes: int) -> Job:
        r = as_alice.post(procedure_url(proc, "rerun"), {"nodes": nodes, "k": 1}, format="json")
        assert r.status_code == 202, r.content
        job = Job.objects.get(code=r.json()["code"])
        tasks.run_job.apply(args=[job.id])
        job.refresh_from_db()
        assert job.status == "done", job.message
        return job

    job = rerun(1)  # continuing the true tree from its root: the model's own sizes fit a little worse
    assert job.result_id == proc.id and job.result_version == 2 and job.params["as_version"] is True
    assert Procedure.objects.count() == 1  # a version of this procedure, not a fork with the same title
    [v2, v1] = version_history(as_alice, proc)
    assert v2["kind"] == "rerun" and v2["based_on"] == 1 and v1["accuracy"] == pytest.approx(1.0)
    assert v2["accuracy"] < v1["accuracy"] and v2["metrics"]["source"] in ("model", "model+repair", "induced")
    assert v2["warning"].startswith("This re-run fits worse than version 1: pixel accuracy")
    assert as_alice.get(f"/api/v1/jobs/{job.code}/").json()["result_version"] == 2
    page = as_alice.get(f"/procedures/{proc.code}").content.decode()
    assert 'id="rerun-warning"' in page and "fits worse than version 1" in page and 'data-compare="1,2"' in page
    # kept or reverted: a revert brings version 1 back as version 3
    assert as_alice.post(procedure_url(proc, "versions/1/revert")).json()["accuracy"] == pytest.approx(1.0)
    assert 'id="rerun-warning"' not in as_alice.get(f"/procedures/{proc.code}").content.decode()
    # from a tree that fits badly, a re-run that fits better says nothing
    as_alice.patch(procedure_url(proc), {"data": same_size_variant(proc.data)}, format="json")
    job = rerun(1)
    [v5, v4] = version_history(as_alice, proc)[:2]
    assert job.result_version == 5 and v5["based_on"] == 4 and v5["accuracy"] > v4["accuracy"]
    assert v5["warning"] == ""


def test_a_re_run_of_someone_elses_procedure_is_a_new_procedure_told_apart(facade_photo, as_alice, as_bob, alice,
                                                                          bob):
    from webapp.facades.services.jobs import submit_job

    _, seg = facade_photo
    proc = _faithful(alice, seg, visibility="public")
    mine = submit_job(alice, Segmentation.objects.get(code=seg["code"]), prefix=proc, prefix_nodes=2)
    assert mine.params["as_version"] is True and mine.params["prefix_version"] == 1
    newer = as_alice.post(f"/api/v1/photos/{seg['photo']}/segmentations/", seg["data"], format="json").json()
    other = submit_job(alice, Segmentation.objects.get(code=newer["code"]), prefix=proc, prefix_nodes=2)
    assert other.params["as_version"] is False  # another segmentation: its figures would not compare
