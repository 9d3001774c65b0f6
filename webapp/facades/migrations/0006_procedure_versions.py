"""Every save of a procedure's tree is a version (`ProcedureVersion`); each procedure stored before gets its
tree as it stands, with its figures, as version 1. A job remembers which version of its result it made."""

import django.db.models.deletion
import django.utils.timezone
from django.db import migrations, models

BATCH = 200  # versions written at a time: a procedure's tree may be megabytes


def first_versions(apps, schema_editor):
    Procedure = apps.get_model("facades", "Procedure")
    ProcedureVersion = apps.get_model("facades", "ProcedureVersion")
    batch = []
    for proc in Procedure.objects.only("id", "data", "digest", "accuracy", "metrics", "updated").iterator(BATCH):
        batch.append(ProcedureVersion(procedure_id=proc.id, version=1, data=proc.data, digest=proc.digest,
                                      accuracy=proc.accuracy, metrics=proc.metrics, kind="created",
                                      note="as it stood when versions began", created=proc.updated))
        if len(batch) >= BATCH:
            ProcedureVersion.objects.bulk_create(batch)
            batch = []
    ProcedureVersion.objects.bulk_create(batch)


class Migration(migrations.Migration):
    dependencies = [("facades", "0005_segmentation_draft")]
    operations = [
        migrations.CreateModel(
            name="ProcedureVersion",
            fields=[
                ("id", models.BigAutoField(auto_created=True, primary_key=True, serialize=False, verbose_name="ID")),
                ("version", models.PositiveIntegerField()),
                ("data", models.JSONField()),
                ("digest", models.CharField(max_length=16)),
                ("accuracy", models.FloatField(blank=True, null=True)),
                ("metrics", models.JSONField(blank=True, default=dict)),
                ("kind", models.CharField(choices=[("created", "Created"), ("edit", "Edited"),
                                                   ("revert", "Reverted"), ("rerun", "Re-run")], max_length=10)),
                ("note", models.CharField(blank=True, max_length=200)),
                ("based_on", models.PositiveIntegerField(blank=True, null=True)),
                ("warning", models.CharField(blank=True, max_length=300)),
                ("created", models.DateTimeField(default=django.utils.timezone.now)),
                ("procedure", models.ForeignKey(on_delete=django.db.models.deletion.CASCADE, related_name="versions",
                                                to="facades.procedure")),
            ],
            options={"ordering": ["procedure", "-version"]},
        ),
        migrations.AddConstraint(
            model_name="procedureversion",
            constraint=models.UniqueConstraint(fields=("procedure", "version"), name="one_procedure_version"),
        ),
        migrations.AddField(model_name="job", name="result_version",
                            field=models.PositiveIntegerField(blank=True, null=True)),
        migrations.RunPython(first_versions, migrations.RunPython.noop),
    ]
