"""scripts/run for real (its own FACAID_VAR, site port and Redis port): the Celery worker and the Redis it started are
killed, each is started again and says so, the site answers all along, a job submitted afterwards is done by the new
worker, and Ctrl-C stops everything."""

from __future__ import annotations

import os
import re
import shutil
import signal
import socket
import subprocess
import time
import urllib.request
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
OURS = ("SECRET_KEY", "DEBUG", "ALLOWED_HOSTS", "FACAID_", "DATABASE_URL", "REDIS_URL", "MEDIA_ROOT")

pytestmark = pytest.mark.skipif(shutil.which("redis-server") is None, reason="needs redis-server")


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_until(what: str, check, timeout: float = 120, every: float = 0.2):
    deadline = time.time() + timeout
    while time.time() < deadline:
        found = check()
        if found:
            return found
        time.sleep(every)
    raise AssertionError(f"timed out waiting for {what}")


def status(url: str) -> int | None:
    try:
        with urllib.request.urlopen(url, timeout=10) as r:
            return r.status
    except OSError:
        return None


def alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    return True


class Run:
    """scripts/run in its own session, as a terminal would run it."""

    def __init__(self, tmp_path: Path):
        self.var, self.port, self.redis_port = tmp_path / "var", free_port(), free_port()
        self.out = tmp_path / "terminal.log"
        self.env = {k: v for k, v in os.environ.items() if not k.startswith(OURS)}
        self.env.update(FACAID_VAR=str(self.var), PORT=str(self.port), REDIS_PORT=str(self.redis_port),
                        FACAID_SETUP="0", PYTHONPATH=str(ROOT), SECRET_KEY="scripts-run-test-" + "k" * 40,
                        FACAID_RECOVER_SECONDS="1", FACAID_HEARTBEAT_SECONDS="1", FACAID_JOB_STALE_SECONDS="4",
                        PYTHONUNBUFFERED="1")
        with open(self.out, "wb") as out:
            # a terminal's Ctrl-C reaches a script whose SIGINT is the default; a test process may have left it
            # ignored (then inherited: bash cannot trap a signal ignored when it starts, and exited 0 on Ctrl-C)
            self.proc = subprocess.Popen(["bash", "scripts/run"], cwd=ROOT, env=self.env, stdout=out,
                                         stderr=subprocess.STDOUT, start_new_session=True,
                                         preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))

    def terminal(self) -> str:
        return self.out.read_text(errors="replace")

    def pids(self, name: str) -> list[int]:
        return [int(p) for p in re.findall(rf"scripts/run: {name} started \(pid (\d+)\)", self.terminal())]

    def site(self, path: str = "/") -> int | None:
        return status(f"http://127.0.0.1:{self.port}{path}")

    def manage(self, code: str) -> str:
        env = {**self.env, "REDIS_URL": f"redis://127.0.0.1:{self.redis_port}/0"}
        return subprocess.run([str(ROOT / ".venv/bin/python"), "manage.py", "shell", "-c", code], cwd=ROOT, env=env,
                              capture_output=True, text=True, check=True, timeout=120).stdout.strip().splitlines()[-1]

    def ctrl_c(self) -> int:
        os.killpg(self.proc.pid, signal.SIGINT)
        return self.proc.wait(timeout=60)

    def stop(self) -> None:
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGTERM)
            try:
                self.proc.wait(timeout=60)
            except subprocess.TimeoutExpired:
                os.killpg(self.proc.pid, signal.SIGKILL)
        for pid in self.pids("worker") + self.pids("redis"):  # their own sessions: not in the script's group
            if alive(pid):
                os.killpg(pid, signal.SIGKILL)


SUBMIT = """
from django.contrib.auth import get_user_model
from webapp.facades.services import jobs
from webapp.facades.models import Segmentation
user = get_user_model().objects.create_user("tester", "t@example.com", "tester-password-1")
seg = Segmentation.objects.get(photo__owner__username="demo")
print(jobs.submit(owner=user, segmentation=seg, params={"k": 2, "seed": 1, "visibility": "public"}).code)
"""

STATUS = "from webapp.facades.models import Job; print(Job.objects.get(code='{code}').status)"


def test_a_killed_worker_and_redis_are_started_again_and_the_site_stays_up(tmp_path):
    run = Run(tmp_path)
    try:
        wait_until("the site", lambda: run.site() == 200 or run.proc.poll() is not None, timeout=240)
        assert run.proc.poll() is None, run.terminal()
        log = run.var / "worker.log"
        wait_until("the worker", lambda: b"ready." in log.read_bytes())
        [worker] = run.pids("worker")
        [redis] = run.pids("redis")

        os.kill(worker, signal.SIGKILL)
        for _ in range(5):  # gunicorn stopped within a second of a worker's death before
            time.sleep(0.5)
            assert run.site() == 200 and run.proc.poll() is None
        wait_until("a new worker", lambda: len(run.pids("worker")) == 2)
        assert "worker exited with status 137; starting it again in 1 s" in run.terminal()
        assert run.pids("worker")[1] != worker and not alive(worker)
        wait_until("the new worker ready", lambda: b"ready." in log.read_bytes().split(b"worker exited")[-1])

        os.kill(redis, signal.SIGKILL)
        wait_until("a new redis", lambda: len(run.pids("redis")) == 2, timeout=30)
        assert "redis exited with status 137" in run.terminal() and run.site() == 200

        code = run.manage(SUBMIT)  # the new worker, on the new Redis, does the next job
        wait_until("the job", lambda: run.manage(STATUS.format(code=code)) in ("done", "failed"), every=1)
        assert run.manage(STATUS.format(code=code)) == "done", log.read_text()[-3000:]
        assert run.site("/api/v1/gallery/") == 200

        rc = run.ctrl_c()
        assert rc != 0, run.terminal()
        # stopped, on a loaded machine within a few seconds of the script (a worker finishing its shutdown)
        wait_until("the worker and redis stopped", lambda: not any(alive(p) for p in run.pids("worker") +
                                                                   run.pids("redis")), timeout=20)
        assert run.site() is None
    finally:
        run.stop()
