"""A procedure keeps its own scale (issue 67: a fork lost the real size, an edit changed the scale): metres per
pixel of its tree and where they came from. Filled in from each procedure's photo's real size (as the downloads
took it: over the original image's pixels where the tree has the original's size, else the rectified image's)
where that shows nobody anything they were not shown before: the procedure's owner may see the photo, and either
only they see the procedure or everyone who sees it sees the photo too. The others (a public procedure of a private
photo, whose owner was told its real size is not shown; a fork of a photo not shared with its owner) are left
without one: their owner, where they may see the photo, still has its scale, and may give the procedure its own."""

from django.db import migrations, models

BATCH = 100  # rows read at a time: a tree may be megabytes
READABLE = ("public", "unlisted")  # as `webapp.facades.access.READABLE` (a migration keeps its own copy)


def scale_of(proc, photo) -> tuple[float, str] | None:
    """As `Procedure.photo_scale`, a migration's copy."""
    if photo.real_width_m is None and photo.real_height_m is None:
        return None
    size = (round(proc.data.get("width", 0)), round(proc.data.get("height", 0)))
    original = bool(photo.rectified) and size == (photo.width, photo.height)
    if original:
        w, h = photo.width, photo.height
    elif photo.rectified:
        try:
            w, h = photo.rectified.width, photo.rectified.height
        except (OSError, ValueError):  # its file gone from storage
            return None
    else:
        w, h = photo.width, photo.height
    if photo.real_width_m is not None and w > 0:
        return photo.real_width_m / w, f"the photo's real width, {photo.real_width_m:g} m"
    if photo.real_height_m is not None and h > 0:
        return photo.real_height_m / h, f"the photo's real height, {photo.real_height_m:g} m"
    return None


def fill(apps, schema_editor):
    Procedure = apps.get_model("facades", "Procedure")
    rows = (Procedure.objects.filter(photo__isnull=False)
            .filter(models.Q(photo__real_width_m__isnull=False) | models.Q(photo__real_height_m__isnull=False))
            .select_related("photo").only("id", "data", "owner_id", "visibility", "photo").order_by("id"))
    last = 0
    while batch := list(rows.filter(id__gt=last)[:BATCH]):
        for proc in batch:
            photo = proc.photo
            owner_sees = photo.owner_id == proc.owner_id or photo.visibility in READABLE
            viewers_see = proc.visibility == "private" or photo.visibility in READABLE
            given = scale_of(proc, photo) if owner_sees and viewers_see else None
            if given is not None:
                Procedure.objects.filter(id=proc.id).update(metres_per_pixel=given[0], scale_from=given[1])
        last = batch[-1].id


class Migration(migrations.Migration):
    dependencies = [("facades", "0008_stored_sizes")]
    operations = [
        migrations.AddField(model_name="procedure", name="metres_per_pixel",
                            field=models.FloatField(blank=True, null=True)),
        migrations.AddField(model_name="procedure", name="scale_from",
                            field=models.CharField(blank=True, max_length=200)),
        migrations.RunPython(fill, migrations.RunPython.noop),
    ]
