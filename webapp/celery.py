"""The Celery app with the site's tasks: ``celery -A webapp.celery worker -Q gpu,default``."""

import os

import django

os.environ.setdefault("DJANGO_SETTINGS_MODULE", "webapp.settings")
django.setup()

import webapp.facades.tasks  # noqa: E402,F401  (registers the tasks)
from worker.app import app  # noqa: E402

__all__ = ["app"]
