"""Procedures stored before their width, height and sizes were capped at 16,384 px (the largest side of a
segmentation) are scaled down uniformly to fit: width, height and every absolute size by one factor, so each
still draws the same facade, smaller (a side is kept at 1 px at least). Relative and floating sizes, counts and
the rest are unchanged; the pixel accuracy, measured at the old size, is dropped."""

from django.db import migrations

CAP = 16384.0


def _largest_size(node) -> float:
    largest, stack = 0.0, [node]
    while stack:
        node = stack.pop()
        if not isinstance(node, dict):
            continue
        for s in node.get("sizes") or []:
            if isinstance(s, list) and len(s) == 2 and s[0] == "abs" and isinstance(s[1], int | float):
                largest = max(largest, float(s[1]))
        if isinstance(node.get("children"), list):
            stack.extend(node["children"])
    return largest


def _scale_sizes(node, factor: float) -> None:
    stack = [node]
    while stack:
        node = stack.pop()
        if not isinstance(node, dict):
            continue
        sizes = node.get("sizes")
        if isinstance(sizes, list):
            node["sizes"] = [[s[0], s[1] * factor] if isinstance(s, list) and len(s) == 2 and s[0] == "abs"
                             and isinstance(s[1], int | float) else s for s in sizes]
        children = node.get("children")
        if isinstance(children, list):
            stack.extend(children)


def scale_down(apps, schema_editor):
    Procedure = apps.get_model("facades", "Procedure")
    for proc in Procedure.objects.all().only("id", "data").iterator():
        data = proc.data
        try:
            side = max(float(data["width"]), float(data["height"]), _largest_size(data.get("root")))
        except (TypeError, KeyError, ValueError, OverflowError):
            continue
        if side <= CAP:
            continue
        factor = CAP / side
        for key in ("width", "height"):
            data[key] = min(CAP, max(1.0, data[key] * factor))
        _scale_sizes(data.get("root"), factor)
        Procedure.objects.filter(id=proc.id).update(data=data, accuracy=None)


class Migration(migrations.Migration):
    dependencies = [("facades", "0001_initial")]
    operations = [migrations.RunPython(scale_down, migrations.RunPython.noop)]
