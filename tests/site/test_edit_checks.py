"""The product checks its own edits (issue 67, item 4): every tree the site writes keeps the verdicts of floors ± 1
and bays ± 1 with its digest (`webapp.facades.editcheck`); the API says of each named parameter whether it is
checked; variations leave out the counts whose edits are not clean unless asked; a tree too costly to check, a
request without the budget for it and a check that fails are "not checked" with the reason, never a 500; a record of
another tree is never shown."""

from __future__ import annotations

import json
import time

import pytest
from grammar_helpers import doc

from facaid.editing.check import Verdict, check_edits
from facaid.editing.parameters import named_parameters
from facaid.editing.variation import vary
from facaid.generator import generate
from facaid.grammar import Procedure as Tree
from facaid.grammar.layout import count_expansion
from webapp.facades import editcheck
from webapp.facades.models import Procedure

pytestmark = pytest.mark.django_db

UNCLEAN = "the new floor is like no floor of the facade (at best 82 % alike, 90 % needed)"


def fake_verdicts() -> dict[str, Verdict]:
    return {"floors+1": Verdict(False, UNCLEAN, 0.99, 0.82, 120),
            "floors-1": Verdict(True, "one floor like the others taken out", 0.99, 0.97, 120),
            "bays+1": Verdict(True, "one bay like the others put in between two", 0.97, 0.95, 60),
            "bays-1": Verdict(True, "one bay like the others taken out", 0.97, 0.95, 60)}


@pytest.fixture
def unclean_floors(monkeypatch) -> list:
    """Every check finds floors + 1 not clean and the rest clean; the list holds each tree checked."""
    checked = []

    def fake(tree):
        checked.append(tree)
        return fake_verdicts()

    monkeypatch.setattr(editcheck, "check_edits", fake)
    return checked


def _url(proc, rest: str = "") -> str:
    return f"/api/v1/procedures/{proc.code}/{rest}"


def _record(proc: Procedure) -> dict:
    proc.refresh_from_db()
    return proc.metrics["edits"]


def _params(client, proc, **post) -> dict[str, dict]:
    r = client.post(_url(proc, "parameters"), post, format="json") if post else client.get(_url(proc, "parameters"))
    assert r.status_code == 200, r.content
    return {p["name"]: p for p in r.json()["parameters"]}


def test_every_tree_the_site_writes_keeps_its_edits_checked(as_alice, as_bob, alice, bob, unclean_floors):
    """Stored, edited, reverted, forked, saved as new: each tree's verdicts are kept with its digest, in the
    procedure and its version; a tree whose verdicts are kept already (a revert, a fork) is not checked again, nor is
    a save of the title alone."""
    r = as_alice.post("/api/v1/procedures/", {"data": generate(3).procedure.to_dict(), "visibility": "public"},
                      format="json")
    assert r.status_code == 201, r.content
    proc = Procedure.objects.get(code=r.json()["code"])
    first = _record(proc)
    assert first["digest"] == proc.digest and first["verdicts"]["floors+1"]["reason"] == UNCLEAN
    assert r.json()["metrics"]["edits"] == first and proc.current_version().metrics["edits"] == first
    assert len(unclean_floors) == 1

    r = as_alice.post(_url(proc, "parameters"), {"values": {"floors": 6}, "save": True}, format="json")
    assert r.status_code == 200 and r.json()["version"] == 2, r.content
    second = _record(proc)
    assert second["digest"] == proc.digest != first["digest"] and len(unclean_floors) == 2  # no second check
    assert r.json()["metrics"]["edits"] == second

    assert as_alice.post(_url(proc, "versions/1/revert")).status_code == 201
    assert _record(proc) == first and proc.digest == first["digest"] and len(unclean_floors) == 2
    assert as_alice.patch(_url(proc), {"title": "Rivoli"}, format="json").status_code == 200
    assert len(unclean_floors) == 2

    fork = Procedure.objects.get(code=as_bob.post(_url(proc, "fork")).json()["code"])
    assert _record(fork) == first and len(unclean_floors) == 2
    variant = vary(Tree.from_dict(proc.data), 1, 3)[0].to_dict()
    r = as_bob.post(_url(proc, "save-as-new"), {"data": variant}, format="json")
    assert r.status_code == 201, r.content
    copy = Procedure.objects.get(code=r.json()["code"])
    assert _record(copy)["digest"] == copy.digest != proc.digest and len(unclean_floors) == 3
    assert [v.metrics["edits"]["digest"] for v in copy.versions.order_by("version")] == [copy.digest]  # one version


def test_the_api_says_which_named_parameters_are_checked(as_alice, alice, unclean_floors):
    """A count is checked where its + 1 and − 1 are clean, and says each edit in words; a length is not judged (null).
    The page's unsaved tree is checked as it is sent, and nothing of it is stored."""
    proc = Procedure.objects.create(owner=alice, data=generate(3).procedure.to_dict())
    assert len(unclean_floors) == 1
    params = _params(as_alice, proc)
    floors, bays = params["floors"], params["bays"]
    assert floors["checked"] is False and bays["checked"] is True
    assert floors["check"] == (f"floors + 1 is not clean: {UNCLEAN}; "
                               "floors \u2212 1 is clean: one floor like the others taken out")
    assert [(e["edit"], e["clean"]) for e in floors["edits"]] == [("+1", False), ("-1", True)]
    assert floors["edits"][0]["said"] == f"floors + 1 is not clean: {UNCLEAN}"
    for name in ("floor_height", "tile_width", "window_width", "width", "height"):
        assert params[name]["checked"] is None and params[name]["check"].startswith("not judged"), name
    assert len(unclean_floors) == 1  # the kept verdicts, not a new check

    same = _params(as_alice, proc, values={}, data=proc.data)  # the page, as it opens: the saved tree
    assert same["floors"]["check"] == floors["check"] and len(unclean_floors) == 1
    edited = _params(as_alice, proc, values={"floors": 6})  # a tree not saved: checked now, not stored
    assert edited["floors"]["value"] == 6 and edited["floors"]["checked"] is False and len(unclean_floors) == 2
    assert _record(proc)["digest"] == proc.digest and proc.versions.count() == 1


def test_a_real_check_is_reported_as_it_judged(as_alice, alice):
    """No verdict made up: what the library judges of a generated facade is what the procedure keeps and the API
    says, count by count."""
    tree = generate(5).procedure
    proc = Procedure.objects.create(owner=alice, data=tree.to_dict())
    verdicts = check_edits(tree)
    kept = _record(proc)["verdicts"]
    assert {k: (v["clean"], v["reason"]) for k, v in kept.items()} == {
        k: (v.clean, v.reason) for k, v in verdicts.items()}
    params = _params(as_alice, proc)
    for name in ("floors", "bays"):
        mine = [v for k, v in verdicts.items() if k.startswith(name)]
        assert params[name]["checked"] == (all(v.clean for v in mine) if mine else None), name
        for v in mine:
            assert v.reason in params[name]["check"]
    assert 0 < _record(proc)["seconds"] < editcheck.CHECK_SECONDS


def _two_floors(side: int) -> dict:
    wall = {"rule": "leaf", "label": "facade"}
    tile = {"rule": "split", "axis": "x", "role": "tile", "sizes": [["flt", 1], ["flt", 2], ["flt", 1]],
            "children": [wall, {"rule": "leaf", "label": "window", "role": "window"}, wall]}
    row = {"rule": "repeat", "axis": "x", "count": 2, "role": "floor", "sizes": [["flt", 1]], "children": [tile]}
    return doc({"rule": "repeat", "axis": "y", "count": 2, "role": "floors", "sizes": [["flt", 1]],
                "children": [row]}, side)


def test_a_tree_too_costly_to_check_is_stored_not_checked_and_says_why(as_alice, monkeypatch):
    """Two floors of two windows, 4,096 px square: 19 node instances, but the check compares its 2,048 px bands
    (40 s here): it is not run, and the procedure says so and why, at once."""
    def never(tree):
        raise AssertionError("checked a tree too costly to check")

    monkeypatch.setattr(editcheck, "check_edits", never)
    data = _two_floors(4096)
    tree = Tree.from_dict(data)
    seconds, units = editcheck.estimate(tree, named_parameters(tree))
    assert seconds > 20 * editcheck.CHECK_SECONDS and units < 50
    assert editcheck.estimate(tree)[0] > editcheck.CHECK_SECONDS  # its pixels alone: its parameters not read
    start = time.perf_counter()
    r = as_alice.post("/api/v1/procedures/", {"data": data}, format="json")
    assert r.status_code == 201, r.content
    assert time.perf_counter() - start < 5
    proc = Procedure.objects.get(code=r.json()["code"])
    record = _record(proc)
    assert record["verdicts"] is None and record["again"] is False
    assert record["reason"] == (f"not checked: checking its edits would take more than the "
                                f"{editcheck.CHECK_SECONDS:g} s a check may take here (the facade is 4096 x 4096 px "
                                f"and lays out {units} node instances)")
    floors = _params(as_alice, proc)["floors"]
    assert floors["checked"] is None and floors["check"] == record["reason"]
    small = Procedure.objects.create(owner=proc.owner, data=_two_floors(256))  # the same tree, small: checked
    assert "check failed" in _record(small)["reason"]  # (by the spy above)


def test_a_request_without_the_budget_for_the_check_saves_and_says_so(as_alice, settings, unclean_floors):
    """The check is reserved from the request's work budget: a save that cannot pay for it is stored, not checked,
    and checked when next asked for (the parameters' request, with its own budget)."""
    data = generate(3).procedure.to_dict()
    tree = Tree.from_dict(data)
    settings.FACAID_REQUEST_WORK = 4 * count_expansion(tree.root, tree.width, tree.height).instances
    r = as_alice.post("/api/v1/procedures/", {"data": data}, format="json")
    assert r.status_code == 201, r.content
    proc = Procedure.objects.get(code=r.json()["code"])
    record = _record(proc)
    assert record["verdicts"] is None and record["again"] is True and unclean_floors == []
    assert "too little of its work budget left for the check" in record["reason"]
    assert _params(as_alice, proc)["floors"]["checked"] is None  # this request cannot pay for it either
    settings.FACAID_REQUEST_WORK = 2_000_000
    assert _params(as_alice, proc)["floors"]["checked"] is False and len(unclean_floors) == 1


def test_a_check_leaves_the_request_the_time_for_its_own_work(as_alice, monkeypatch, unclean_floors):
    """A check estimated to take more than half the CPU time its request has left is not run: the save goes on,
    and the tree is checked when next asked for."""
    monkeypatch.setattr(editcheck, "seconds_left", lambda: 0.02)
    r = as_alice.post("/api/v1/procedures/", {"data": generate(3).procedure.to_dict()}, format="json")
    assert r.status_code == 201, r.content
    record = r.json()["metrics"]["edits"]
    assert record["verdicts"] is None and record["again"] is True and unclean_floors == []
    assert record["reason"].startswith("not checked: the request had too little of its computing time left for "
                                       "the check (it may take ")
    assert record["reason"].endswith(" s, and 0.02 s were left); it is checked when next asked for")


def test_a_check_that_fails_is_said_and_never_a_500(as_alice, monkeypatch):
    def broken(tree):
        raise RuntimeError("boom")

    monkeypatch.setattr(editcheck, "check_edits", broken)
    r = as_alice.post("/api/v1/procedures/", {"data": generate(3).procedure.to_dict()}, format="json")
    assert r.status_code == 201, r.content
    proc = Procedure.objects.get(code=r.json()["code"])
    assert _record(proc)["reason"] == "not checked: the check failed (RuntimeError: boom)"
    assert _params(as_alice, proc)["floors"]["check"] == "not checked: the check failed (RuntimeError: boom)"
    assert as_alice.post(_url(proc, "variations"), {"n": 2}, format="json").status_code == 200


def test_verdicts_of_another_tree_are_never_shown(as_alice, alice, unclean_floors):
    """The verdicts are keyed by the digest of the tree they judged: a record of another tree is not shown (the tree
    is checked again), one of this tree is shown as kept."""
    proc = Procedure.objects.create(owner=alice, data=generate(3).procedure.to_dict())
    stale = {"digest": "0" * 16, "verdicts": {"floors+1": {"clean": True, "reason": "STALE"}}, "seconds": 0.1}
    Procedure.objects.filter(pk=proc.pk).update(metrics={"edits": stale})
    body = as_alice.get(_url(proc, "parameters")).content.decode()
    assert "STALE" not in body and UNCLEAN in body and len(unclean_floors) == 2
    kept = {"digest": proc.digest, "verdicts": {"floors+1": {"clean": False, "reason": "KEPT"}}, "seconds": 0.1}
    Procedure.objects.filter(pk=proc.pk).update(metrics={"edits": kept})
    floors = _params(as_alice, proc)["floors"]
    assert floors["check"] == "floors + 1 is not clean: KEPT" and len(unclean_floors) == 2
    assert editcheck.current({"edits": stale}, proc.digest) is None  # (and a save checks its own tree again)
    proc.refresh_from_db()
    proc.metrics = {"edits": stale}
    proc.save()
    assert _record(proc)["digest"] == proc.digest and len(unclean_floors) == 3


def test_variations_leave_out_unclean_counts_unless_asked(as_alice, alice, unclean_floors):
    tree = generate(3).procedure
    proc = Procedure.objects.create(owner=alice, data=tree.to_dict())
    floors = {p.name: p.value for p in named_parameters(tree)}["floors"]
    r = as_alice.post(_url(proc, "variations"), {"n": 8, "seed": 0}, format="json")
    assert r.status_code == 200, r.content
    body = r.json()
    assert [o["name"] for o in body["left_out"]] == ["floors"]
    assert body["left_out"][0]["reason"] == f"floors + 1 is not clean: {UNCLEAN}"  # the edit that did not pass
    assert len(body["variants"]) == 8
    for v in body["variants"]:  # the floors as they are: no floor added by a count, a resize or a swap
        assert {p.name: p.value for p in named_parameters(Tree.from_dict(v))}["floors"] == floors, v["meta"]

    r = as_alice.post(_url(proc, "variations"), {"n": 8, "seed": 0, "include_unchecked": True}, format="json")
    assert r.status_code == 200 and r.json()["left_out"] == []
    assert r.json()["variants"] == [v.to_dict() for v in vary(tree, 8, 0)]  # as before the check
    assert any({p.name: p.value for p in named_parameters(Tree.from_dict(v))}["floors"] != floors
               for v in r.json()["variants"])

    ranges = {"floors": [4, 6], "floor_height": [80, 90], "height": [700, 900]}
    body = as_alice.post(_url(proc, "variations"), {"n": 4, "ranges": ranges}, format="json").json()
    assert [o["name"] for o in body["left_out"]] == ["floors", "height"]
    assert "recounts the floors, whose edits are not clean" in body["left_out"][1]["reason"]
    assert all(set(v["meta"]["parameters"]) == {"floor_height"} for v in body["variants"])
    r = as_alice.post(_url(proc, "variations"), {"n": 4, "ranges": {"floors": [4, 6]}}, format="json")
    said = str(r.json()["ranges"])
    assert r.status_code == 400 and "ask with include_unchecked to vary them" in said and UNCLEAN in said
    body = as_alice.post(_url(proc, "variations"), {"n": 4, "ranges": {"floors": [4, 6]}, "include_unchecked": True},
                         format="json").json()
    assert body["left_out"] == [] and {v["meta"]["parameters"]["floors"] for v in body["variants"]} <= {4, 5, 6}
    for bad in ("yes", 1, None):
        r = as_alice.post(_url(proc, "variations"), {"include_unchecked": bad}, format="json")
        assert r.status_code == 400 and "include_unchecked" in json.dumps(r.json()), bad
