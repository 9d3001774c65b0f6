"""The life of a job: submitted under its owner's cap (`submit_job`; the task is sent once the row is committed),
claimed (a conditional update, so a message delivered twice runs once), heartbeat, finish, and recovery of jobs
whose message or worker was lost."""

from __future__ import annotations

import logging
from datetime import datetime, timedelta

from django.conf import settings
from django.contrib.auth import get_user_model
from django.db import transaction
from django.db.models import F, Q
from django.utils import timezone

from facaid.defaults import DEFAULT_K
from webapp.env import env_int
from webapp.facades import queue
from webapp.facades.errors import TooManyJobs
from webapp.facades.models import Job, Procedure, Segmentation, check_quota

log = logging.getLogger(__name__)

MAX_ATTEMPTS = 3


def stale_after() -> timedelta:
    """A running job whose heartbeat is older than this has lost its worker."""
    return timedelta(seconds=env_int("FACAID_JOB_STALE_SECONDS", 30))


def heartbeat_every() -> int:
    return env_int("FACAID_HEARTBEAT_SECONDS", 5) or 5


def resend_after() -> timedelta:
    """A queued job not claimed this long after its message was sent is sent again (the message may be lost)."""
    return timedelta(seconds=env_int("FACAID_JOB_RESEND_SECONDS", 300))


# a queued job waiting longer than this, or a running one whose worker has been silent for this many heartbeats,
# says what may be happening
WAITING_SECONDS, SILENT_BEATS = 30, 3


def _plural(n: int, word: str) -> str:
    return f"{n} {word}{'' if n == 1 else 's'}"


def state(job: Job, now=None) -> tuple[datetime, str]:
    """When the job entered its status (a queued job put back after a failure or a lost worker: when it was put
    back), and, for one that is late, a sentence saying what is happening, else ""."""
    now = now or timezone.now()
    if job.status in (Job.Status.DONE, Job.Status.FAILED):
        return job.finished or job.created, ""
    if job.status == Job.Status.RUNNING:
        silent = int((now - (job.heartbeat or job.started or now)).total_seconds())
        if silent < SILENT_BEATS * heartbeat_every():
            return job.started or job.created, ""
        return job.started or job.created, (
            f"the worker has not reported for {silent} s: it may have stopped; the job is queued again once it has "
            f"been silent for {int(stale_after().total_seconds())} s")
    since = job.heartbeat or job.created  # release and recover touch it as they queue the job again
    waited = int((now - since).total_seconds())
    if waited < WAITING_SECONDS:
        return since, ""
    if job.sent is None:
        return since, (f"not in the queue for {waited} s: the queue (Redis) could not be reached; the job is sent "
                       "again as soon as it answers")
    ahead = Job.objects.filter(status=Job.Status.RUNNING, heartbeat__gte=now - stale_after()).exclude(
        id=job.id).count()
    if ahead:
        return since, f"waiting {waited} s for a worker: {_plural(ahead, 'job')} running before it"
    return since, (f"no worker has taken this job for {waited} s: the worker may be down; it runs once one is "
                   "back (a job lost from the queue is sent again)")


def send(job_id: int) -> None:
    """Publish the job's task (by name: this module does not import the tasks, which import it), then record
    when: a publish that fails (the broker is down) leaves ``sent`` as it was, so recovery sends the job again at
    its next round instead of after the resend delay."""
    queue.send(job_id)
    Job.objects.filter(id=job_id).update(sent=timezone.now())


def submit(**fields) -> Job:
    """Create a queued job; its task is sent when the transaction commits."""
    job = Job.objects.create(**fields)
    transaction.on_commit(lambda: _send_quietly(job.id))
    return job


QUOTA_ROOM = 64 * 1024  # bytes of versions a job's result needs at most, about (two versions of a large tree)


def submit_job(user, segmentation: Segmentation, k=DEFAULT_K, seed=0, prefix: Procedure | None = None,
               prefix_nodes: int = 0, structure: str = "editable") -> Job:
    """Queue a reconstruction; `TooManyJobs` when the user already has FACAID_MAX_ACTIVE_JOBS waiting or
    running, so that one account cannot fill the workers' queue. A re-run from a prefix continues the prefix
    procedure's current version; of the user's own procedure against its own segmentation, its result is that
    procedure's next version, else a new procedure whose parent it is. ``structure``: which of a real facade's two
    procedures is current (`facaid.pipeline.reconstruct`); the other is its first version."""
    params = {"k": k, "seed": seed, "structure": structure}
    if prefix is not None and prefix_nodes > 0:
        current = prefix.current_version()
        params.update(prefix_procedure=str(prefix.code), prefix_nodes=prefix_nodes, parent_id=prefix.id,
                      prefix_version=current.version if current else None,
                      as_version=prefix.owner_id == user.id and prefix.segmentation_id == segmentation.id)
    with transaction.atomic():  # the count and the new row together: two submissions at once cannot both pass
        get_user_model().objects.select_for_update().filter(pk=user.pk).first()
        active = Job.objects.filter(owner=user, status__in=(Job.Status.QUEUED, Job.Status.RUNNING)).count()
        if active >= settings.FACAID_MAX_ACTIVE_JOBS:
            raise TooManyJobs(f"You have {active} reconstructions waiting or running (at most "
                              f"{settings.FACAID_MAX_ACTIVE_JOBS}); submit more when one has finished.")
        check_quota(user.pk, QUOTA_ROOM)  # a full quota refuses the job now, not its result after the work
        return submit(owner=user, segmentation=segmentation, params=params)


def _send_quietly(job_id: int) -> None:
    try:
        send(job_id)
    except Exception:  # the broker is down: the row stays queued and recovery sends it later
        log.exception("could not send job %s; it will be re-sent", job_id)


def claim(job_id: int) -> bool:
    """Take a queued job for this worker; False if another worker has it or it is finished."""
    now = timezone.now()
    return Job.objects.filter(id=job_id, status=Job.Status.QUEUED).update(
        status=Job.Status.RUNNING, started=now, heartbeat=now, attempts=F("attempts") + 1, progress=0.0,
        stage="starting") == 1


def beat(job_id: int, progress: float | None = None, stage: str | None = None) -> None:
    fields = {"heartbeat": timezone.now()}
    if progress is not None:
        fields["progress"] = max(0.0, min(1.0, progress))
    if stage is not None:
        fields["stage"] = stage[:100]
    Job.objects.filter(id=job_id, status=Job.Status.RUNNING).update(**fields)


def fail(job_id: int, message: str) -> None:
    Job.objects.filter(id=job_id).exclude(status=Job.Status.DONE).update(
        status=Job.Status.FAILED, message=message[:2000], finished=timezone.now())


def release(job_id: int) -> None:
    """Give a running job back to the queue (a transient error; it will be retried)."""
    Job.objects.filter(id=job_id, status=Job.Status.RUNNING).update(status=Job.Status.QUEUED, stage="retrying",
                                                                    heartbeat=timezone.now())


# A key the workers keep in the broker's Redis. A Redis that restarted without its data (no append-only file) lost
# it, and with it every message it held: then every queued job is sent again at once, not after the resend delay.
EPOCH_KEY = "facaid:broker-epoch"


def broker_lost_messages() -> bool:
    """Has the broker's Redis lost its data since the last look (or is this the first look)? Sets the key again."""
    import redis

    client = redis.Redis.from_url(queue.sender.conf.broker_url, socket_timeout=5, socket_connect_timeout=5)
    try:
        return bool(client.set(EPOCH_KEY, timezone.now().isoformat(), nx=True))
    finally:
        client.close()


def recover() -> dict[str, int]:
    """Re-queue running jobs whose worker stopped beating (failing those out of attempts) and re-send queued
    jobs whose message seems lost: not sent, sent long ago, or sent to a Redis that has lost its data since.
    Safe to run anywhere, any number of times (a message delivered twice runs once)."""
    now = timezone.now()
    requeued = failed = resent = 0
    try:
        lost = broker_lost_messages()
    except Exception:  # Redis is down: the resends below fail too, and are tried at the next round
        log.warning("job recovery: the broker cannot be reached")
        lost = False
    for job in Job.objects.filter(status=Job.Status.RUNNING, heartbeat__lt=now - stale_after()):
        if job.attempts >= MAX_ATTEMPTS:
            failed += Job.objects.filter(id=job.id, status=Job.Status.RUNNING, heartbeat=job.heartbeat).update(
                status=Job.Status.FAILED, finished=now,
                message=f"the worker stopped responding {job.attempts} times; giving up")
        elif Job.objects.filter(id=job.id, status=Job.Status.RUNNING, heartbeat=job.heartbeat).update(
                status=Job.Status.QUEUED, stage="worker lost; queued again", sent=None, heartbeat=now):
            requeued += 1
    queued = Job.objects.filter(status=Job.Status.QUEUED)
    if not lost:
        queued = queued.filter(Q(sent__isnull=True) | Q(sent__lt=now - resend_after()))
    for job_id in queued.values_list("id", flat=True):
        try:
            send(job_id)
            resent += 1
        except Exception:
            log.exception("could not re-send job %s", job_id)
            break
    if requeued or failed or resent:
        log.warning("job recovery: %d requeued, %d failed, %d re-sent", requeued, failed, resent)
    return {"requeued": requeued, "failed": failed, "resent": resent}
