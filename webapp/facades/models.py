"""Photos, their segmentations (versioned), reconstruction jobs and procedures (versioned: every save of a tree
is a new `ProcedureVersion`, stored compressed, and none is ever changed or deleted but with its procedure). What an
account stores, photos, segmentations and procedures, is within its quota (`check_quota`). Every object is addressed
by a UUID ``code``; photos and procedures carry a visibility (private, unlisted, public)."""

from __future__ import annotations

import hashlib
import json
import re
import uuid
from dataclasses import dataclass

from django.conf import settings
from django.db import models, transaction
from django.urls import reverse
from django.utils import timezone

from webapp.facades import editcheck
from webapp.facades.errors import QuotaError
from webapp.facades.fields import CompressedJSONField, pack


class Visibility(models.TextChoices):
    PRIVATE = "private", "Private"  # the owner only
    UNLISTED = "unlisted", "Unlisted"  # anyone with the link
    PUBLIC = "public", "Public"  # anyone, and listed in the gallery


REAL_SIZE_M = (0.5, 1000.0)  # the real width or height of a facade a user may give, in metres: a shed to a tower


UNSAFE_IN_NAMES = re.compile(r'[\x00-\x1f\x7f/\\:*?"<>|]+')  # what a file name may not hold: folders, and more


def photo_path(photo: Photo, filename: str) -> str:
    return f"photos/{photo.code}/original.{filename.rsplit('.', 1)[-1].lower()}"


def rectified_path(photo: Photo, filename: str) -> str:
    return f"photos/{photo.code}/rectified.{filename.rsplit('.', 1)[-1].lower()}"  # .jpg (.png before issue 66)


class Photo(models.Model):
    code = models.UUIDField(default=uuid.uuid4, unique=True, editable=False)
    owner = models.ForeignKey(settings.AUTH_USER_MODEL, on_delete=models.CASCADE, related_name="photos")
    title = models.CharField(max_length=200, blank=True)
    image = models.ImageField(upload_to=photo_path, width_field="width", height_field="height")
    width = models.PositiveIntegerField(default=0)
    height = models.PositiveIntegerField(default=0)
    # rectification: four corners (x, y) in the original image, top-left, top-right, bottom-right, bottom-left
    corners = models.JSONField(null=True, blank=True)
    rectified = models.ImageField(upload_to=rectified_path, null=True, blank=True)
    # the facade's real size as the user gave it, its width or its height in metres (one of the two): kept rather
    # than metres per pixel so that it stays true when the photo is rectified again (another image size)
    real_width_m = models.FloatField(null=True, blank=True)
    real_height_m = models.FloatField(null=True, blank=True)
    visibility = models.CharField(max_length=10, choices=Visibility.choices, default=Visibility.PRIVATE)
    created = models.DateTimeField(default=timezone.now)
    stored_bytes = models.PositiveBigIntegerField(default=0)  # its files' bytes, the original's and the rectified's

    class Meta:
        ordering = ["-created"]

    def __str__(self) -> str:
        return self.title or f"photo {self.code}"

    def file_bytes(self) -> int:
        """Bytes its files take in storage (what `stored_bytes` keeps, for the quota)."""
        return sum(field.size for field in (self.image, self.rectified) if field)

    def get_absolute_url(self) -> str:
        return reverse("photo", args=[self.code])

    def working_image(self):
        """The image segmentations are drawn on: the rectified one when there is one."""
        return self.rectified if self.rectified else self.image

    def working_size(self) -> tuple[int, int]:
        return (self.rectified.width, self.rectified.height) if self.rectified else (self.width, self.height)

    def file_name(self, rectified: bool = False) -> str:
        """The photo as an annotation file names its picture: its title where it has one (as a file name: no
        folders, no characters a file system refuses), else ``facaid-photo-<code>``; ``-rectified`` for the
        rectified image; the extension of the image stored."""
        base = UNSAFE_IN_NAMES.sub("-", self.title).strip(" .-")[:100] or f"facaid-photo-{str(self.code)[:8]}"
        rectified = rectified and bool(self.rectified)
        field = self.rectified if rectified else self.image
        return f"{base}{'-rectified' if rectified else ''}.{field.name.rsplit('.', 1)[-1].lower()}"

    def metres_per_pixel(self, size: tuple[float, float] | None = None) -> float | None:
        """The real size over the pixels of an image of the facade of ``size`` (by default the working image's):
        None when no real size is given."""
        w, h = size or self.working_size()
        if self.real_width_m is not None and w > 0:
            return self.real_width_m / w
        if self.real_height_m is not None and h > 0:
            return self.real_height_m / h
        return None

    def latest_segmentation(self) -> Segmentation | None:
        return self.segmentations.order_by("-version").first()

    def rescale_procedures(self) -> int:
        """After its real size changed: its owner's procedures made from it take the scale it now gives (others'
        forks keep the one they were made with). The number changed."""
        changed = 0
        for proc in self.procedures.filter(owner_id=self.owner_id).only("id", "data", "photo_id", "metres_per_pixel",
                                                                        "scale_from"):
            proc.photo = self
            before = (proc.metres_per_pixel, proc.scale_from)
            proc.take_photo_scale()
            if (proc.metres_per_pixel, proc.scale_from) != before:
                Procedure.objects.filter(id=proc.id).update(metres_per_pixel=proc.metres_per_pixel,
                                                            scale_from=proc.scale_from)
                changed += 1
        return changed


class Segmentation(models.Model):
    """One version of a photo's segmentation (the segmentation JSON contract); saving makes a new version."""

    code = models.UUIDField(default=uuid.uuid4, unique=True, editable=False)
    photo = models.ForeignKey(Photo, on_delete=models.CASCADE, related_name="segmentations")
    version = models.PositiveIntegerField()
    data = models.JSONField()
    rect_count = models.PositiveIntegerField(default=0)
    size = models.PositiveIntegerField(default=0)  # bytes of its JSON (`json_size`), for the quota
    created = models.DateTimeField(default=timezone.now)

    class Meta:
        ordering = ["photo", "-version"]
        constraints = [models.UniqueConstraint(fields=["photo", "version"], name="one_segmentation_per_version")]

    def __str__(self) -> str:
        return f"{self.photo} v{self.version}"


class Draft(models.Model):
    """The owner's unsaved segmentation of a photo as the editor last sent it (one a photo): kept so that work
    survives another browser or a lost tab; saving a version removes it."""

    photo = models.OneToOneField(Photo, on_delete=models.CASCADE, related_name="draft")
    data = models.JSONField()
    rect_count = models.PositiveIntegerField(default=0)
    size = models.PositiveIntegerField(default=0)  # bytes of its JSON (`json_size`), for the quota
    updated = models.DateTimeField(default=timezone.now)

    def __str__(self) -> str:
        return f"{self.photo} draft"


def json_size(data) -> int:
    """Bytes a JSON value takes written out compactly: what a JSON column holds of it, uncompressed."""
    return len(json.dumps(data, separators=(",", ":"), allow_nan=False, ensure_ascii=False).encode())


def stored_bytes(owner_id) -> dict[str, int]:
    """Bytes an account stores, by kind: its photos' files (the original and the rectified image), its
    segmentations (every version and the drafts, as JSON), and its procedures (each current tree as JSON, and every
    version, compressed)."""
    def total(rows, field: str) -> int:
        return rows.aggregate(total=models.Sum(field))["total"] or 0

    return {"photos": total(Photo.objects.filter(owner_id=owner_id), "stored_bytes"),
            "segmentations": total(Segmentation.objects.filter(photo__owner_id=owner_id), "size")
            + total(Draft.objects.filter(photo__owner_id=owner_id), "size"),
            "procedures": total(Procedure.objects.filter(owner_id=owner_id), "data_size")
            + total(ProcedureVersion.objects.filter(procedure__owner_id=owner_id), "size")}


def check_quota(owner_id, size: int, replaced: int = 0) -> None:
    """Refuse a write of ``size`` bytes (in place of ``replaced`` bytes stored now) that would take its owner past
    ``FACAID_STORAGE_QUOTA_MB``; nothing stored is touched. Called before the write, or inside its transaction
    after it (where the rows written count already: ``size`` is then what is still to come)."""
    quota = settings.FACAID_STORAGE_QUOTA_MB * 2**20
    used = stored_bytes(owner_id)
    total = sum(used.values())
    if size > 0 and total - replaced + size > quota:
        kinds = ", ".join(f"{kind} {n / 2**20:.1f} MB" for kind, n in used.items())
        raise QuotaError(
            f"your account stores {total / 2**20:.1f} MB of its {quota / 2**20:g} MB ({kinds}), and this needs "
            f"{size / 2**10:.0f} KB more: delete photos or procedures you no longer need (a procedure's versions "
            "go with it); nothing was saved")


def tree_digest(data: dict) -> str:
    """16 hex digits naming a procedure JSON (its keys sorted); migration 0003 writes the same out."""
    text = json.dumps(data, sort_keys=True, separators=(",", ":"), allow_nan=False)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


class Procedure(models.Model):
    code = models.UUIDField(default=uuid.uuid4, unique=True, editable=False)
    owner = models.ForeignKey(settings.AUTH_USER_MODEL, on_delete=models.CASCADE, related_name="procedures")
    title = models.CharField(max_length=200, blank=True)
    data = models.JSONField()  # procedure JSON (facaid.grammar)
    photo = models.ForeignKey(Photo, on_delete=models.SET_NULL, null=True, blank=True, related_name="procedures")
    segmentation = models.ForeignKey(Segmentation, on_delete=models.SET_NULL, null=True, blank=True,
                                     related_name="procedures")
    parent = models.ForeignKey("self", on_delete=models.SET_NULL, null=True, blank=True, related_name="forks")
    accuracy = models.FloatField(null=True, blank=True)  # pixel accuracy against the segmentation
    metrics = models.JSONField(default=dict, blank=True)
    # its own scale: metres per pixel of its tree and where they came from (its photo's real size when it was made,
    # its parent's for a fork, or its owner's); the metric downloads' scale, kept across edits (migration 0009)
    metres_per_pixel = models.FloatField(null=True, blank=True)
    scale_from = models.CharField(max_length=200, blank=True)
    # names the tree in `data` (tree_digest): its kept pictures' names and ETags, read without `data`
    digest = models.CharField(max_length=16, blank=True, editable=False)
    data_size = models.PositiveIntegerField(default=0, editable=False)  # bytes of `data` (`json_size`): the quota's
    visibility = models.CharField(max_length=10, choices=Visibility.choices, default=Visibility.PRIVATE)
    created = models.DateTimeField(default=timezone.now)
    updated = models.DateTimeField(auto_now=True)

    class Meta:
        ordering = ["-created"]

    def __str__(self) -> str:
        return self.title or f"procedure {self.code}"

    def get_absolute_url(self) -> str:
        return reverse("procedure", args=[self.code])

    def save(self, *args, change: Change | None = None, **kwargs) -> None:
        """Save, and record the tree as a new version (`_record_version`): when it differs from the latest
        version's, or when ``change`` is more than an edit (a revert, a re-run); so a save of the title or visibility
        alone, or of the same tree again, records none. A tree written has its edits checked (`editcheck.checked`:
        ``metrics["edits"]``), unless its metrics hold the verdicts of this very tree already (a fork, a revert)."""
        fields = kwargs.get("update_fields")
        writes_tree = "data" in fields if fields is not None else "data" not in self.get_deferred_fields()
        if writes_tree:
            self.digest, self.data_size = tree_digest(self.data), json_size(self.data)
            # its edits checked (or kept, where its metrics judged this tree already), before any row is locked
            self.metrics = editcheck.checked(self.metrics, self.data, self.digest)
            if fields is not None:
                kwargs["update_fields"] = {*fields, "digest", "data_size", "metrics"}
        with transaction.atomic(using=kwargs.get("using")):
            super().save(*args, **kwargs)  # first: the row's write lock orders racing saves' version numbers
            if writes_tree:
                self._record_version(change)

    def _record_version(self, change: Change | None) -> None:
        """The versioning rule: a tree is a new version unless it is the latest one's and nothing but an edit made
        it (a save of an unchanged tree, parameters set to what they were): then the latest stays current."""
        latest = self.versions.order_by("-version").values("version", "digest").first()
        unchanged = latest is not None and latest["digest"] == self.digest
        if change is None or change.kind == ProcedureVersion.Kind.EDIT:
            if unchanged:
                return
            change = change or Change(ProcedureVersion.Kind.EDIT if latest else ProcedureVersion.Kind.CREATED)
        packed = pack(self.data)  # stored as it is: the field compresses only what is not compressed yet
        check_quota(self.owner_id, len(packed))  # with the tree just written: a refusal rolls both back
        ProcedureVersion.objects.create(
            procedure=self, version=(latest["version"] if latest else 0) + 1, data=packed, size=len(packed),
            digest=self.digest,
            accuracy=self.accuracy, metrics=self.metrics, kind=change.kind, note=change.note[:200],
            based_on=change.based_on, warning=change.warning[:300])

    def current_version(self) -> ProcedureVersion | None:
        """The latest version: the one whose tree the procedure holds."""
        return self.versions.defer("data").order_by("-version").first()

    def drawn_on_original(self) -> bool:
        """Whether the procedure was drawn on its photo's original image, not the rectified one (it has the
        original's size, drawn before rectification)."""
        photo = self.photo
        size = (self.data.get("width", 0), self.data.get("height", 0))
        return bool(photo.rectified) and (round(size[0]), round(size[1])) == (photo.width, photo.height)

    def photo_scale(self) -> tuple[float, str] | None:
        """The scale its photo's real size gives (the real width or height over the pixels of the image the
        procedure was drawn on) and a line saying so; None without a photo or a real size."""
        photo = self.photo
        if photo is None or (photo.real_width_m is None and photo.real_height_m is None):
            return None
        scale = photo.metres_per_pixel((photo.width, photo.height) if self.drawn_on_original() else None)
        if scale is None:
            return None
        what = (f"the photo's real width, {photo.real_width_m:g} m" if photo.real_width_m is not None
                else f"the photo's real height, {photo.real_height_m:g} m")
        return scale, what

    def take_photo_scale(self) -> None:
        """Its own scale set to its photo's (`photo_scale`), or none where the photo has no real size (not saved)."""
        given = self.photo_scale()
        self.metres_per_pixel, self.scale_from = given if given else (None, "")

    def lineage(self) -> list[Procedure]:
        """Ancestors, nearest first (forks of forks), stopping at a cycle or a deleted parent."""
        out, seen, node = [], {self.pk}, self.parent
        while node is not None and node.pk not in seen and len(out) < 50:
            out.append(node)
            seen.add(node.pk)
            node = node.parent
        return out


@dataclass(frozen=True)
class Change:
    """What made a version: its kind, a line for the history, the version it was made from (the one a revert
    restores or a re-run continued) and a warning (a re-run that fits worse than that one)."""

    kind: str
    note: str = ""
    based_on: int | None = None
    warning: str = ""


class ProcedureVersion(models.Model):
    """One saved tree of a procedure, with its figures as measured when it was saved (against the procedure's
    segmentation, which never changes). Written once, never edited: a revert is a new version."""

    class Kind(models.TextChoices):
        CREATED = "created", "Created"
        EDIT = "edit", "Edited"
        REVERT = "revert", "Reverted"
        RERUN = "rerun", "Re-run"

    procedure = models.ForeignKey(Procedure, on_delete=models.CASCADE, related_name="versions")
    version = models.PositiveIntegerField()
    data = CompressedJSONField()  # the tree, zlib-compressed JSON (migration 0007)
    size = models.PositiveIntegerField(default=0)  # bytes stored: what the owner's quota adds up
    digest = models.CharField(max_length=16)  # tree_digest(data): the ETag of its picture
    accuracy = models.FloatField(null=True, blank=True)
    metrics = models.JSONField(default=dict, blank=True)
    kind = models.CharField(max_length=10, choices=Kind.choices)
    note = models.CharField(max_length=200, blank=True)
    based_on = models.PositiveIntegerField(null=True, blank=True)
    warning = models.CharField(max_length=300, blank=True)
    created = models.DateTimeField(default=timezone.now)

    class Meta:
        ordering = ["procedure", "-version"]
        constraints = [models.UniqueConstraint(fields=["procedure", "version"], name="one_procedure_version")]

    def __str__(self) -> str:
        return f"{self.procedure} v{self.version}"


class Job(models.Model):
    class Status(models.TextChoices):
        QUEUED = "queued", "Queued"
        RUNNING = "running", "Running"
        DONE = "done", "Done"
        FAILED = "failed", "Failed"

    class Kind(models.TextChoices):
        RECONSTRUCT = "reconstruct", "Reconstruct"

    code = models.UUIDField(default=uuid.uuid4, unique=True, editable=False)
    owner = models.ForeignKey(settings.AUTH_USER_MODEL, on_delete=models.CASCADE, related_name="jobs")
    kind = models.CharField(max_length=20, choices=Kind.choices, default=Kind.RECONSTRUCT)
    segmentation = models.ForeignKey(Segmentation, on_delete=models.CASCADE, related_name="jobs")
    params = models.JSONField(default=dict, blank=True)  # k, seed, prefix procedure code and node count
    status = models.CharField(max_length=10, choices=Status.choices, default=Status.QUEUED, db_index=True)
    progress = models.FloatField(default=0.0)
    stage = models.CharField(max_length=100, blank=True)
    message = models.TextField(blank=True)  # why it failed
    attempts = models.PositiveIntegerField(default=0)
    result = models.ForeignKey(Procedure, on_delete=models.SET_NULL, null=True, blank=True, related_name="jobs")
    result_version = models.PositiveIntegerField(null=True, blank=True)  # the version of `result` it made
    created = models.DateTimeField(default=timezone.now)
    started = models.DateTimeField(null=True, blank=True)
    heartbeat = models.DateTimeField(null=True, blank=True)  # a running worker touches it every few seconds
    finished = models.DateTimeField(null=True, blank=True)
    sent = models.DateTimeField(null=True, blank=True)  # last time the task message was sent

    class Meta:
        ordering = ["-created"]

    def __str__(self) -> str:
        return f"{self.kind} job {self.code} ({self.status})"

    def get_absolute_url(self) -> str:
        return reverse("job", args=[self.code])
