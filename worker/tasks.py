"""The worker's task (`RUN_JOB`, which the site sends by name): it takes a job id, claims the job's row, runs
`worker.compute` and stores the result through the site's models. The worker also runs the site's job recovery at
start and every FACAID_RECOVER_SECONDS."""

from __future__ import annotations

import logging
import threading

from celery.exceptions import SoftTimeLimitExceeded, TimeLimitExceeded
from celery.signals import worker_ready
from django.conf import settings
from django.db import OperationalError, close_old_connections, transaction
from django.utils import timezone

from facaid.defaults import DEFAULT_K
from webapp.env import env_int
from webapp.facades import access, editcheck
from webapp.facades.models import Change, Job, Photo, Procedure, ProcedureVersion, Visibility, tree_digest
from webapp.facades.queue import RUN_JOB
from webapp.facades.services import jobs, versions
from worker import compute
from worker.app import app

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
    heart = _Heartbeat(job_id, jobs.heartbeat_every())
    heart.start()
    try:
        job = Job.objects.select_related("segmentation__photo").get(id=job_id)
        if not access.photo_visible_to(job.owner, job.segmentation.photo):  # made private while it was queued
            jobs.fail(job_id, MADE_PRIVATE)
            return
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


# a fork's re-run (its owner is not the photo's) whose photo its owner made private before the result was stored
MADE_PRIVATE = "the photo was made private while this job ran, so nothing of it was stored"

# the notes of a real facade's two first versions (`facaid.pipeline.reconstruct`)
STRUCTURE_NOTES = {"editable": "editable: floors of tiles with exceptions, what the parameters edit",
                   "exact": "exact: the annotation as drawn"}


def _compute(job: Job) -> dict:
    params = job.params or {}
    prefix = None
    if params.get("prefix_version"):  # the version that was current when the re-run was asked for
        prefix = ProcedureVersion.objects.get(procedure__code=params["prefix_procedure"],
                                              version=params["prefix_version"]).data
    elif params.get("prefix_procedure"):  # a job queued before procedures had versions
        prefix = Procedure.objects.get(code=params["prefix_procedure"]).data

    def progress(fraction: float, stage: str) -> None:
        jobs.beat(job.id, fraction, stage)

    return compute.reconstruct(job.segmentation.data, settings.FACAID_CHECKPOINT, k=int(params.get("k", DEFAULT_K)),
                               seed=int(params.get("seed", 0)), prefix=prefix,
                               prefix_nodes=int(params.get("prefix_nodes", 0)), progress=progress,
                               structure=params.get("structure", "editable"))


def _still_shared(job: Job) -> bool:
    """May the job's owner still see its photo? Read again, its row locked, inside the transaction that stores the
    result: a photo made private while the job ran (by its owner, of a fork's re-run) either waits for the store to
    commit, then hides what was stored with the rest, or is seen private here, and nothing is stored."""
    photo = Photo.objects.select_for_update().filter(id=job.segmentation.photo_id).first()
    return photo is not None and access.photo_visible_to(job.owner, photo)


def _store(job: Job, result: dict) -> None:
    """The result as a new procedure, or, for a re-run of the owner's procedure against its own segmentation, as
    that procedure's next version (`versions.add_rerun`); nothing, and the job failed, where its owner may no longer
    see the photo."""
    photo, params = job.segmentation.photo, job.params or {}
    # the edits of each tree checked here, before any row is locked (the saves below find them and keep them)
    metrics = editcheck.checked(result["metrics"], result["procedure"], tree_digest(result["procedure"]))
    other = result.get("alternative")
    if other:
        other_metrics = editcheck.checked(other["metrics"], other["procedure"], tree_digest(other["procedure"]))
    with transaction.atomic():
        if Job.objects.select_for_update().filter(id=job.id, status=Job.Status.RUNNING).count() != 1:
            return  # recovered and given to another worker meanwhile
        if not _still_shared(job):
            jobs.fail(job.id, MADE_PRIVATE)
            return
        if params.get("as_version") and params.get("prefix_version"):
            proc = Procedure.objects.select_for_update().filter(id=params["parent_id"]).first()
            if proc is None:
                jobs.fail(job.id, "the procedure to re-run was deleted while the job ran")
                return
            version = versions.add_rerun(proc, result["procedure"], result["accuracy"], metrics,
                                         params["prefix_version"], int(params["prefix_nodes"])).version
        else:
            parent = Procedure.objects.filter(id=params.get("parent_id", -1)).first()  # may be gone
            title = photo.title or ""
            if params.get("prefix_nodes"):  # told apart from the procedure it continued
                title = f"{parent or title or 'Procedure'} · re-run keeping {params['prefix_nodes']} nodes"
            proc = Procedure(owner=job.owner, title=title[:200], photo=photo, segmentation=job.segmentation,
                             parent=parent, visibility=params.get("visibility", Visibility.PRIVATE),
                             data=result["procedure"])
            proc.take_photo_scale()  # its own from now on: a fork keeps it, an edit leaves it
            if other:  # a real facade's other procedure: its first version, one revert away
                proc.data, proc.accuracy, proc.metrics = other["procedure"], other["accuracy"], other_metrics
                proc.save(change=Change(ProcedureVersion.Kind.CREATED, STRUCTURE_NOTES[other["structure"]]))
            proc.data, proc.accuracy, proc.metrics = result["procedure"], result["accuracy"], metrics
            proc.save(change=Change(ProcedureVersion.Kind.CREATED, STRUCTURE_NOTES.get(result.get("structure"), "")
                                    if other else ""))
            version = 2 if other else 1
        Job.objects.filter(id=job.id).update(status=Job.Status.DONE, progress=1.0, stage="done", result=proc,
                                             result_version=version, finished=timezone.now())


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
    every = env_int("FACAID_RECOVER_SECONDS", 10)
    if every > 0:
        threading.Thread(target=_recover_forever, args=(every,), daemon=True, name="job-recovery").start()
