"""Peak memory and CPU time of each picture (and download) a request can ask for, with the largest inputs the site
accepts.

    .venv/bin/python bench/bench_render_memory.py [--repeat 3] [--case NAME ...]

Each case runs in a fresh Python process on a scratch SQLite database: Django is set up, the objects the request
needs are made (a procedure of the largest declared size, 16,384 px a side; 73,947 leaves; a 40-megapixel photo
as JPEG and as PNG), the same request is made once at a small size to warm imports and caches, then the
process's peak resident set is reset (Linux `/proc/self/clear_refs`) and the request is made through Django's
test client. The figure is the peak resident memory above what the process held just before the request
(VmHWM after − VmRSS before), the median of ``--repeat`` fresh processes; beside it the CPU seconds the request
took (user and system, all the process's threads, `resource.getrusage`), also a median. Targets: ≤ 300 MB for
every case, and ≤ 1 s of CPU for every request that reads a 40 MP photo (the cases named ``40MP``). CPU time
counts what the request computes, but a machine busy with other work makes it noisier than the memory figure.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
LIMIT_MB = 300
LIMIT_CPU_S = 1.0  # for the cases that read a 40 MP photo

CASES = {  # name: what the request is
    "render-16384": "POST /api/v1/render, a 16,384 x 16,384 procedure (one wall leaf), anonymous",
    "render-73947-leaves": "POST /api/v1/render, 16,384 px, 157 x 157 repeated tiles of 3 leaves (73,947 leaves)",
    "render-declared-20000": "POST /api/v1/render, 20,000 x 20,000 declared (refused: 400)",
    "labels.png-16384": "GET labels.png of a stored public 16,384 px procedure, anonymous",
    "thumbnail-16384": "GET the thumbnail of a stored public 16,384 px procedure (a gallery card), anonymous",
    "labels.png-unrendered-16384": "GET labels.png of a 16,384 px procedure whose pictures were not kept yet",
    "save-16384": "POST /api/v1/procedures/ a 16,384 px procedure (its pictures are rendered as it is saved)",
    "save-73947-leaves": "POST /api/v1/procedures/ the 73,947-leaf procedure (pictures rendered as it is saved)",
    "labels.svg-73947-leaves": "GET labels.svg of the 73,947-leaf procedure",
    "segmentation.json-73947-leaves": "GET segmentation.json of the 73,947-leaf procedure",
    "overlay.png-40MP-jpeg": "GET overlay.png over a 40-megapixel JPEG photo (8,000 x 5,000)",
    "overlay.png-40MP-png": "GET overlay.png over a 40-megapixel PNG photo",
    "rectify-40MP-png": "POST rectify of a 40-megapixel PNG photo (its four corners)",
    "rectify-40MP-rgba-png": "POST rectify of a 40-megapixel PNG photo with an alpha channel",
    "photo-image-40MP-png": "GET the 40-megapixel PNG photo's image file",
    "upload-40MP-png": "POST a 40-megapixel PNG photo (the largest accepted)",
    "upload-40MP-jpeg-rotated": "POST a 40-megapixel JPEG photo whose EXIF says it is turned (upright on upload)",
    "upload-40MP-cmyk-jpeg": "POST a 40-megapixel CMYK JPEG photo (stored as RGB)",
    "upload-40MP-rgba-png": "POST a 40-megapixel PNG photo with an alpha channel",
    "upload-40MP-webp": "POST a 16,000 x 2,490 WebP photo (40 MP in a ~70 KB file, the probe's)",
    "json-4MB-of-objects": "POST /api/v1/render, 4 MB of [{},{},...] (the most objects a body can hold), anonymous",
    "segmentation-list-100": "GET a photo's 100 segmentation versions of 20,000 rectangles each (a page)",
    "remeasure-40MP": "PATCH the data of a procedure made from a 40 MP segmentation (2,000 windows), re-measured",
    "compare.png-73947-leaves": "GET the difference picture of two versions of the 73,947-leaf procedure",
    "complete-40MP-rgba-png": "POST complete on a 40 MP RGBA PNG photo, 2,000 rectangles of 2,000 sizes, anonymous",
    "copies-40MP-rgba-png": "POST complete with a unit (Find copies) on a 40 MP RGBA PNG photo, 2,000 rectangles",
    "overlay.png-40MP-rgba-png": "GET overlay.png over a 40 MP RGBA PNG photo",
    "facade-photo.glb-40MP-rgba-png": "GET facade-photo.glb (the relief with the photo on its fronts), 40 MP RGBA PNG",
}

CHILD = r"""
import io, json, os, sys, gc, resource
os.environ["DJANGO_SETTINGS_MODULE"] = "webapp.settings"
import django
django.setup()
from django.core.management import call_command
call_command("migrate", verbosity=0)
from django.contrib.auth import get_user_model
from django.core.files.images import ImageFile
from django.core.files.uploadedfile import SimpleUploadedFile
from PIL import Image
from rest_framework.test import APIClient
from webapp.facades.models import Photo, Procedure, Segmentation

case = sys.argv[1]
user = get_user_model().objects.create_user("bench", "b@example.com", "bench-password-1")
owner = APIClient(); owner.force_login(user)
anon = APIClient()

def facade(side_w, side_h, windows=0):
    wall = {"rule": "leaf", "label": "facade"}
    if not windows:
        return {"format": "facaid-procedure", "version": 1, "grammar": GRAMMAR, "width": side_w, "height": side_h,
                "root": wall}
    tile = {"rule": "split", "axis": "x", "sizes": [["flt", 1], ["flt", 2],
            ["flt", 1]], "children": [wall, {"rule": "leaf", "label": "window"}, wall]}
    row = {"rule": "repeat", "axis": "x", "count": windows, "sizes": [["flt", 1]],
           "children": [tile]}
    return {"format": "facaid-procedure", "version": 1, "grammar": GRAMMAR, "width": side_w, "height": side_h,
            "root": {"rule": "repeat", "axis": "y", "count": windows, "sizes": [["flt", 1]],
                     "children": [row]}}

from facaid.grammar.procedure import GRAMMAR_VERSION as GRAMMAR

def photo(fmt, w=8000, h=5000, mode="RGB", **save):
    img = Image.new(mode, (w, h), (150, 140, 130, 255)[:len(mode)])
    img.paste((90, 100, 120, 200)[:len(mode)], (w // 4, h // 4, w // 2, h // 2))
    buf = io.BytesIO(); img.save(buf, fmt, **({"quality": 90} if fmt == "JPEG" else {}), **save); del img
    p = Photo(owner=user, title="big", visibility="public")
    p.image.save("photo." + {"JPEG": "jpg", "PNG": "png", "WEBP": "webp"}[fmt],
                 ImageFile(io.BytesIO(buf.getvalue()), name="photo"), save=False)
    p.save()
    seg = Segmentation.objects.create(photo=p, version=1, data={"width": w, "height": h, "rects": []})
    proc = Procedure.objects.create(owner=user, data=facade(w, h, 0), photo=p, segmentation=seg,
                                    visibility="public")
    return p, proc, buf.getvalue()

def stored(data):
    return Procedure.objects.create(owner=user, data=data, visibility="public")

small = facade(100, 80, 0)
if case == "render-16384":
    warm = lambda: anon.post("/api/v1/render", small, format="json")
    run = lambda: anon.post("/api/v1/render", facade(16384, 16384), format="json")
elif case == "render-73947-leaves":
    body = facade(16384, 16384, 157)
    warm = lambda: anon.post("/api/v1/render", facade(100, 80, 2), format="json")
    run = lambda: anon.post("/api/v1/render", body, format="json")
elif case == "render-declared-20000":
    warm = lambda: anon.post("/api/v1/render", small, format="json")
    run = lambda: anon.post("/api/v1/render", facade(20000, 20000), format="json")
elif case in ("labels.png-16384", "labels.svg-73947-leaves", "segmentation.json-73947-leaves"):
    name = case.split("-")[0]
    big = stored(facade(16384, 16384, 157 if "leaves" in case else 0))
    little = stored(small)
    warm = lambda: anon.get(f"/api/v1/procedures/{little.code}/download/{name}")
    run = lambda: anon.get(f"/api/v1/procedures/{big.code}/download/{name}")
elif case == "thumbnail-16384":
    big, little = stored(facade(16384, 16384, 0)), stored(small)
    warm = lambda: anon.get(f"/api/v1/procedures/{little.code}/thumbnail.png")
    run = lambda: anon.get(f"/api/v1/procedures/{big.code}/thumbnail.png")
elif case == "labels.png-unrendered-16384":
    big, little = stored(facade(16384, 16384, 0)), stored(small)
    from django.core.files.storage import default_storage
    for name in default_storage.listdir(f"pictures/{big.code}")[1]:
        default_storage.delete(f"pictures/{big.code}/{name}")
    warm = lambda: anon.get(f"/api/v1/procedures/{little.code}/download/labels.png")
    run = lambda: anon.get(f"/api/v1/procedures/{big.code}/download/labels.png")
elif case.startswith("save-"):
    body = {"data": facade(16384, 16384, 157 if "leaves" in case else 0)}
    warm = lambda: owner.post("/api/v1/procedures/", {"data": facade(100, 80, 2)}, format="json")
    run = lambda: owner.post("/api/v1/procedures/", body, format="json")
elif case.startswith("overlay.png"):
    p, proc, _ = photo("JPEG" if case.endswith("jpeg") else "PNG")
    sp, sproc, _ = photo("JPEG" if case.endswith("jpeg") else "PNG", 100, 80)
    warm = lambda: anon.get(f"/api/v1/procedures/{sproc.code}/download/overlay.png")
    run = lambda: anon.get(f"/api/v1/procedures/{proc.code}/download/overlay.png")
elif case.startswith("rectify-40MP"):
    p, _, _ = photo("PNG", mode="RGBA" if "rgba" in case else "RGB")
    sp, _, _ = photo("PNG", 100, 80)
    corners = [[100, 50], [7900, 0], [8000, 5000], [0, 4950]]
    warm = lambda: owner.post(f"/api/v1/photos/{sp.code}/rectify", {"corners": [[1, 1], [99, 0], [100, 80], [0, 79]]},
                              format="json")
    run = lambda: owner.post(f"/api/v1/photos/{p.code}/rectify", {"corners": corners}, format="json")
elif case == "photo-image-40MP-png":
    p, _, _ = photo("PNG")
    sp, _, _ = photo("PNG", 100, 80)
    warm = lambda: anon.get(f"/api/v1/photos/{sp.code}/image")
    run = lambda: anon.get(f"/api/v1/photos/{p.code}/image")
elif case.startswith("upload-40MP"):
    fmt = "JPEG" if "jpeg" in case else "WEBP" if "webp" in case else "PNG"
    mode = "CMYK" if "cmyk" in case else "RGBA" if "rgba" in case else "RGB"
    w, h = (16000, 2490) if fmt == "WEBP" else (8000, 5000)
    turned = {}
    if "rotated" in case:
        exif = Image.Exif(); exif[0x0112] = 6; turned = {"exif": exif.tobytes()}
    _, _, raw = photo(fmt, w, h, mode=mode, **turned)
    _, _, little_raw = photo(fmt, 100, 80, mode=mode, **turned)
    warm = lambda: owner.post("/api/v1/photos/", {"image": SimpleUploadedFile("s.png", little_raw)}, format="multipart")
    run = lambda: owner.post("/api/v1/photos/", {"image": SimpleUploadedFile("b.png", raw)}, format="multipart")
elif case == "json-4MB-of-objects":
    body = "[" + ",".join(["{}"] * ((4 * 2**20 - 8) // 3)) + "]"
    warm = lambda: anon.post("/api/v1/render", "[{}]", content_type="application/json")
    run = lambda: anon.post("/api/v1/render", body, content_type="application/json")
elif case == "segmentation-list-100":
    p, _, _ = photo("PNG", 2000, 2000)
    rects = [{"label": "window", "x0": (i % 140) * 14, "y0": (i // 140) * 13, "x1": (i % 140) * 14 + 10,
              "y1": (i // 140) * 13 + 10} for i in range(20000)]
    data = {"width": 2000, "height": 2000, "rects": rects}
    Segmentation.objects.bulk_create([Segmentation(photo=p, version=v, data=data, rect_count=20000)
                                      for v in range(2, 102)])
    warm = lambda: anon.get(f"/api/v1/photos/{p.code}/segmentations/?limit=1")
    run = lambda: anon.get(f"/api/v1/photos/{p.code}/segmentations/?limit=100")
elif case == "remeasure-40MP":
    from facaid.grammar.decompose import procedure_from_segmentation
    from facaid.segmentation import Segmentation as SegData
    w, h = 8000, 5000
    rects = [{"label": "window", "x0": (i % 50) * 160, "y0": (i // 50) * 125, "x1": (i % 50) * 160 + 100,
              "y1": (i // 50) * 125 + 80} for i in range(2000)]
    data = {"width": w, "height": h, "rects": [{"label": "facade", "x0": 0, "y0": 0, "x1": w, "y1": h}] + rects}
    p, _, _ = photo("PNG", w, h)
    seg = Segmentation.objects.create(photo=p, version=2, data=data, rect_count=len(data["rects"]))
    tree = procedure_from_segmentation(SegData.from_dict(data)).to_dict()
    proc = Procedure.objects.create(owner=user, data=tree, photo=p, segmentation=seg)
    little = Procedure.objects.create(owner=user, data=small)
    warm = lambda: owner.patch(f"/api/v1/procedures/{little.code}/", {"data": small}, format="json")
    run = lambda: owner.patch(f"/api/v1/procedures/{proc.code}/", {"data": tree}, format="json")
elif case == "compare.png-73947-leaves":
    big, little = stored(facade(16384, 16384, 157)), stored(facade(100, 80, 2))
    for proc, count in ((big, 156), (little, 1)):
        proc.data["root"]["count"] = count
        proc.save()  # a second version
    warm = lambda: anon.get(f"/api/v1/procedures/{little.code}/versions/compare.png?a=1&b=2")
    run = lambda: anon.get(f"/api/v1/procedures/{big.code}/versions/compare.png?a=1&b=2")
elif case in ("complete-40MP-rgba-png", "copies-40MP-rgba-png"):
    p, _, _ = photo("PNG", mode="RGBA")
    sp, _, _ = photo("PNG", 100, 80, mode="RGBA")
    import numpy as np
    rng = np.random.default_rng(0)
    rects = []
    for i in range(2000):
        w, h = np.exp(rng.uniform(np.log(8), np.log(300), size=2))
        x, y = rng.uniform(0, 8000 - w), rng.uniform(0, 5000 - h)
        rects.append({"label": ["window", "door", "balcony", "sill", "blind"][i % 5], "x0": int(x), "y0": int(y),
                      "x1": int(x + w), "y1": int(y + h)})
    body = {"width": 8000, "height": 5000, "rects": rects}
    small_body = {"width": 100, "height": 80, "rects": [{"label": "window", "x0": 10, "y0": 10, "x1": 30, "y1": 40}]}
    if case.startswith("copies"):  # the unit: the first window and the sill drawn with it
        body["unit"], small_body["unit"] = [0, 3], [0]
    warm = lambda: anon.post(f"/api/v1/photos/{sp.code}/complete", small_body, format="json")
    run = lambda: anon.post(f"/api/v1/photos/{p.code}/complete", body, format="json")
elif case in ("overlay.png-40MP-rgba-png", "facade-photo.glb-40MP-rgba-png"):
    name = case.split("-40MP")[0]
    p, proc, _ = photo("PNG", mode="RGBA")
    sp, sproc, _ = photo("PNG", 100, 80, mode="RGBA")
    warm = lambda: anon.get(f"/api/v1/procedures/{sproc.code}/download/{name}")
    run = lambda: anon.get(f"/api/v1/procedures/{proc.code}/download/{name}")
else:
    raise SystemExit(f"unknown case {case}")

def status():
    out = {}
    for line in open("/proc/self/status"):
        key, _, value = line.partition(":")
        if key in ("VmRSS", "VmHWM"):
            out[key] = int(value.split()[0]) / 1024
    return out

r = warm()
gc.collect()
before = status()["VmRSS"]
with open("/proc/self/clear_refs", "w") as f:
    f.write("5")  # reset the peak (VmHWM) to the current resident set
def cpu():
    use = resource.getrusage(resource.RUSAGE_SELF)
    return use.ru_utime + use.ru_stime

start = cpu()
r = run()
if getattr(r, "streaming", False):
    b"".join(r.streaming_content)  # a file response is read as a client would
took = cpu() - start
code = getattr(r, "status_code", 200)
peak = status()["VmHWM"]
print(json.dumps({"case": case, "status": code, "peak_mb": peak - before, "cpu_s": took}))
"""


def run_case(case: str) -> dict:
    with tempfile.TemporaryDirectory(prefix="facaid-mem-") as tmp:
        env = {**os.environ, "FACAID_VAR": tmp, "MEDIA_ROOT": str(Path(tmp) / "media"),
               "DATABASE_URL": f"sqlite:///{Path(tmp) / 'db.sqlite3'}", "SECRET_KEY": "bench-" * 10,
               "DEBUG": "0", "FACAID_HTTPS": "0"}
        out = subprocess.run([sys.executable, "-c", CHILD, case], cwd=ROOT, env=env, capture_output=True,
                             text=True)
        if out.returncode != 0:
            raise RuntimeError(f"{case} failed:\n{out.stderr[-3000:]}")
        return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--case", nargs="*", choices=sorted(CASES), help="only these cases")
    args = ap.parse_args()
    worst, slowest = 0.0, 0.0
    print(f"{'case':32s} {'status':>6s} {'peak MB (median)':>17s} {'CPU s':>6s}  runs (MB)")
    for case in args.case or CASES:
        runs = [run_case(case) for _ in range(args.repeat)]
        peaks, cpus = [r["peak_mb"] for r in runs], [r["cpu_s"] for r in runs]
        worst = max(worst, statistics.median(peaks))
        if "40MP" in case:
            slowest = max(slowest, statistics.median(cpus))
        print(f"{case:32s} {runs[0]['status']:6d} {statistics.median(peaks):17.1f} {statistics.median(cpus):6.2f}  "
              f"{', '.join(f'{p:.0f}' for p in peaks)}   {CASES[case]}")
    print(f"worst median peak: {worst:.1f} MB (target ≤ {LIMIT_MB} MB): {'met' if worst <= LIMIT_MB else 'NOT met'}")
    print(f"most CPU of a 40 MP photo's request: {slowest:.2f} s (target ≤ {LIMIT_CPU_S:.0f} s): "
          f"{'met' if slowest <= LIMIT_CPU_S else 'NOT met'}")


if __name__ == "__main__":
    main()
