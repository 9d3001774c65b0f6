"""A version's tree is stored as zlib-compressed JSON (`webapp.facades.fields.CompressedJSONField`), with its
compressed size, which the per-account quota of saved versions adds up (issue 56: each save of a 498 KB tree stored
a full copy). Every version is kept: its tree is copied over as it is."""

from django.db import migrations, models

import webapp.facades.fields

BATCH = 100  # versions rewritten at a time: a tree may be megabytes


def pack_versions(apps, schema_editor):
    ProcedureVersion = apps.get_model("facades", "ProcedureVersion")
    rows = ProcedureVersion.objects.only("id", "data").order_by("id")
    last = 0
    while True:
        batch = list(rows.filter(id__gt=last)[:BATCH])
        if not batch:
            return
        for v in batch:
            v.packed = webapp.facades.fields.pack(v.data)  # stored as it is, not compressed twice
            v.size = len(v.packed)
        ProcedureVersion.objects.bulk_update(batch, ["packed", "size"])
        last = batch[-1].id


def unpack_versions(apps, schema_editor):
    ProcedureVersion = apps.get_model("facades", "ProcedureVersion")
    for v in ProcedureVersion.objects.only("id", "packed").iterator(BATCH):
        v.data = v.packed
        v.save(update_fields=["data"])


class Migration(migrations.Migration):
    dependencies = [("facades", "0006_procedure_versions")]
    operations = [
        migrations.AddField(model_name="procedureversion", name="packed",
                            field=webapp.facades.fields.CompressedJSONField(null=True)),
        migrations.AddField(model_name="procedureversion", name="size",
                            field=models.PositiveIntegerField(default=0)),
        migrations.AlterField(model_name="procedureversion", name="data", field=models.JSONField(null=True)),
        migrations.RunPython(pack_versions, unpack_versions),
        migrations.RemoveField(model_name="procedureversion", name="data"),
        migrations.RenameField(model_name="procedureversion", old_name="packed", new_name="data"),
        migrations.AlterField(model_name="procedureversion", name="data",
                              field=webapp.facades.fields.CompressedJSONField()),
    ]
