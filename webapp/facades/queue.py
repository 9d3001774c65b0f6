"""The site's side of the job queue. A job is sent by name (`RUN_JOB`) through the Redis broker to the worker
(`worker/`: its Celery app and its task), which the site never imports; the names and the broker's settings here are
the contract both sides read (`worker.app` builds its app on them)."""

from __future__ import annotations

from celery import Celery
from kombu import Queue

from webapp.env import env_int, env_str

RUN_JOB = "facaid.run_job"  # the worker's task, by its name
GPU_QUEUE = "gpu"  # model work
DEFAULT_QUEUE = "default"


def broker_settings() -> dict:
    """The broker and the queues, as the site sends and the worker listens: Redis from REDIS_URL, JSON messages, a
    job routed to the `GPU_QUEUE`, no result backend (a job's state is its row)."""
    return {
        "broker_url": env_str("REDIS_URL", "redis://127.0.0.1:6379/0"),
        "broker_connection_retry_on_startup": True,
        "broker_transport_options": {"visibility_timeout": env_int("FACAID_VISIBILITY_TIMEOUT", 3600, minimum=1)},
        "task_ignore_result": True,
        "task_default_queue": DEFAULT_QUEUE,
        "task_queues": (Queue(DEFAULT_QUEUE), Queue(GPU_QUEUE)),
        "task_routes": {RUN_JOB: {"queue": GPU_QUEUE}},
        "task_serializer": "json",
        "accept_content": ["json"],
    }


sender = Celery("facaid")  # sends only: the tasks are the worker's
sender.conf.update(**broker_settings())


def send(job_id: int) -> None:
    """Send the job's message; no time limits in it: the worker applies its own (FACAID_JOB_*TIME_LIMIT)."""
    sender.send_task(RUN_JOB, args=[job_id], time_limit=None, soft_time_limit=None)


__all__ = ["DEFAULT_QUEUE", "GPU_QUEUE", "RUN_JOB", "broker_settings", "send", "sender"]
