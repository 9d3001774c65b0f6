"""A version's named parameters and variations through the API (listed, set, saved as the next version, bad names
and values a 400 naming them), and a real facade's two readings stored as versions: the editable one current, the
exact one version 1, the parameters editing the editable one."""

from __future__ import annotations

import json

import pytest
from site_helpers import faithful_procedure, procedure_url, version_history

from facaid.generator import generate
from facaid.grammar import Procedure as Tree
from facaid.grammar import to_segmentation
from facaid.labels import LABELS
from webapp.facades.models import Job, Procedure

pytestmark = pytest.mark.django_db


def test_named_parameters_through_the_api(facade_photo, as_alice, as_bob, alice):
    """GET lists the named parameters; POST sets them (returned only, or saved as the next version with a fresh
    accuracy); bad names and values are a 400 naming them, and another user cannot save."""
    _, seg = facade_photo
    proc = faithful_procedure(alice, seg, visibility="public")
    r = as_alice.get(procedure_url(proc, "parameters"))
    assert r.status_code == 200, r.content
    floors = {p["name"]: p for p in r.json()["parameters"]}["floors"]
    assert floors["integer"] and floors["nodes"]
    # where each element is drawn, with its node: the rectangles of the executed tree, background left out
    tree = Tree.from_dict(proc.data)
    drawn = [r for r in to_segmentation(tree).rects if LABELS[r.label] != "background"]
    leaves = r.json()["leaves"]
    nodes = dict(tree.nodes())
    assert len(leaves) == len(drawn) and all(leaf[5] in nodes and nodes[leaf[5]].label == leaf[0] for leaf in leaves)
    assert sorted(tuple(leaf[1:5]) for leaf in leaves if leaf[0] != "facade") == sorted(
        (r.x0, r.y0, r.x1, r.y1) for r in drawn if LABELS[r.label] != "facade")
    target = floors["value"] + 1
    r = as_alice.post(procedure_url(proc, "parameters"), {"values": {"floors": target}}, format="json")
    assert r.status_code == 200, r.content
    body = r.json()
    assert {p["name"]: p["value"] for p in body["parameters"]}["floors"] == target
    assert body["version"] is None and len(version_history(as_alice, proc)) == 1  # not saved
    r = as_alice.post(procedure_url(proc, "parameters"), {"values": {"floors": target}, "save": True}, format="json")
    assert r.status_code == 200, r.content
    saved = r.json()
    assert saved["version"] == 2, saved
    # a taller facade than its segmentation: measured again on save, and said to be unmeasurable, never stale
    assert saved["accuracy"] is None and "its segmentation is" in saved["metrics"]["unmeasured"]
    [v2, v1] = version_history(as_alice, proc)
    assert v2["kind"] == "edit" and "floors" in v2["note"] and v1["version"] == 1
    proc.refresh_from_db()
    assert proc.data["height"] > generate(3).procedure.height and proc.accuracy is None
    for bad, word in (({"values": {"storeys": 3}}, "storeys"), ({"values": {"floors": 0}}, "floors"),
                      ({"values": {"floors": "x"}}, "values"), ({}, "values")):
        r = as_alice.post(procedure_url(proc, "parameters"), bad, format="json")
        assert r.status_code == 400 and word in json.dumps(r.json()), (bad, r.content)
    r = as_bob.post(procedure_url(proc, "parameters"), {"values": {"floors": target}, "save": True}, format="json")
    assert r.status_code in (403, 404) and len(version_history(as_alice, proc)) == 2


def test_variations_by_named_ranges_through_the_api(facade_photo, as_alice, alice):
    _, seg = facade_photo
    proc = faithful_procedure(alice, seg)
    r = as_alice.post(procedure_url(proc, "variations"), {"n": 4, "seed": 1, "ranges": {"floors": [2, 3]}},
                      format="json")
    assert r.status_code == 200, r.content
    variants = r.json()["variants"]
    assert len(variants) == 4 and {v["meta"]["parameters"]["floors"] for v in variants} <= {2, 3}
    for bad in ({"ranges": {"storeys": [1, 2]}}, {"ranges": {"floors": [1]}}, {"ranges": {"floors": [3, 2]}}):
        r = as_alice.post(procedure_url(proc, "variations"), bad, format="json")
        assert r.status_code == 400 and "ranges" in r.json(), (bad, r.content)


def _real_like_job(client, structure: str | None = None) -> tuple[Procedure, Job]:
    """A photo of a real-like facade (drawn as people draw CMP's), reconstructed in this process as the worker does
    it, with the shipped model."""
    import io

    from grammar_helpers import real_like

    from facaid.formats.render import render_segmentation
    from tests.site.site_helpers import upload
    from worker import tasks

    seg = real_like()
    out = io.BytesIO()
    render_segmentation(seg).save(out, "PNG")
    photo = upload(client, out.getvalue(), title="Real-like").json()
    made = client.post(f"/api/v1/photos/{photo['code']}/segmentations/", seg.to_dict(), format="json").json()
    body = {"segmentation": made["code"], "k": 2} | ({"structure": structure} if structure else {})
    r = client.post("/api/v1/jobs/", body, format="json")
    assert r.status_code == 202, r.content
    job = Job.objects.get(code=r.json()["code"])
    tasks.run_job.apply(args=[job.id])
    job.refresh_from_db()
    assert job.status == "done", job.message
    return Procedure.objects.get(id=job.result_id), job


def test_a_real_facade_gets_both_procedures_the_editable_one_current(as_alice, monkeypatch):
    """The editable reading is the current version, the exact one version 1; the page names both with their
    accuracies and switches between them by a revert; the parameters edit the editable one."""
    monkeypatch.setenv("FACAID_HEARTBEAT_SECONDS", "3600")
    proc, job = _real_like_job(as_alice)
    assert job.result_version == 2
    [v2, v1] = version_history(as_alice, proc)
    assert (v1["metrics"]["structure"], v2["metrics"]["structure"]) == ("exact", "editable")
    assert v2["metrics"]["source"] == "lattice" and v1["accuracy"] > v2["accuracy"] > 0.94
    assert v2["note"].startswith("editable: floors of tiles") and v1["note"] == "exact: the annotation as drawn"
    # the worker checked both trees' edits as it stored them (issue 67), each record naming its own tree
    assert [v["metrics"]["edits"]["digest"] for v in (v1, v2)] == [v1["digest"], v2["digest"]]
    assert v2["metrics"]["edits"]["verdicts"].keys() == {"floors+1", "floors-1", "bays+1", "bays-1"}
    params = {p["name"]: p for p in as_alice.get(procedure_url(proc, "parameters")).json()["parameters"]}
    assert params["floors"]["value"] == 5 and params["bays"]["value"] == 6
    assert params["floors"]["checked"] == all(v["clean"] for k, v in v2["metrics"]["edits"]["verdicts"].items()
                                              if k.startswith("floors"))
    page = as_alice.get(f"/procedures/{proc.code}").content.decode()
    assert "editable structure: floors of tiles with exceptions" in page
    assert 'id="other-structure"' in page and "The exact procedure (pixel accuracy" in page
    assert 'data-revert="1" id="switch-structure"' in page and "Switch to the exact one" in page
    assert as_alice.post(procedure_url(proc, "versions/1/revert")).status_code in (200, 201)
    page = as_alice.get(f"/procedures/{proc.code}").content.decode()
    assert "exact structure: the annotation as drawn" in page and "Switch to the editable one" in page


def test_the_exact_procedure_first_when_asked(as_alice, monkeypatch):
    monkeypatch.setenv("FACAID_HEARTBEAT_SECONDS", "3600")
    proc, job = _real_like_job(as_alice, "exact")
    [v2, v1] = version_history(as_alice, proc)
    assert (v1["metrics"]["structure"], v2["metrics"]["structure"]) == ("editable", "exact")
    assert job.params["structure"] == "exact"
