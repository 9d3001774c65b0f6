"""The worker package is the Celery app (issue 69): ``celery -A worker`` finds it, with its task registered by the name
the site sends, on the site's queues, acknowledged late, one job at a time."""

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_celery_dash_a_worker_finds_the_app_and_the_task_the_site_sends():
    from celery.app.utils import find_app

    from webapp.facades.queue import GPU_QUEUE, RUN_JOB, broker_settings, sender

    app = find_app("worker")
    assert RUN_JOB in app.tasks
    assert app.conf.task_routes == sender.conf.task_routes == {RUN_JOB: {"queue": GPU_QUEUE}}
    assert app.conf.broker_url == broker_settings()["broker_url"]  # REDIS_URL, as the site reads it
    assert app.conf.task_acks_late and app.conf.worker_prefetch_multiplier == 1


def test_python_dash_m_worker_names_its_one_command():
    out = subprocess.run([sys.executable, "-m", "worker", "nonsense"], cwd=ROOT, capture_output=True, text=True,
                         timeout=60)
    assert out.returncode == 2 and "usage: python -m worker demo" in out.stderr
