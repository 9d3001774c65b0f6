"""A photo keeps the facade's real width or height in metres, as the user gave it (the scale of its exports)."""

from django.db import migrations, models


class Migration(migrations.Migration):
    dependencies = [("facades", "0003_procedure_digest")]
    operations = [
        migrations.AddField(model_name="photo", name="real_width_m", field=models.FloatField(blank=True, null=True)),
        migrations.AddField(model_name="photo", name="real_height_m", field=models.FloatField(blank=True, null=True)),
    ]
