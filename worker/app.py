"""The Celery app: Redis broker from REDIS_URL, a ``gpu`` queue for model work, late acks, one job at a time.

Job state lives in the site's database, not in a result backend: a task takes a job id, claims the row with
a conditional update and writes its results there. Messages are acknowledged after the task returns
(``acks_late``) and given back if the worker dies, and the site re-sends jobs that stay queued or whose
worker stopped beating (`webapp.facades.jobs.recover`), so neither a killed worker nor a Redis restart loses
a job.
"""

from __future__ import annotations

import os

from celery import Celery
from kombu import Queue

GPU_QUEUE = "gpu"
DEFAULT_QUEUE = "default"

app = Celery("facaid")
app.conf.update(
    broker_url=os.environ.get("REDIS_URL", "redis://127.0.0.1:6379/0"),
    broker_connection_retry_on_startup=True,
    broker_transport_options={"visibility_timeout": int(os.environ.get("FACAID_VISIBILITY_TIMEOUT", "3600"))},
    task_ignore_result=True,
    task_acks_late=True,
    task_reject_on_worker_lost=True,
    task_acks_on_failure_or_timeout=True,
    worker_prefetch_multiplier=1,
    task_default_queue=DEFAULT_QUEUE,
    task_queues=(Queue(DEFAULT_QUEUE), Queue(GPU_QUEUE)),
    task_routes={"facaid.run_job": {"queue": GPU_QUEUE}},
    task_serializer="json",
    accept_content=["json"],
    worker_hijack_root_logger=False,
)
