"""Seconds of CPU each request that takes a tree costs, with the heaviest trees the site accepts (issue 56).

    .venv/bin/python bench/bench_request_cost.py [--repeat 3] [--case NAME ...] [--tree deep|wide|crafted ...]

One Django process on a scratch SQLite database, requests through the test client, anonymous where the site
allows it (a public procedure). The trees:

- ``crafted``: issue 56's 2.1 KB tree, 256 x 256 repeats, each leaf under 29 one-child splits (65,536 leaves,
  2 million node instances): refused by the cost model (`facaid.grammar.limits.MAX_INSTANCES`) before any work.
- ``deep``: the same shape cut to the limit: 256 x 12 copies of a 29-split chain (95,000 node instances).
- ``wide``: 157 x 157 tiles of a window with wall on both sides (73,947 leaves, 98,755 instances), its rows
  floors, its tiles bays, its windows windows: every named parameter applies.
- ``photo``: completion (no tree): 2,000 rectangles of 2,000 sizes drawn on a public 16 MP photo (issue 56 measured
  135 s for 1,690 types).
- ``probe``: issue 66's 137 KB tree, repeat y x 256 -> repeat x x 11 -> R, a repeat of one copy with 1,024
  size-only exceptions in copy 0 whose paths run down 28 one-child splits into a ``"fill"`` repeat of 4 leaves of
  abs 5000 (a render took 206 s); refused by the cost model, which charges each exception at every level it is
  carried through.
- ``probe-stored``: the same shape with 100 copies of R, stored as the site accepted it before (issue 66: render
  7.9 s, store 16 s, the page 9 s): every request on it, the page included, reads it and refuses or shows it light.
- ``probe-max``: the heaviest accepted tree of that shape, 3 copies of R whose exceptions reach a repeat of 256
  copies (95,474 units): what an accepted tree of exceptions costs.
- ``nested``: issue 66's 460 KB shape, 8 nested repeats of 1,010 exceptions each (1.06 s to parse and refuse).

Each figure is the median of ``--repeat`` requests, in seconds of wall time on an idle machine (one request at
a time, so wall time is the CPU the request thread holds). Target: a crafted tree refused in < 0.1 s on every
entry point; what is accepted answers in about a second or goes to the worker.
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

CASES = {
    "render": "POST /api/v1/render (the live preview)",
    "store": "POST /api/v1/procedures/ (a new procedure; its pictures are rendered as it is saved)",
    "parameters": "GET parameters (the named parameters and where each leaf is drawn)",
    "set-floors": "POST parameters {floors: +1}, not saved",
    "set-window-width": "POST parameters {window_width: x 1.1}, not saved",
    "set-all": "POST parameters, every named parameter at once, not saved",
    "variations": "POST variations n=2 with a range of floors",
    "variations-32": "POST variations n=32 (the most one request may ask for)",
    "compare.png": "GET the difference picture of two versions",
    "labels.png": "GET the download labels.png",
    "facade.glb": "GET the download facade.glb",
    "procedure.cga": "GET the download procedure.cga",
    "complete-16MP": "POST complete, 2,000 rectangles of 2,000 sizes on a public 16 MP photo, anonymous",
    "page": "GET the procedure's page",
}
REFUSED = ("crafted", "probe", "nested")  # never stored: only requests that carry a tree can send them

BODY = ("render", "store", "set-floors", "set-window-width", "set-all")  # the requests that carry a tree in their body

CHILD = r"""
import json, os, sys, time
os.environ["DJANGO_SETTINGS_MODULE"] = "webapp.settings"
import django
django.setup()
from django.core.management import call_command
call_command("migrate", verbosity=0)
from django.contrib.auth import get_user_model
from rest_framework.test import APIClient
from webapp.facades.models import Procedure

sys.path.insert(0, "tests")
from grammar_helpers import doc, nested, probe  # issue 66's trees, as the tests build them

tree_name, case, repeat = sys.argv[1], sys.argv[2], int(sys.argv[3])
user = get_user_model().objects.create_user("bench", "b@example.com", "bench-password-1")
owner = APIClient(); owner.force_login(user)
anon = APIClient()


def chain(n_x, n_y, depth):
    node = {"rule": "leaf", "label": "window"}
    for _ in range(depth):
        node = {"rule": "split", "axis": "y", "sizes": [["flt", 1]], "children": [node]}
    inner = {"rule": "repeat", "axis": "y", "count": n_y, "sizes": [["flt", 1]], "children": [node]}
    return doc({"rule": "repeat", "axis": "x", "count": n_x, "sizes": [["flt", 1]], "children": [inner]})


def wide(n):
    wall = {"rule": "leaf", "label": "facade"}
    tile = {"rule": "split", "axis": "x", "role": "tile", "sizes": [["flt", 1], ["flt", 2], ["flt", 1]],
            "children": [wall, {"rule": "leaf", "label": "window", "role": "window"}, wall]}
    row = {"rule": "repeat", "axis": "x", "count": n, "role": "floor", "sizes": [["flt", 1]], "children": [tile]}
    return doc({"rule": "repeat", "axis": "y", "count": n, "role": "floors", "sizes": [["flt", 1]],
                "children": [row]})


tree = {"crafted": chain(256, 256, 29), "deep": chain(256, 12, 29), "wide": wide(157), "photo": wide(2),
        "probe": probe(256, 11), "probe-stored": probe(100, 1), "probe-max": probe(3, 1, count=256),
        "nested": nested()}[tree_name]
proc = Procedure.objects.create(owner=user, data=wide(2), visibility="public")
if tree_name not in ("crafted", "probe", "nested"):
    proc.data = tree
    proc.save()  # the heavy tree as its version 2 (version 1 is small)
code = proc.code
floors_range = {"floors": [2, 4]}
if case == "complete-16MP":
    import io
    import numpy as np
    from django.core.files.images import ImageFile
    from PIL import Image
    from webapp.facades.models import Photo
    rng = np.random.default_rng(0)
    buf = io.BytesIO()
    Image.fromarray(rng.integers(0, 256, size=(4000, 4000, 3), dtype=np.uint8)).save(buf, "JPEG", quality=85)
    photo = Photo(owner=user, title="noise", visibility="public")
    photo.image.save("photo.jpg", ImageFile(io.BytesIO(buf.getvalue()), name="photo"), save=False)
    photo.save()
    rects = []
    for i in range(2000):
        w, h = np.exp(rng.uniform(np.log(8), np.log(300), size=2))
        x, y = rng.uniform(0, 4000 - w), rng.uniform(0, 4000 - h)
        rects.append({"label": ["window", "door", "balcony", "sill", "blind"][i % 5], "x0": int(x), "y0": int(y),
                      "x1": int(x + w), "y1": int(y + h)})
    drawn = {"width": 4000, "height": 4000, "rects": rects}
requests = {
    "render": lambda: anon.post("/api/v1/render", tree, format="json"),
    "store": lambda: owner.post("/api/v1/procedures/", {"data": tree}, format="json"),
    "parameters": lambda: anon.get(f"/api/v1/procedures/{code}/parameters"),
    "set-floors": lambda: anon.post(f"/api/v1/procedures/{code}/parameters",
                                    {"values": {"floors": 4}, "data": tree}, format="json"),
    "set-window-width": lambda: anon.post(f"/api/v1/procedures/{code}/parameters",
                                          {"values": {"window_width": 12}, "data": tree}, format="json"),
    "variations": lambda: anon.post(f"/api/v1/procedures/{code}/variations",
                                    {"n": 2, "ranges": floors_range}, format="json"),
    "set-all": lambda: anon.post(f"/api/v1/procedures/{code}/parameters",
                                 {"values": {"floors": 150, "bays": 150, "floor_height": 25, "tile_width": 25,
                                             "window_width": 12, "width": 4000, "height": 4000}, "data": tree},
                                 format="json"),
    "variations-32": lambda: anon.post(f"/api/v1/procedures/{code}/variations", {"n": 32}, format="json"),
    "compare.png": lambda: anon.get(f"/api/v1/procedures/{code}/versions/compare.png?a=1&b=2"),
    "labels.png": lambda: anon.get(f"/api/v1/procedures/{code}/download/labels.png"),
    "facade.glb": lambda: anon.get(f"/api/v1/procedures/{code}/download/facade.glb"),
    "procedure.cga": lambda: anon.get(f"/api/v1/procedures/{code}/download/procedure.cga"),
    "complete-16MP": lambda: anon.post(f"/api/v1/photos/{photo.code}/complete", drawn, format="json"),
    "page": lambda: anon.get(f"/procedures/{code}"),
}
anon.post("/api/v1/render", wide(2), format="json")  # warm: imports, URL resolution
times, status = [], None
for _ in range(repeat):
    t0 = time.perf_counter()
    r = requests[case]()
    if getattr(r, "streaming", False):
        b"".join(r.streaming_content)
    else:
        r.content
    times.append(time.perf_counter() - t0)
    status = r.status_code
print(json.dumps({"times": times, "status": status}))
"""


def run_case(tree: str, case: str, repeat: int) -> dict:
    with tempfile.TemporaryDirectory(prefix="facaid-cost-") as tmp:
        env = {**os.environ, "FACAID_VAR": tmp, "MEDIA_ROOT": str(Path(tmp) / "media"),
               "DATABASE_URL": f"sqlite:///{Path(tmp) / 'db.sqlite3'}", "SECRET_KEY": "bench-" * 10,
               "DEBUG": "0", "FACAID_HTTPS": "0"}
        out = subprocess.run([sys.executable, "-c", CHILD, tree, case, str(repeat)], cwd=ROOT, env=env,
                             capture_output=True, text=True)
        if out.returncode != 0:
            raise RuntimeError(f"{tree} {case} failed:\n{out.stderr[-3000:]}")
        return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--case", nargs="*", choices=sorted(CASES), help="only these requests")
    trees = ["crafted", "deep", "wide", "photo", "probe", "probe-stored", "probe-max", "nested"]
    ap.add_argument("--tree", nargs="*", choices=trees, default=trees)
    args = ap.parse_args()
    print(f"{'tree':12s} {'request':18s} {'status':>6s} {'seconds (median)':>17s}  runs")
    for tree in args.tree:
        for case in args.case or CASES:
            if tree in REFUSED and case not in BODY:
                continue  # a tree the site refuses is never stored: only requests that carry one can send it
            if (tree == "photo") != (case == "complete-16MP"):
                continue
            r = run_case(tree, case, args.repeat)
            print(f"{tree:12s} {case:18s} {r['status']:6d} {statistics.median(r['times']):17.3f}  "
                  f"{', '.join(f'{t:.3f}' for t in r['times'])}   {CASES[case]}", flush=True)


if __name__ == "__main__":
    main()
