"""Versions of procedures, for the API's views and the pages alike: a tree saved (re-measured against the
procedure's segmentation, so that no figure outlives the tree it was measured on), an old version restored (a new
version equal to it: nothing is deleted), a re-run's result kept as a version beside the one it continued (with a
warning when it fits worse), a procedure saved as a new one with lineage, and two versions compared. Bad input
raises `Invalid` naming the field; an unknown version is `NotFound`."""

from __future__ import annotations

from django.db import transaction

from facaid.metrics import measure
from facaid.segmentation import Segmentation as SegmentationData
from facaid.segmentation import flatten
from webapp.facades import access, drawing, editcheck
from webapp.facades.errors import Invalid, NotFound
from webapp.facades.models import Change, Procedure, ProcedureVersion, tree_digest
from webapp.facades.parsing import parse_procedure
from webapp.facades.services import sharing
from webapp.facades.services.procedures import fork_procedure

# figures of the job that made a tree (its timings, the decoded candidate's accuracy, how it searched): true of that
# tree alone, so an edit, a revert or a copy drops them; `source` (where the structure came from) stays
JOB_FIGURES = ("accuracy_decoded", "timings", "retried", "shortcut", "denoised")
MAX_VERSION_DIGITS = 9


def remeasure(proc: Procedure) -> None:
    """Pixel accuracy and per-class IoU of the procedure's tree against the segmentation it was made from, into
    ``accuracy`` and ``metrics`` (nothing is saved). A tree of another size than the segmentation (a resized
    variant) is not comparable: no accuracy, and ``metrics["unmeasured"]`` says why; neither is a fork's whose photo
    is not shared with its owner (the figures would tell them about the segmentation)."""
    metrics = {k: v for k, v in (proc.metrics or {}).items() if k not in (*JOB_FIGURES, "iou", "unmeasured")}
    proc.accuracy = None
    if proc.segmentation_id is not None and not access.segmentation_visible_to(proc.owner, proc):
        # a fork whose photo is not shared with its owner: no figure may tell them about the segmentation
        metrics["unmeasured"] = "the photo it was made from is not shared with its owner"
    elif proc.segmentation_id is not None:
        target = flatten(SegmentationData.from_dict(proc.segmentation.data))
        tree = parse_procedure(proc.data)
        size = (round(tree.width), round(tree.height))
        if size == (target.width, target.height):
            proc.accuracy, metrics["iou"] = measure(tree, target)
        else:
            metrics["unmeasured"] = (f"the tree is {size[0]}x{size[1]} px but its segmentation is "
                                     f"{target.width}x{target.height}")
    proc.metrics = metrics


def save_tree(proc: Procedure, data: dict, change: Change | None = None) -> None:
    """Give the procedure ``data`` (a validated procedure JSON), re-measured, and save it with its other fields;
    whether that makes a version, and of which kind, is the versioning rule's, in one place
    (`models.Procedure._record_version`: an edit, unless ``change`` says otherwise, and none for an unchanged
    tree)."""
    proc.data = data
    remeasure(proc)
    proc.save(change=change)


def save_parameters(proc: Procedure, data: dict, values: dict) -> None:
    """Save ``data``, the procedure with its named parameters set to ``values``, as an edit that names them."""
    names = ", ".join(f"{k} {v:g}" for k, v in values.items())
    save_tree(proc, data, Change(ProcedureVersion.Kind.EDIT, f"set {names}"[:200]))


def edit_procedure(user, proc: Procedure, changes: dict) -> Procedure:
    """Apply a validated edit (title, ``data``: a new version, re-measured; ``visibility``, with ``share_photo``:
    `sharing.set_visibility`) all or nothing: a photo that cannot be shared leaves the title and the tree as they
    were."""
    changes = dict(changes)
    tree = changes.pop("data", None)
    visibility, share_photo = changes.pop("visibility", None), changes.pop("share_photo", False)
    with transaction.atomic():
        for key, value in changes.items():
            setattr(proc, key, value)
        if tree is None:
            proc.save()
        else:
            save_tree(proc, tree)
        if visibility is not None or share_photo:
            sharing.set_visibility(user, proc, visibility or proc.visibility, share_photo)
    return proc


def version_number(text, field: str | None = None) -> int:
    """A version number from a path (malformed: `NotFound`) or from the query parameter ``field`` (`Invalid`,
    naming it)."""
    text = "" if text is None else str(text)
    if text.isascii() and text.isdigit() and len(text) <= MAX_VERSION_DIGITS:
        return int(text)
    if field is None:
        raise NotFound(f"no version {text[:20]!r}: versions are numbered from 1")
    raise Invalid(f"give a version number, got {text[:20]!r}", field)


def get_version(proc: Procedure, number, field: str | None = None, with_data: bool = True) -> ProcedureVersion:
    """Version ``number`` of the procedure: `NotFound` (from a path) or `Invalid` naming ``field`` when there is
    none."""
    n = version_number(number, field)
    rows = proc.versions.all() if with_data else proc.versions.defer("data")
    version = rows.filter(version=n).first()
    if version is None:
        latest = proc.versions.order_by("-version").values_list("version", flat=True).first() or 0
        message = f"no version {n} of this procedure: it has versions 1 to {latest}"
        if field is None:
            raise NotFound(message)
        raise Invalid(message, field)
    version.procedure = proc
    return version


def revert(proc: Procedure, number) -> ProcedureVersion:
    """A new version whose tree is version ``number``'s, measured again; the versions between stay."""
    old = get_version(proc, number)
    if old.digest == proc.digest:
        raise Invalid(f"version {old.version} is the tree this procedure holds now: there is nothing to revert",
                      "version")
    proc.metrics = dict(old.metrics)  # where its structure came from, as that version knew it
    save_tree(proc, old.data, Change(ProcedureVersion.Kind.REVERT, f"reverted to version {old.version}",
                                     based_on=old.version))
    return proc.current_version()


def rerun_warning(accuracy: float | None, base: float | None, based_on: int) -> str:
    """The warning of a re-run that fits worse (a lower pixel accuracy, to the 4 decimals shown) than the version
    it continued; empty when it fits as well or better, or when either was not measured."""
    if accuracy is None or base is None or round(accuracy, 4) >= round(base, 4):
        return ""
    return (f"This re-run fits worse than version {based_on}: pixel accuracy {100 * accuracy:.2f} % against "
            f"{100 * base:.2f} %. Revert to version {based_on} to keep that one.")


def add_rerun(proc: Procedure, data: dict, accuracy: float | None, metrics: dict, based_on: int,
              nodes: int) -> ProcedureVersion:
    """A re-run's result (measured by the job against the procedure's own segmentation) as the procedure's new
    version, beside version ``based_on`` that it continued."""
    base = proc.versions.filter(version=based_on).values_list("accuracy", flat=True).first()
    proc.data, proc.accuracy, proc.metrics = data, accuracy, metrics
    proc.save(change=Change(ProcedureVersion.Kind.RERUN, f"re-run keeping the first {nodes} nodes of version "
                                                         f"{based_on}", based_on=based_on,
                            warning=rerun_warning(accuracy, base, based_on)))
    return proc.current_version()


def new_title(user, proc: Procedure, data: dict) -> str:
    """A title that tells a saved copy from its parent and its siblings: the variation and seed that made it, or
    a running number among the user's copies of the parent."""
    base = proc.title or "Procedure"
    meta = data.get("meta") if isinstance(data.get("meta"), dict) else {}
    if isinstance(meta.get("variation"), str) and meta["variation"]:
        what = f"{meta['variation'][:40]} variant"
        if isinstance(meta.get("variation_seed"), int) and isinstance(meta.get("variation_index"), int):
            what += f" (seed {meta['variation_seed']}, #{meta['variation_index'] + 1})"
        return f"{base} · {what}"[:200]
    n = Procedure.objects.filter(parent=proc, owner=user).count() + 1
    return f"{base} · variant {n}"[:200]


def save_as_new(user, proc: Procedure, data: dict | None = None, title: str = "") -> Procedure:
    """A new procedure of ``user``'s whose parent is ``proc``: a fork (its links to the photo as a fork keeps
    them) whose first version is ``data`` (an edited tree or a variation, when given), re-measured."""
    tree = proc.data if data is None else data
    current = proc.current_version()
    meta = tree.get("meta") if isinstance(tree.get("meta"), dict) else {}
    made = "a variation" if isinstance(meta.get("variation"), str) and meta["variation"] else "an edit"
    digest = tree_digest(tree)
    same = digest == proc.digest  # the page sends the tree it shows, edited or not
    note = (f"saved as a new procedure from version {current.version if current else 1} of “{proc}”" if same
            else f"saved from {made} of version {current.version if current else 1} of “{proc}”")
    title = title or new_title(user, proc, tree)
    # its edits checked before the transaction writes (SQLite's one writer is not held for them); the parent's
    # verdicts where the tree is the parent's
    checks = editcheck.checked(proc.metrics, tree, digest)[editcheck.KEY]
    return fork_procedure(user, proc, data, note[:200], measure=lambda p: _measured(p, checks), title=title)


def _measured(proc: Procedure, checks: dict) -> None:
    """`remeasure`, with the edits' verdicts of its tree already made (``checks``)."""
    remeasure(proc)
    proc.metrics = {**(proc.metrics or {}), editcheck.KEY: checks}


def compare(proc: Procedure, a, b, max_side: int = drawing.COMPARE_SIDE) -> tuple[ProcedureVersion,
                                                                                   ProcedureVersion, dict]:
    """Versions ``a`` and ``b`` (from the query: a 400 names the bad one) and their difference picture:
    {"png", "differing", "pixels", "sizes"} (pixels whose label differs, of the picture's, at most ``max_side`` a
    side; each tree's width and height). Each tree is read once, before any is drawn."""
    first, second = get_version(proc, a, "a"), get_version(proc, b, "b")
    trees = parse_procedure(first.data), parse_procedure(second.data)  # both charged to the budget, then drawn
    png, differing, pixels = drawing.difference_png(*trees, max_side)
    return first, second, {"png": png, "differing": differing, "pixels": pixels,
                           "sizes": [(tree.width, tree.height) for tree in trees]}
