"""Celery tasks of the site. They take job ids, claim the job row, run `worker.compute` and store the result
in our own rows. The worker also runs job recovery at start and every FACAID_RECOVER_SECONDS."""

from __future__ import annotations

import logging
import threading

from celery.exceptions import SoftTimeLimitExceeded, TimeLimitExceeded
from celery.signals import worker_ready
from django.conf import settings
from django.db import OperationalError, close_old_connections, transaction

from facaid.defaults import DEFAULT_K
from webapp.env import env_int
from webapp.facades import jobs
from webapp.facades.models import Job, Procedure, Visibility
from worker import compute
from worker.app import RUN_JOB, app

log = logging.getLogger(__name__)

TRANSIENT = (OperationalError, ConnectionError, TimeoutError)


class _Heartbeat(threading.Thread):
    """Touch the job's heartbeat every few seconds while the computation runs."""

    def __init__(self, job_id: int, every: float):
        super().__init__(daemon=True)
        self.job_id, self.every, self.stop = job_id, every, threading.Event()

    def run(self) -> None:
        while not self.stop.wait(self.every):
            try:
                jobs.beat(self.job_id)
            except Exception:  # a missed beat is not fatal
                log.exception("heartbeat of job %s", self.job_id)
            finally:
                close_old_connections()


class JobTask(app.Task):
    def on_failure(self, exc, task_id, args, kwargs, einfo) -> None:
        """The worker's main process calls this when it killed the task's process at the hard time limit."""
        if isinstance(exc, TimeLimitExceeded) and args:
            try:
                jobs.fail(args[0], f"the job ran longer than the worker's hard time limit ({exc.args[0]:g} s) "
                                   "and was stopped")
            finally:
                close_old_connections()


@app.task(name=RUN_JOB, bind=True, base=JobTask, max_retries=jobs.MAX_ATTEMPTS)
def run_job(self, job_id: int) -> None:
    if not jobs.claim(job_id):
        return  # done, failed, or another worker has it: a duplicate delivery
    heart = _Heartbeat(job_id, env_int("FACAID_HEARTBEAT_SECONDS", 5) or 5)
    heart.start()
    try:
        job = Job.objects.select_related("segmentation__photo").get(id=job_id)
        result = _compute(job)
        _store(job, result)
    except TRANSIENT as exc:
        jobs.release(job_id)
        heart.stop.set()
        if self.request.retries >= self.max_retries:
            jobs.fail(job_id, f"gave up after {self.request.retries + 1} tries: {exc}")
            return
        raise self.retry(exc=exc, countdown=2 ** self.request.retries) from exc
    except SoftTimeLimitExceeded:
        log.warning("job %s ran past the soft time limit", job_id)
        jobs.fail(job_id, f"the job took longer than {self.soft_time_limit or app.conf.task_soft_time_limit:g} s "
                          "and was stopped; try fewer candidates (k) or a smaller segmentation")
    except Exception as exc:
        log.exception("job %s failed", job_id)
        jobs.fail(job_id, f"{type(exc).__name__}: {exc}")
    finally:
        heart.stop.set()


def _compute(job: Job) -> dict:
    params = job.params or {}
    prefix = None
    if params.get("prefix_procedure"):
        prefix = Procedure.objects.get(code=params["prefix_procedure"]).data

    def progress(fraction: float, stage: str) -> None:
        jobs.beat(job.id, fraction, stage)

    return compute.reconstruct(job.segmentation.data, settings.FACAID_CHECKPOINT, k=int(params.get("k", DEFAULT_K)),
                               seed=int(params.get("seed", 0)), prefix=prefix,
                               prefix_nodes=int(params.get("prefix_nodes", 0)), progress=progress)


def _store(job: Job, result: dict) -> None:
    photo = job.segmentation.photo
    with transaction.atomic():
        if Job.objects.select_for_update().filter(id=job.id, status=Job.Status.RUNNING).count() != 1:
            return  # recovered and given to another worker meanwhile
        proc = Procedure.objects.create(
            owner=job.owner, title=photo.title or "", data=result["procedure"], photo=photo,
            segmentation=job.segmentation, accuracy=result["accuracy"],
            metrics={k: result[k] for k in ("accuracy_decoded", "iou", "timings", "source", "retried", "shortcut")
                     if k in result},
            parent=Procedure.objects.filter(id=(job.params or {}).get("parent_id", -1)).first(),  # may be gone
            visibility=(job.params or {}).get("visibility", Visibility.PRIVATE))
        Job.objects.filter(id=job.id).update(status=Job.Status.DONE, progress=1.0, stage="done", result=proc,
                                             finished=proc.created)


def _recover_forever(every: int) -> None:
    import time

    while True:
        try:
            jobs.recover()
        except Exception:
            log.exception("job recovery")
        finally:
            close_old_connections()
        time.sleep(every)


@worker_ready.connect
def _start_recovery(**_) -> None:
    every = env_int("FACAID_RECOVER_SECONDS", 30)
    if every > 0:
        threading.Thread(target=_recover_forever, args=(every,), daemon=True, name="job-recovery").start()
