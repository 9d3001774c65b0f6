"""The light pages under a burst of the heaviest requests the site accepts (issues 56 and 66).

    .venv/bin/python bench/bench_heavy_load.py [--seconds 20] [--heavy 8] [--slots 2 8] [--mix api pages uploads]

Starts gunicorn as `scripts/run` does (2 workers x 4 threads) on a scratch SQLite database in a temporary directory,
loopback only, with a public procedure of the largest accepted size (157 x 157 tiles, 98,755 node instances, in two
versions) and 60 small public ones for the gallery. Then for ``--seconds``: ``--heavy`` clients each send, one after
another, the heaviest requests of one mix, while one client reads the gallery (`GET /api/v1/gallery/`) and
measures it. The mixes:

- ``api``, anonymous: a render of that tree, two variations of it in a range of floors, its windows made wider;
- ``pages``, anonymous: that procedure's page, the difference picture of its two versions, the label map of its
  first version (drawn on each request);
- ``uploads``, one account (an API token): a 40-megapixel WebP photo of 16,000 x 2,490 px (issue 66's probe).

The API's rate throttles are off (every client shares one address: this measures the process's heavy slots, not
the throttle). Run once per mix and ``--slots`` value (`FACAID_HEAVY_SLOTS`: heavy requests one process serves at
once; 8 is no cap with 4 threads a worker). Target: the gallery's p95 ≤ 500 ms at the default slots.
"""

from __future__ import annotations

import argparse
import http.client
import json
import os
import secrets
import shutil
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from collections import Counter
from pathlib import Path

from bench_site import free_port, manage, pct, wait_port

ROOT = Path(__file__).resolve().parents[1]

SEED_SCRIPT = """
import json
from django.contrib.auth import get_user_model
from facaid.generator import generate
from facaid.grammar.procedure import GRAMMAR_VERSION
from webapp.facades.models import Procedure
user = get_user_model().objects.create_user("bench", "b@example.com", "bench-password-1")
for i in range(60):
    Procedure.objects.create(owner=user, title=f"facade {i}", data=generate(i).procedure.to_dict(),
                             visibility="public", accuracy=0.99)
wall = {"rule": "leaf", "label": "facade"}
tile = {"rule": "split", "axis": "x", "role": "tile", "sizes": [["flt", 1], ["flt", 2], ["flt", 1]],
        "children": [wall, {"rule": "leaf", "label": "window", "role": "window"}, wall]}
row = {"rule": "repeat", "axis": "x", "count": 157, "role": "floor", "sizes": [["flt", 1]], "children": [tile]}
tree = {"format": "facaid-procedure", "version": 1, "grammar": GRAMMAR_VERSION, "width": 4096, "height": 4096,
        "root": {"rule": "repeat", "axis": "y", "count": 157, "role": "floors", "sizes": [["flt", 1]],
                 "children": [row]}}
big = Procedure.objects.create(owner=user, title="big", data=tree, visibility="public")
tree["root"]["count"] = 156
big.data = tree
big.save()  # its version 2
from rest_framework.authtoken.models import Token
print(json.dumps({"big": str(big.code), "tree": tree, "token": Token.objects.create(user=user).key}))
"""

BOUNDARY = "facaid-bench-boundary"


def upload_body() -> bytes:
    """A multipart body of the probe's photo: a 16,000 x 2,490 WebP (40 MP), a few tens of KB."""
    import io

    from PIL import Image

    img = Image.new("RGB", (16000, 2490), (150, 140, 130))
    img.paste((90, 100, 120), (4000, 600, 8000, 1800))
    buf = io.BytesIO()
    img.save(buf, "WEBP", quality=50)
    head = (f"--{BOUNDARY}\r\nContent-Disposition: form-data; name=\"image\"; filename=\"big.webp\"\r\n"
            "Content-Type: image/webp\r\n\r\n").encode()
    return head + buf.getvalue() + f"\r\n--{BOUNDARY}--\r\n".encode()


def mix_requests(mix: str, seeded: dict) -> list[tuple[str, str, object, dict]]:
    """(method, path, body, headers) of each heavy request of a mix, sent in turn."""
    code, tree = seeded["big"], seeded["tree"]
    json_body = {"Content-Type": "application/json"}
    if mix == "api":
        return [("POST", "/api/v1/render", tree, json_body),
                ("POST", f"/api/v1/procedures/{code}/variations", {"n": 2, "ranges": {"floors": [150, 157]}},
                 json_body),
                ("POST", f"/api/v1/procedures/{code}/parameters", {"values": {"window_width": 12}}, json_body)]
    if mix == "pages":
        return [("GET", f"/procedures/{code}", None, {}),
                ("GET", f"/api/v1/procedures/{code}/versions/compare.png?a=1&b=2", None, {}),
                ("GET", f"/api/v1/procedures/{code}/versions/1/labels.png", None, {})]
    form = {"Content-Type": f"multipart/form-data; boundary={BOUNDARY}", "Authorization": f"Token {seeded['token']}"}
    return [("POST", "/api/v1/photos/", seeded["upload"], form)]



def run(env: dict, slots: int, seconds: float, heavy: int, seeded: dict, mix: str) -> dict:
    port = free_port()
    env = {**env, "FACAID_HEAVY_SLOTS": str(slots)}
    server = subprocess.Popen([sys.executable, "-m", "gunicorn", "webapp.wsgi", "--bind", f"127.0.0.1:{port}",
                               "--workers", "2", "--threads", "4", "--no-control-socket"], cwd=ROOT, env=env,
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        wait_port(port)
        requests = mix_requests(mix, seeded)
        stop = time.time() + seconds
        statuses: Counter = Counter()
        heavy_times: list[float] = []
        gallery: list[float] = []
        lock = threading.Lock()

        def send(conn, method, path, body=None, headers=None):
            data = body if body is None or isinstance(body, bytes) else json.dumps(body)
            conn.request(method, path, body=data, headers=headers or {})
            r = conn.getresponse()
            r.read()
            return r.status, r.getheader("Retry-After")

        def heavy_client(i: int) -> None:
            conn = http.client.HTTPConnection("127.0.0.1", port, timeout=60)
            n = i
            while time.time() < stop:
                method, path, body, headers = requests[n % len(requests)]
                n += 1
                t0 = time.perf_counter()
                try:
                    status, retry = send(conn, method, path, body, headers)
                except (OSError, http.client.HTTPException):
                    status, retry = "error", None
                    conn.close()
                    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=60)
                with lock:
                    statuses[status] += 1
                    if status == 200:
                        heavy_times.append(time.perf_counter() - t0)
                if status == 503:
                    time.sleep(float(retry or 1) / 4)  # an impatient client: a quarter of what it is told
            conn.close()

        def light_client() -> None:
            conn = http.client.HTTPConnection("127.0.0.1", port, timeout=60)
            while time.time() < stop:
                t0 = time.perf_counter()
                status, _ = send(conn, "GET", "/api/v1/gallery/")
                if status == 200:
                    gallery.append(time.perf_counter() - t0)
                time.sleep(0.05)
            conn.close()

        send(http.client.HTTPConnection("127.0.0.1", port, timeout=60), "GET", "/api/v1/gallery/")  # warm
        threads = [threading.Thread(target=heavy_client, args=(i,)) for i in range(heavy)]
        threads.append(threading.Thread(target=light_client))
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        return {"slots": slots, "gallery": gallery, "statuses": dict(statuses), "heavy": heavy_times}
    finally:
        server.terminate()
        server.wait()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seconds", type=float, default=20)
    ap.add_argument("--heavy", type=int, default=8)
    ap.add_argument("--slots", type=int, nargs="+", default=[2, 8])
    ap.add_argument("--mix", nargs="+", choices=("api", "pages", "uploads"), default=["api", "pages", "uploads"])
    args = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="facaid-heavy-"))
    env = {**os.environ, "DATABASE_URL": f"sqlite:///{tmp / 'db.sqlite3'}", "MEDIA_ROOT": str(tmp / "media"),
           "FACAID_VAR": str(tmp), "DJANGO_SETTINGS_MODULE": "webapp.settings", "SECRET_KEY": secrets.token_urlsafe(50),
           "FACAID_HTTPS": "0", "FACAID_API_ANON_RATE": "none", "FACAID_API_USER_RATE": "none",
           "FACAID_API_HEAVY_RATE": "none"}
    try:
        manage(env, "migrate", "--noinput")
        seeded = json.loads(manage(env, "shell", "-c", SEED_SCRIPT).strip().splitlines()[-1])
        seeded["upload"] = upload_body()
        print(f"{args.heavy} clients sending the heaviest accepted requests, one reading the gallery, "
              f"{args.seconds:.0f} s, gunicorn 2 workers x 4 threads")
        for mix, slots in [(mix, slots) for mix in args.mix for slots in args.slots]:
            r = run(env, slots, args.seconds, args.heavy, seeded, mix)
            g = r["gallery"]
            served = f", served in median {statistics.median(r['heavy']):.2f} s" if r["heavy"] else ""
            print(f"{mix}, heavy slots {slots}: gallery {len(g)} reads, median {1000 * statistics.median(g):.0f} ms, "
                  f"p95 {1000 * pct(g, 0.95):.0f} ms, max {1000 * max(g):.0f} ms; heavy answers {r['statuses']}"
                  f"{served}")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
