"""The site under load, and the worker's throughput.

    .venv/bin/python bench/bench_site.py [--clients 50] [--seconds 20] [--jobs 12] [--k K]

Starts its own Redis, gunicorn (2 workers x 4 threads, as `scripts/run`) and one Celery worker on a scratch
SQLite database in a temporary directory, fills it with public procedures and jobs, then:
1. 50 concurrent keep-alive clients on loopback request the gallery (`GET /api/v1/gallery/`) and a job's status
   (`GET /api/v1/jobs/<code>/`) for N seconds: requests/s, median and p95 latency per endpoint;
2. submits J reconstruction jobs (generated facades, K candidates each, by default the site's
   `facaid.defaults.DEFAULT_K`) to one CPU worker: jobs per minute from the first claim to the last finish.
"""

from __future__ import annotations

import argparse
import http.client
import json
import os
import secrets
import shutil
import socket
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

from facaid.defaults import DEFAULT_K

ROOT = Path(__file__).resolve().parents[1]


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_port(port: int, timeout: float = 60) -> None:
    deadline = time.time() + timeout
    while time.time() < deadline:
        try:
            socket.create_connection(("127.0.0.1", port), timeout=0.2).close()
            return
        except OSError:
            time.sleep(0.1)
    raise RuntimeError(f"nothing listens on {port}")


def manage(env, *args) -> str:
    return subprocess.run([sys.executable, "manage.py", *args], cwd=ROOT, env=env, check=True,
                          capture_output=True, text=True).stdout


SEED_SCRIPT = """
import json, sys
from django.contrib.auth import get_user_model
from facaid.generator import generate
from webapp.facades.models import Job, Photo, Procedure, Segmentation
user = get_user_model().objects.create_user("bench", "b@example.com", "bench-password-1")
for i in range(60):
    Procedure.objects.create(owner=user, title=f"facade {i}", data=generate(i).procedure.to_dict(),
                             visibility="public", accuracy=0.99)
photo = Photo.objects.create(owner=user, title="bench", image="photos/none.png", width=10, height=10)
seg = Segmentation.objects.create(photo=photo, version=1, data=generate(0).segmentation.to_dict())
job = Job.objects.create(owner=user, segmentation=seg, status="done", progress=1.0)
from django.test import Client
client = Client()
client.force_login(user)  # a session, as a browser has: no password hashing per request
print(json.dumps({"job": str(job.code), "session": client.cookies["sessionid"].value}))
"""


def load(port: int, paths: list[str], cookie: str, clients: int, seconds: float) -> dict[str, list[float]]:
    lat: dict[str, list[float]] = {p: [] for p in paths}
    errors = []
    stop = time.time() + seconds
    lock = threading.Lock()

    def client(i: int) -> None:
        conn = http.client.HTTPConnection("127.0.0.1", port, timeout=30)
        n = i
        while time.time() < stop:
            path = paths[n % len(paths)]
            n += 1
            t0 = time.perf_counter()
            try:
                conn.request("GET", path, headers={"Cookie": cookie, "Connection": "keep-alive"})
                resp = conn.getresponse()
                resp.read()
                ok = resp.status == 200
            except (OSError, http.client.HTTPException):
                ok = False
                conn.close()
                conn = http.client.HTTPConnection("127.0.0.1", port, timeout=30)
            dt = time.perf_counter() - t0
            with lock:
                (lat[path] if ok else errors).append(dt)
        conn.close()

    threads = [threading.Thread(target=client, args=(i,)) for i in range(clients)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    lat["errors"] = errors
    return lat


def pct(values: list[float], q: float) -> float:
    values = sorted(values)
    return values[min(len(values) - 1, int(q * len(values)))]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--clients", type=int, default=50)
    ap.add_argument("--seconds", type=float, default=20)
    ap.add_argument("--jobs", type=int, default=12)
    ap.add_argument("--k", type=int, default=DEFAULT_K, help=f"candidates per job (default {DEFAULT_K}, the site's)")
    args = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="facaid-bench-"))
    redis_port, web_port = free_port(), free_port()
    env = {**os.environ, "DATABASE_URL": f"sqlite:///{tmp / 'db.sqlite3'}", "MEDIA_ROOT": str(tmp / "media"),
           "REDIS_URL": f"redis://127.0.0.1:{redis_port}/0", "FACAID_VAR": str(tmp), "DJANGO_SETTINGS_MODULE":
           "webapp.settings",
           # as scripts/run: DEBUG off over plain http with a key of its own; the API's throttles off, as the
           # 50 clients share one session and one address (this measures the site, not the throttle)
           "SECRET_KEY": secrets.token_urlsafe(50), "FACAID_HTTPS": "0", "FACAID_API_ANON_RATE": "none",
           "FACAID_API_USER_RATE": "none", "FACAID_API_HEAVY_RATE": "none"}
    procs = []
    try:
        redis = subprocess.run(["bash", "scripts/redis-server-path"], cwd=ROOT, capture_output=True, text=True,
                               check=True).stdout.strip()
        procs.append(subprocess.Popen([redis, "--port", str(redis_port), "--save", "", "--dir", str(tmp)],
                                      stdout=subprocess.DEVNULL))
        manage(env, "migrate", "--noinput")
        manage(env, "collectstatic", "--noinput")
        seeded = json.loads(manage(env, "shell", "-c", SEED_SCRIPT).strip().splitlines()[-1])
        job = seeded["job"]
        procs.append(subprocess.Popen([sys.executable, "-m", "gunicorn", "webapp.wsgi", "--bind",
                                       f"127.0.0.1:{web_port}", "--workers", "2", "--threads", "4",
                                       "--max-requests", "1000", "--max-requests-jitter", "100",
                                       "--no-control-socket"],
                                      cwd=ROOT, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        wait_port(web_port)
        cookie = f"sessionid={seeded['session']}"
        paths = ["/api/v1/gallery/", f"/api/v1/jobs/{job}/"]
        load(web_port, paths, cookie, 4, 2)  # warm up
        lat = load(web_port, paths, cookie, args.clients, args.seconds)
        total = sum(len(v) for k, v in lat.items() if k != "errors")
        print(f"load: {args.clients} clients for {args.seconds:.0f} s on loopback: {total / args.seconds:.0f} "
              f"requests/s, {len(lat['errors'])} errors")
        for path in paths:
            v = lat[path]
            name = "gallery" if "gallery" in path else "job status"
            print(f"  {name:10s} {len(v):6d} requests  median {1000 * statistics.median(v):6.1f} ms  "
                  f"p95 {1000 * pct(v, 0.95):6.1f} ms")
        # throughput of one CPU worker
        log = open(tmp / "worker.log", "wb")  # noqa: SIM115 (lives as long as the worker)
        procs.append(subprocess.Popen([sys.executable, "-m", "celery", "-A", "worker", "worker", "-Q",
                                       "gpu,default", "--pool", "prefork", "--concurrency", "1", "-l", "info"],
                                      cwd=ROOT, env=env,
                                      stdout=log, stderr=subprocess.STDOUT))
        submit = f"""
import json
from facaid.generator import generate
from facaid.generator.dataset import sample_seed
from webapp.facades.services import jobs
from webapp.facades.models import Photo, Segmentation, Job
from django.contrib.auth import get_user_model
user = get_user_model().objects.get(username="bench")
photo = Photo.objects.get(title="bench")
for i in range({args.jobs}):
    s = generate(sample_seed(1000, i))
    seg = Segmentation.objects.create(photo=photo, version=i + 2, data=s.segmentation.to_dict())
    jobs.submit(owner=user, segmentation=seg, params={{"k": {args.k}, "seed": 0}})
"""
        manage(env, "shell", "-c", submit)
        status = """
import json
from webapp.facades.models import Job
from django.db.models import Min, Max
q = Job.objects.exclude(status="done", result=None).filter(segmentation__version__gt=1)
print(json.dumps({"left": q.exclude(status__in=["done", "failed"]).count(),
                  "failed": q.filter(status="failed").count(),
                  "first": str(q.aggregate(Min("started"))["started__min"]),
                  "last": str(q.aggregate(Max("finished"))["finished__max"])}))
"""
        deadline = time.time() + 60 * 30
        while time.time() < deadline:
            s = json.loads(manage(env, "shell", "-c", status).strip().splitlines()[-1])
            if s["left"] == 0:
                break
            time.sleep(2)
        from datetime import datetime

        span = (datetime.fromisoformat(s["last"]) - datetime.fromisoformat(s["first"])).total_seconds()
        print(f"worker: {args.jobs} jobs ({s['failed']} failed) in {span:.1f} s from the first claim to the last "
              f"finish: {60 * args.jobs / span:.1f} jobs per minute on one CPU worker")
    finally:
        for p in reversed(procs):
            p.terminate()
        for p in procs:
            try:
                p.wait(10)
            except subprocess.TimeoutExpired:
                p.kill()
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
