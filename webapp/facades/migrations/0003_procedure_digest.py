"""Each procedure keeps a digest of its tree (webapp.facades.models.tree_digest, written out here as it is today),
so that its pictures are found and revalidated without reading the tree."""

import hashlib
import json

from django.db import migrations, models


def fill(apps, schema_editor):
    Procedure = apps.get_model("facades", "Procedure")
    for proc in Procedure.objects.all().only("id", "data").iterator():
        text = json.dumps(proc.data, sort_keys=True, separators=(",", ":"), allow_nan=False)
        Procedure.objects.filter(id=proc.id).update(digest=hashlib.sha256(text.encode()).hexdigest()[:16])


class Migration(migrations.Migration):
    dependencies = [("facades", "0002_procedures_within_the_size_cap")]
    operations = [
        migrations.AddField(model_name="procedure", name="digest",
                            field=models.CharField(blank=True, editable=False, max_length=16)),
        migrations.RunPython(fill, migrations.RunPython.noop),
    ]
