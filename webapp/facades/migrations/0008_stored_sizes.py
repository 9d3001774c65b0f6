"""What each row stores, for the account's storage quota (issue 66: a procedure's current tree is stored as JSON
besides its compressed versions, and photos and segmentations counted nothing): a photo's files, a segmentation's
and a draft's JSON, a procedure's current tree's JSON. Filled in for the rows there are."""

import json

from django.db import migrations, models

BATCH = 100  # rows read at a time: a tree or a segmentation may be megabytes


def json_size(data) -> int:  # as `webapp.facades.models.json_size` (a migration keeps its own copy)
    return len(json.dumps(data, separators=(",", ":"), allow_nan=False, ensure_ascii=False).encode())


def measure(apps, schema_editor):
    for model, field in (("Procedure", "data_size"), ("Segmentation", "size"), ("Draft", "size")):
        rows = apps.get_model("facades", model).objects.only("id", "data").order_by("id")
        last = 0
        while batch := list(rows.filter(id__gt=last)[:BATCH]):
            for row in batch:
                setattr(row, field, json_size(row.data))
            rows.model.objects.bulk_update(batch, [field])
            last = batch[-1].id
    Photo = apps.get_model("facades", "Photo")
    for photo in Photo.objects.only("id", "image", "rectified").iterator(BATCH):
        total = 0
        for f in (photo.image, photo.rectified):
            try:
                total += f.size if f else 0
            except OSError:  # a file gone from storage stores nothing
                pass
        Photo.objects.filter(id=photo.id).update(stored_bytes=total)


class Migration(migrations.Migration):
    dependencies = [("facades", "0007_compressed_versions")]
    operations = [
        migrations.AddField(model_name="photo", name="stored_bytes", field=models.PositiveBigIntegerField(default=0)),
        migrations.AddField(model_name="segmentation", name="size", field=models.PositiveIntegerField(default=0)),
        migrations.AddField(model_name="draft", name="size", field=models.PositiveIntegerField(default=0)),
        migrations.AddField(model_name="procedure", name="data_size",
                            field=models.PositiveIntegerField(default=0, editable=False)),
        migrations.RunPython(measure, migrations.RunPython.noop),
    ]
