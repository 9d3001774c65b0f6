"""End to end with a real Redis server and real Celery worker processes: a job runs; a worker killed mid-job
and a Redis restart lose no job."""

from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest
from django.db import connection
from site_helpers import client_for, facade_png, upload

from webapp.facades.models import Job
from worker.app import app

pytestmark = [pytest.mark.django_db(transaction=True),
              pytest.mark.skipif(shutil.which("redis-server") is None, reason="needs redis-server")]

ROOT = Path(__file__).resolve().parents[2]


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Redis:
    def __init__(self, workdir: Path):
        self.port, self.workdir, self.proc = free_port(), workdir, None
        self.url = f"redis://127.0.0.1:{self.port}/0"

    def start(self) -> None:
        self.proc = subprocess.Popen(["redis-server", "--port", str(self.port), "--bind", "127.0.0.1",
                                      "--save", "", "--appendonly", "no", "--dir", str(self.workdir)],
                                     stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        deadline = time.time() + 10
        while time.time() < deadline:
            try:
                with socket.create_connection(("127.0.0.1", self.port), timeout=0.2) as s:
                    s.sendall(b"PING\r\n")
                    if s.recv(16).startswith(b"+PONG"):
                        return
            except OSError:
                time.sleep(0.05)
        raise RuntimeError("redis-server did not start")

    def stop(self) -> None:
        if self.proc:
            self.proc.kill()
            self.proc.wait()
            self.proc = None


class Worker:
    def __init__(self, redis: Redis, log: Path):
        self.redis, self.log, self.proc = redis, log, None

    def start(self) -> None:
        db = connection.settings_dict["NAME"]
        env = {**os.environ, "REDIS_URL": self.redis.url, "DATABASE_URL": f"sqlite:///{db}",
               "FACAID_RECOVER_SECONDS": "1", "FACAID_JOB_STALE_SECONDS": "4", "FACAID_HEARTBEAT_SECONDS": "1",
               "FACAID_JOB_RESEND_SECONDS": "2", "PYTHONUNBUFFERED": "1"}
        with open(self.log, "ab") as out:  # the worker keeps its own copy of the descriptor
            self.proc = subprocess.Popen(
                [sys.executable, "-m", "celery", "-A", "webapp.celery", "worker", "-Q", "gpu,default", "--pool",
                 "solo", "--without-gossip", "--without-mingle", "-l", "info"],
                cwd=ROOT, env=env, stdout=out, stderr=subprocess.STDOUT, start_new_session=True)
        deadline = time.time() + 120
        while time.time() < deadline:
            if b"ready." in self.log.read_bytes():
                return
            if self.proc.poll() is not None:
                break
            time.sleep(0.2)
        raise RuntimeError("the worker did not start:\n" + self.log.read_text()[-3000:])

    def kill(self) -> None:
        if self.proc and self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGKILL)
            self.proc.wait()
        self.log.write_bytes(b"")  # the next start waits for its own "ready."


@pytest.fixture
def redis(tmp_path):
    server = Redis(tmp_path)
    server.start()
    app.conf.broker_url = server.url
    app.pool.force_close_all()
    app._pool = None
    yield server
    server.stop()


@pytest.fixture
def worker(redis, tmp_path):
    w = Worker(redis, tmp_path / "worker.log")
    yield w
    w.kill()


def submit(alice, k=2) -> Job:
    client = client_for(alice)
    data, seg = facade_png(seed=3)
    photo = upload(client, data).json()
    seg = client.post(f"/api/v1/photos/{photo['code']}/segmentations/", seg, format="json").json()
    r = client.post("/api/v1/jobs/", {"segmentation": seg["code"], "k": k}, format="json")
    assert r.status_code == 202
    return Job.objects.get(code=r.json()["code"])


def wait_for(job: Job, statuses: set[str], timeout: float = 240, poll: float = 0.2) -> Job:
    deadline = time.time() + timeout
    while time.time() < deadline:
        job.refresh_from_db()
        if job.status in statuses:
            return job
        time.sleep(poll)
    raise AssertionError(f"job stayed {job.status} ({job.stage}) for {timeout} s")


def check_done(job: Job, attempts: int) -> None:
    assert job.status == "done", job.message
    assert job.attempts == attempts and job.progress == 1.0 and job.result is not None
    assert job.result.accuracy > 0.8 and job.result.segmentation_id == job.segmentation_id


def test_a_job_runs_end_to_end(alice, worker):
    worker.start()
    job = submit(alice)
    check_done(wait_for(job, {"done", "failed"}), attempts=1)
    page = client_for(alice).get(f"/procedures/{job.result.code}").content.decode()
    assert "pixel accuracy" in page


def test_a_worker_killed_mid_job_loses_no_job(alice, worker):
    worker.start()
    job = submit(alice)
    wait_for(job, {"running", "done"}, poll=0.02)
    assert job.status == "running", "the job finished before the worker could be killed"
    worker.kill()
    time.sleep(1)
    job.refresh_from_db()
    assert job.status == "running"  # its worker is gone; recovery notices the missing heartbeat
    worker.start()
    check_done(wait_for(job, {"done", "failed"}), attempts=2)


def test_a_redis_restart_loses_no_job(alice, redis, worker):
    job = submit(alice)  # sent to Redis; no worker yet
    redis.stop()  # the queued message dies with the server (no persistence)
    redis.start()
    worker.start()
    check_done(wait_for(job, {"done", "failed"}), attempts=1)
