"""The worker process's entry: ``celery -A worker worker -Q gpu,default`` finds this module's ``app`` (Celery looks
for ``worker.celery``). Django is set up first, for the task stores through the site's models."""

import os

import django

os.environ.setdefault("DJANGO_SETTINGS_MODULE", "webapp.settings")
django.setup()

import worker.tasks  # noqa: E402,F401  (registers the task)
from worker.app import app  # noqa: E402

__all__ = ["app"]
