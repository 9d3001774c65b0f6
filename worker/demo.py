"""The demo made before the site opens (``python -m worker demo``, what `scripts/run` runs). The site's ``manage.py
demo --hold`` makes the demo account, its photo, segmentation and job; the worker's own task runs the job here, in
this process, with the shipped model (seconds), so that the first page a newcomer opens has its example. A job that
fails here is queued again for the worker process; one never run is sent by the site's recovery."""

from __future__ import annotations

import sys

from django.core.management import call_command

from webapp.facades.example import DEMO_USERNAME
from webapp.facades.models import Job
from webapp.facades.services import jobs
from worker.tasks import run_job


def make_demo() -> str:
    """Make the demo now (Django set up); what happened, in words."""
    call_command("demo", hold=True)
    held = Job.objects.filter(owner__username=DEMO_USERNAME, status=Job.Status.QUEUED, sent__isnull=True).first()
    if held is None:
        return "the demo was made before"
    run_job.apply(args=[held.id])
    held.refresh_from_db()
    if held.status == Job.Status.DONE:
        return "the demo's procedure is made"
    if held.status != Job.Status.FAILED:  # a worker's recovery sent it and that worker claimed it first
        return "the demo's procedure is being made by the worker"
    print(f"the demo's reconstruction failed here ({held.message}); the worker will make it", file=sys.stderr)
    jobs.submit(owner=held.owner, segmentation=held.segmentation, params=held.params)
    return "the demo's facade is queued for the worker"
