"""``python manage.py demo``: a demo account with a demo facade photo (a photo-like picture of a generated facade,
`facaid.photo.photolike`), its segmentation and its reconstruction into a public procedure, the front page's example
(`webapp.facades.example`): queued for the worker, or with ``--hold`` its job made but not sent, for the worker to run
at once in its own process before the site opens (``python -m worker demo``, which `scripts/run` runs: the first page
a newcomer opens has its example). Does nothing if the account exists."""

from __future__ import annotations

import io

from django.contrib.auth import get_user_model
from django.core.files.images import ImageFile
from django.core.management.base import BaseCommand

from facaid.defaults import DEFAULT_K
from facaid.generator import generate
from facaid.photo.photolike import render_photo
from webapp.facades.example import DEMO_PASSWORD, DEMO_USERNAME
from webapp.facades.models import Job, Photo, Segmentation, Visibility
from webapp.facades.services import jobs


class Command(BaseCommand):
    help = "Create the demo account (demo / demo-facade) with a demo facade and queue its reconstruction."

    def add_arguments(self, parser):
        parser.add_argument("--seed", type=int, default=3, help="generator seed of the demo facade")
        parser.add_argument("--hold", action="store_true",
                            help="make its job but do not send it (python -m worker demo runs it at once)")

    def handle(self, *args, seed: int, hold: bool = False, **options):
        users = get_user_model()
        if users.objects.filter(username=DEMO_USERNAME).exists():
            self.stdout.write(f"demo account exists: log in as {DEMO_USERNAME} / {DEMO_PASSWORD}")
            return
        user = users.objects.create_user(DEMO_USERNAME, "demo@example.com", DEMO_PASSWORD)
        sample = generate(seed)
        buf = io.BytesIO()
        render_photo(sample.segmentation, seed).save(buf, "PNG")  # a photo of it, made here: walls, glass, light
        photo = Photo(owner=user, title=f"Demo facade ({sample.style})", visibility=Visibility.PUBLIC)
        buf.seek(0)
        photo.image.save("photo.png", ImageFile(buf, name="photo.png"), save=False)
        photo.save()
        seg = Segmentation.objects.create(photo=photo, version=1, data=sample.segmentation.to_dict(),
                                          rect_count=len(sample.segmentation.rects))
        fields = {"owner": user, "segmentation": seg,
                  "params": {"k": DEFAULT_K, "seed": 0, "visibility": Visibility.PUBLIC}}
        if hold:
            job = Job.objects.create(**fields)
            made = f"its job {job.id} is held for the worker"
        else:
            jobs.submit(**fields)
            made = "its facade is queued"
        self.stdout.write(f"demo account created: log in as {DEMO_USERNAME} / {DEMO_PASSWORD}; {made}")
