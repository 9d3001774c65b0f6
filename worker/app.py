"""The worker's Celery app: the site's broker and queues (`webapp.facades.queue`: Redis from REDIS_URL, a ``gpu`` queue
for model work), late acks, one job at a time, soft and hard time limits.

Job state lives in the site's database, not in a result backend: the task (`worker.tasks`) takes a job id, claims
the row with a conditional update and writes its results there. Messages are acknowledged after the task returns
(``acks_late``) and given back if the worker dies, and the site re-sends jobs that stay queued or whose worker
stopped beating (`webapp.facades.services.jobs.recover`), so neither a killed worker nor a Redis restart loses a job.
"""

from __future__ import annotations

from celery import Celery

from webapp.env import env_seconds
from webapp.facades.queue import broker_settings

# A job past the soft limit gets SoftTimeLimitExceeded and ends `failed` with a message; one stuck where that
# cannot reach it (native code) is killed at the hard limit and failed by the worker's main process. Limits need
# the prefork pool (`--pool prefork --concurrency 1`): the solo pool ignores them.
JOB_SOFT_TIME_LIMIT = env_seconds("FACAID_JOB_SOFT_TIME_LIMIT", 600)
JOB_TIME_LIMIT = env_seconds("FACAID_JOB_TIME_LIMIT", 660)

app = Celery("facaid")
app.conf.update(
    **broker_settings(),
    task_acks_late=True,
    task_reject_on_worker_lost=True,
    task_acks_on_failure_or_timeout=True,
    worker_prefetch_multiplier=1,
    task_soft_time_limit=JOB_SOFT_TIME_LIMIT,
    task_time_limit=JOB_TIME_LIMIT,
    worker_hijack_root_logger=False,
)

__all__ = ["JOB_SOFT_TIME_LIMIT", "JOB_TIME_LIMIT", "app"]
