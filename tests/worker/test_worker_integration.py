"""End to end with a real Redis server and real Celery worker processes: a job runs; a worker killed mid-job,
a Redis restart and a submission while Redis is down lose no job; a job past its time limit fails with a
message; a late job's status says what is happening."""

from __future__ import annotations

import shutil
import time

import pytest
from site_helpers import client_for, facade_png, upload

from webapp.facades.models import Job

pytestmark = [pytest.mark.django_db(transaction=True),
              pytest.mark.skipif(shutil.which("redis-server") is None, reason="needs redis-server")]

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
    assert job.result.metrics["source"] in ("model", "induced") and "timings" in job.result.metrics


def test_a_job_runs_end_to_end(alice, worker):
    worker.start()
    job = submit(alice)
    check_done(wait_for(job, {"done", "failed"}), attempts=1)
    page = client_for(alice).get(f"/procedures/{job.result.code}").content.decode()
    assert "pixel accuracy" in page and 'id="structure"' in page


def status(user, job: Job) -> dict:
    r = client_for(user).get(f"/api/v1/jobs/{job.code}/")
    assert r.status_code == 200
    return r.json()


def test_a_worker_killed_mid_job_loses_no_job_and_its_status_says_so(alice, worker, monkeypatch):
    monkeypatch.setenv("FACAID_HEARTBEAT_SECONDS", "1")  # the site's side: silent for 3 beats is late
    worker.start(FACAID_JOB_STALE_SECONDS="10")
    job = submit(alice)
    wait_for(job, {"running", "done"}, poll=0.02)
    assert job.status == "running", "the job finished before the worker could be killed"
    assert status(alice, job)["note"] == ""
    worker.kill()
    time.sleep(1)
    job.refresh_from_db()
    assert job.status == "running"  # its worker is gone; recovery notices the missing heartbeat
    deadline = time.time() + 8  # no worker runs: nothing recovers it meanwhile
    while "has not reported" not in (now := status(alice, job))["note"] and time.time() < deadline:
        time.sleep(0.2)
    assert now["status"] == "running" and "the worker has not reported for" in now["note"], now
    assert "it may have stopped" in client_for(alice).get(f"/jobs/{job.code}").content.decode()
    worker.start(FACAID_JOB_STALE_SECONDS="10")
    check_done(wait_for(job, {"done", "failed"}), attempts=2)
    assert status(alice, job)["note"] == ""


def test_a_late_queued_job_says_why(alice, bob, redis, worker):
    from datetime import timedelta

    from django.utils import timezone

    from webapp.facades.services import jobs

    redis.stop()
    job = submit(alice)  # not sent: Redis is down
    Job.objects.filter(id=job.id).update(created=timezone.now() - timedelta(seconds=40))
    said = status(alice, job)
    assert said["status"] == "queued" and said["state_seconds"] >= 40 and "could not be reached" in said["note"]
    redis.start()
    assert jobs.recover()["resent"] == 1
    said = status(alice, job)
    assert said["note"].startswith("no worker has taken this job for 4") and "may be down" in said["note"], said
    assert "the worker may be down" in client_for(alice).get(f"/jobs/{job.code}").content.decode()
    other = submit(bob)  # a job a worker is on
    Job.objects.filter(id=other.id).update(status="running", heartbeat=timezone.now())
    said = status(alice, job)["note"]
    assert said.startswith("waiting 4") and said.endswith("for a worker: 1 job running before it"), said
    worker.start()  # recovers the other (its 'worker' never beats) and does both
    check_done(wait_for(job, {"done", "failed"}), attempts=1)
    assert wait_for(other, {"done", "failed"}).status == "done"
    assert status(alice, job)["note"] == ""


def test_the_broker_epoch_tells_a_redis_that_lost_its_data(redis):
    from webapp.facades.services import jobs

    assert jobs.broker_lost_messages()  # the first look: nothing to tell it from a lost one
    assert not jobs.broker_lost_messages()
    redis.stop()
    redis.start()  # without persistence: empty
    assert jobs.broker_lost_messages() and not jobs.broker_lost_messages()


def test_jobs_a_redis_restarted_empty_lost_are_sent_again_at_once(alice, redis, worker):
    """Issue 66: a job stayed 'queued' 310 s after Redis restarted empty (the resend delay, 300 s)."""
    import redis as redis_client

    from webapp.facades.services import jobs

    worker.start()
    assert redis_client.Redis.from_url(redis.url).exists(jobs.EPOCH_KEY)  # its first recovery round marked it
    worker.kill()
    job = submit(alice)  # sent to Redis; no worker takes it
    job.refresh_from_db()
    assert job.status == "queued" and job.sent is not None
    redis.stop()
    redis.start()  # the message died with it
    worker.start(FACAID_JOB_RESEND_SECONDS="300", FACAID_RECOVER_SECONDS="10")  # the real delays
    back = time.time()
    check_done(wait_for(job, {"done", "failed"}, timeout=150), attempts=1)
    assert time.time() - back < 60


def test_a_redis_restart_loses_no_job(alice, redis, worker):
    job = submit(alice)  # sent to Redis; no worker yet
    redis.stop()  # the queued message dies with the server (no persistence)
    redis.start()
    worker.start()
    check_done(wait_for(job, {"done", "failed"}), attempts=1)


def test_rerun_from_a_prefix_and_a_failure_is_recorded(alice, worker):
    from facaid.decoding import prefix_from_procedure
    from facaid.grammar import Procedure as Tree
    from facaid.paths import DEFAULT_CHECKPOINT
    from facaid.tokenizer import Tokenizer
    from webapp.facades.models import Procedure

    worker.start()
    first = wait_for(submit(alice), {"done", "failed"})
    check_done(first, attempts=1)
    client = client_for(alice)
    r = client.post(f"/api/v1/procedures/{first.result.code}/rerun", {"nodes": 3, "k": 2}, format="json")
    assert r.status_code == 202
    rerun = wait_for(Job.objects.get(code=r.json()["code"]), {"done", "failed"})
    check_done(rerun, attempts=1)
    assert rerun.result_id == first.result_id and rerun.result_version == 2  # the procedure's next version
    [made, continued] = [rerun.result.versions.get(version=n) for n in (2, 1)]
    assert made.kind == "rerun" and made.based_on == 1 and made.data == rerun.result.data
    tok = Tokenizer.load(DEFAULT_CHECKPOINT / "tokenizer.json")  # the tokenizer alone, not the model

    def structure(data):  # the first three nodes without their sizes (the sizing refits those)
        ids = prefix_from_procedure(tok, Tree.from_dict(data), 3)
        return [t for t in ids if tok.vocab.kinds[t] not in ("abs", "flt", "rel")]

    assert structure(made.data) == structure(continued.data)
    # a job whose prefix procedure was deleted before it ran fails with a message; the worker goes on
    worker.kill()
    r = client.post(f"/api/v1/procedures/{first.result.code}/rerun", {"nodes": 2}, format="json")
    doomed = Job.objects.get(code=r.json()["code"])
    Procedure.objects.filter(id=first.result_id).delete()
    worker.start()
    doomed = wait_for(doomed, {"done", "failed"})
    assert doomed.status == "failed" and "DoesNotExist" in doomed.message
    check_done(wait_for(submit(alice), {"done", "failed"}), attempts=1)


def test_a_job_submitted_while_redis_is_down_runs_soon_after_it_is_back(alice, redis, worker):
    redis.stop()
    started = time.time()
    job = submit(alice)  # the publish fails; the job is still accepted
    assert time.time() - started < 15
    job.refresh_from_db()
    assert job.status == "queued" and job.sent is None  # not recorded as sent: recovery sends it at once
    redis.start()
    worker.start(FACAID_JOB_RESEND_SECONDS="300", FACAID_RECOVER_SECONDS="30")  # the real delays
    back = time.time()
    check_done(wait_for(job, {"done", "failed"}, timeout=200), attempts=1)
    assert time.time() - back < 150  # the worker's first recovery round, not the 300 s resend delay


def test_a_job_past_its_soft_time_limit_fails_with_a_message(alice, worker):
    worker.start(FACAID_JOB_SOFT_TIME_LIMIT="1", FACAID_JOB_TIME_LIMIT="120")
    job = wait_for(submit(alice, k=32), {"done", "failed"})  # loading the model alone takes longer
    assert job.status == "failed" and "took longer than 1 s and was stopped" in job.message, job.message
    assert job.result is None


def test_a_job_past_its_hard_time_limit_is_killed_and_fails(alice, worker):
    worker.start(FACAID_JOB_SOFT_TIME_LIMIT="0", FACAID_JOB_TIME_LIMIT="2")
    job = wait_for(submit(alice, k=32), {"done", "failed"})
    assert job.status == "failed" and "hard time limit (2 s)" in job.message, job.message
    assert worker.proc.poll() is None  # the worker lives on with a new process for the next job
