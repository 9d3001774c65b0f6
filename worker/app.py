"""The Celery app: Redis broker from REDIS_URL, a ``gpu`` queue for model work, late acks, one job at a time,
soft and hard time limits.

Job state lives in the site's database, not in a result backend: a task takes a job id, claims the row with
a conditional update and writes its results there. Messages are acknowledged after the task returns
(``acks_late``) and given back if the worker dies, and the site re-sends jobs that stay queued or whose
worker stopped beating (`webapp.facades.jobs.recover`), so neither a killed worker nor a Redis restart loses
a job.
"""

from __future__ import annotations

from celery import Celery
from kombu import Queue

from worker.env import env_int, env_seconds, env_str

GPU_QUEUE = "gpu"
DEFAULT_QUEUE = "default"


# A job past the soft limit gets SoftTimeLimitExceeded and ends `failed` with a message; one stuck where that
# cannot reach it (native code) is killed at the hard limit and failed by the worker's main process. Limits need
# the prefork pool (`--pool prefork --concurrency 1`): the solo pool ignores them.
JOB_SOFT_TIME_LIMIT = env_seconds("FACAID_JOB_SOFT_TIME_LIMIT", 600)
JOB_TIME_LIMIT = env_seconds("FACAID_JOB_TIME_LIMIT", 660)
RUN_JOB = "facaid.run_job"  # the task's name: the site sends it by name, the worker registers it

app = Celery("facaid")
app.conf.update(
    broker_url=env_str("REDIS_URL", "redis://127.0.0.1:6379/0"),
    broker_connection_retry_on_startup=True,
    broker_transport_options={"visibility_timeout": env_int("FACAID_VISIBILITY_TIMEOUT", 3600, minimum=1)},
    task_ignore_result=True,
    task_acks_late=True,
    task_reject_on_worker_lost=True,
    task_acks_on_failure_or_timeout=True,
    worker_prefetch_multiplier=1,
    task_soft_time_limit=JOB_SOFT_TIME_LIMIT,
    task_time_limit=JOB_TIME_LIMIT,
    task_default_queue=DEFAULT_QUEUE,
    task_queues=(Queue(DEFAULT_QUEUE), Queue(GPU_QUEUE)),
    task_routes={RUN_JOB: {"queue": GPU_QUEUE}},
    task_serializer="json",
    accept_content=["json"],
    worker_hijack_root_logger=False,
)
