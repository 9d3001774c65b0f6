"""How a procedure's versions are stored: migration 0006 gives every procedure its tree as version 1, migration 0007
compresses every version and keeps its tree, a compressed tree reads back however it comes, and versions past the
account's quota are refused by name with nothing lost."""

from __future__ import annotations

import json

import pytest
from site_helpers import faithful_procedure, procedure_url, same_size_variant, version_history

from facaid.generator import generate
from facaid.grammar import Procedure as Tree
from webapp.facades.models import Job, Procedure, ProcedureVersion, stored_bytes

pytestmark = pytest.mark.django_db


def test_migration_0005_gives_every_procedure_its_tree_as_version_1(alice):
    import importlib

    from django.apps import apps

    data = generate(4).procedure.to_dict()
    proc = Procedure.objects.create(owner=alice, data=data, accuracy=0.93, metrics={"source": "model"})
    ProcedureVersion.objects.all().delete()  # as stored before versions
    importlib.import_module("webapp.facades.migrations.0006_procedure_versions").first_versions(apps, None)
    [v1] = ProcedureVersion.objects.filter(procedure=proc)
    assert (v1.version, v1.data, v1.digest, v1.accuracy, v1.metrics) == (1, data, proc.digest, 0.93,
                                                                         proc.metrics)
    assert proc.metrics["source"] == "model"  # (and its edits checked as it was saved)
    assert v1.kind == "created" and v1.created == proc.updated


@pytest.mark.django_db(transaction=True)
def test_migration_0007_stores_every_version_compressed_and_keeps_its_tree(alice):
    from django.db import connection
    from django.db.migrations.executor import MigrationExecutor

    from webapp.facades.fields import pack

    before = [("facades", "0006_procedure_versions")]
    executor = MigrationExecutor(connection)
    executor.migrate(before)
    old = executor.loader.project_state(before).apps
    trees = [generate(i).procedure.to_dict() for i in (4, 5)]
    proc = old.get_model("facades", "Procedure").objects.create(owner_id=alice.id, data=trees[1], digest="x")
    rows = old.get_model("facades", "ProcedureVersion").objects
    for n, tree in enumerate(trees, start=1):
        rows.create(procedure_id=proc.id, version=n, data=tree, digest=f"d{n}", kind="edit")
    executor = MigrationExecutor(connection)
    executor.loader.build_graph()
    executor.migrate([("facades", "0007_compressed_versions")])
    executor.loader.build_graph()
    executor.migrate(executor.loader.graph.leaf_nodes())  # the later ones too: the tests after this one need them
    versions = ProcedureVersion.objects.filter(procedure_id=proc.id).order_by("version")
    assert [v.data for v in versions] == trees  # (PostgreSQL's jsonb kept them in its own key order)
    assert all(v.size == len(pack(v.data)) for v in versions)
    with connection.cursor() as cursor:
        cursor.execute("SELECT data FROM facades_procedureversion WHERE procedure_id = %s", [proc.id])
        stored = [bytes(row[0]) for row in cursor.fetchall()]
    assert all(len(b) * 4 < len(json.dumps(t)) for b, t in zip(stored, trees, strict=True))  # compressed


def test_versions_past_the_accounts_quota_are_refused_by_name_and_nothing_is_lost(facade_photo, as_alice, alice,
                                                                                   settings):
    _, seg = facade_photo
    proc = faithful_procedure(alice, seg)
    used = sum(stored_bytes(alice.pk).values())  # the photo, its segmentation, the tree and its version
    settings.FACAID_STORAGE_QUOTA_MB = (used + ProcedureVersion.objects.get(procedure=proc).size * 2.5) / 2**20
    kept = []
    for seed in range(10, 20):
        tree = same_size_variant(generate(seed).procedure.to_dict()) if seed % 2 else None
        tree = tree or {**Tree.from_dict(proc.data).to_dict(), "meta": {"note": f"save {seed}"}}
        r = as_alice.patch(procedure_url(proc), {"data": tree}, format="json")
        if r.status_code != 200:
            break
        kept.append(r.json()["version"])
    assert r.status_code == 400 and "your account stores" in r.json()["detail"], r.content[:300]
    assert "nothing was saved" in r.json()["detail"]
    assert [v["version"] for v in version_history(as_alice, proc)] == [*reversed(kept), 1]  # all kept, none added
    assert as_alice.get(procedure_url(proc)).json()["version"] == (kept or [1])[-1]
    jobs = Job.objects.count()  # a job would fail on its result: it is refused when asked for
    r = as_alice.post("/api/v1/jobs/", {"segmentation": seg["code"]}, format="json")
    assert r.status_code == 400 and "your account stores" in r.json()["detail"] and Job.objects.count() == jobs


def test_a_compressed_tree_reads_back_from_the_database_from_a_dump_and_as_given():
    from webapp.facades.fields import CompressedJSONField, pack

    field, tree = CompressedJSONField(), generate(3).procedure.to_dict()
    assert field.to_python(pack(tree)) == tree == field.to_python(json.dumps(tree)) == field.to_python(tree)
