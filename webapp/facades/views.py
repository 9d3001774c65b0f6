"""The pages. They call the same operations as the JSON API (`webapp.facades.services`) under the same access
rules; a service's error about what a form sent is said on the page, the rest is the error page
(`webapp.middleware.ServiceErrorMiddleware`)."""

from __future__ import annotations

import math

from django.conf import settings
from django.contrib import messages
from django.contrib.auth.decorators import login_required
from django.core.paginator import Paginator
from django.shortcuts import redirect, render
from django.views.decorators.http import require_POST

from facaid.defaults import DEFAULT_K, MAX_K
from facaid.formats import interchange
from facaid.formats.cga import MAX_SCALE
from facaid.grammar import ProcedureError
from facaid.grammar.budget import WorkLimitError
from facaid.grammar.procedure import MAX_NODES
from webapp.facades import access, disclosure, example, jsonbody, throttling
from webapp.facades.downloads import DOWNLOADS, download_scale, drawn_on_original
from webapp.facades.errors import Invalid, QuotaError, TooManyJobs
from webapp.facades.forms import (
    PhotoForm,
    ProcedureVisibilityForm,
    RealSizeForm,
    ReconstructForm,
    RerunForm,
    SegmentationForm,
    VisibilityForm,
)
from webapp.facades.models import REAL_SIZE_M, Job, Photo, Procedure
from webapp.facades.parsing import parse_procedure
from webapp.facades.serializers.photos import PhotoSerializer
from webapp.facades.services import jobs, photos, procedures, segmentations, sharing

INTERCHANGE_FORMATS = (("segmentation", "our JSON"), ("coco", "COCO"), ("labelme", "LabelMe"), ("cvat", "CVAT XML"))


def _errors_text(detail) -> str:
    """A serializer's errors (field -> messages) in a sentence: "real_width_m: Ensure this value ..."."""
    if isinstance(detail, dict):
        return "; ".join(f"{k}: {' '.join(map(str, v)) if isinstance(v, list) else v}" for k, v in detail.items())
    return " ".join(map(str, detail)) if isinstance(detail, list) else str(detail)


def _set_visibility(request, obj, noun: str):
    form = VisibilityForm(request.POST)
    if form.is_valid():
        obj.visibility = form.cleaned_data["visibility"]
        obj.save()
        messages.success(request, f"The {noun} is now {obj.get_visibility_display().lower()}.")
    return redirect(obj)


def home(request):
    gallery = Paginator(access.public_procedures(), 24).get_page(request.GET.get("page"))
    context = {"gallery": gallery}
    newcomer = not request.user.is_authenticated or not Photo.objects.filter(owner=request.user).exists()
    if newcomer:  # what the product does, from the demo, and the first step
        context["example"] = example.front_page_example()
        context["newcomer"] = True
    if request.user.is_authenticated:
        context.update(photos=Photo.objects.filter(owner=request.user)[:12],
                       procedures=access.listed(Procedure.objects.filter(owner=request.user))[:12],
                       jobs=Job.objects.filter(owner=request.user).select_related(
                           "result", "segmentation__photo").defer(*access.JOB_WITHOUT)[:8])
    return render(request, "facades/home.html", context)


@login_required
def photo_new(request):
    form = PhotoForm(request.POST or None, request.FILES or None)
    busy = False
    if request.method == "POST" and form.is_valid():
        with throttling.heavy_slot(request) as held:  # decoding a photo is a heavy request, as the API's upload
            allowed, wait = throttling.allow_heavy(request) if held else (False, 2)
            busy = not allowed
            if busy:
                form.add_error("image", f"the site is busy with other uploads and drawings; send it again in "
                                        f"{math.ceil(wait or 2)} s")
            else:
                photo = _upload(request, form)
                if photo is not None:
                    messages.success(request, "Photo uploaded. Rectify it if needed, then add a segmentation.")
                    return redirect(photo)
    return render(request, "facades/photo_new.html", {"form": form},
                  status=503 if busy else 400 if form.errors else 200)


def _upload(request, form: PhotoForm) -> Photo | None:
    """The photo the form uploads, or None with what was wrong added to the form's image field."""
    try:
        return photos.create_photo(request.user, form.cleaned_data["image"], form.cleaned_data["title"],
                                   form.cleaned_data["visibility"])
    except Invalid as exc:
        form.add_error("image", exc.text().removeprefix("image: "))
    except QuotaError as exc:
        form.add_error("image", str(exc))
    return None


def photo(request, code):
    photo = access.get_photo_for_user(request.user, code)
    owner = request.user == photo.owner and not access.is_demo(photo)  # nobody changes the demo's
    segmentation = photo.latest_segmentation()
    context = {"photo": photo, "owner": owner, "segmentation": segmentation,
               "procedures": access.listed(photo.procedures.filter(owner=photo.owner) if owner else
                                           photo.procedures.filter(visibility="public")),
               "jobs": Job.objects.filter(owner=photo.owner, segmentation__photo=photo).select_related(
                   "result", "segmentation__photo").defer(*access.JOB_WITHOUT)[:10] if owner
               else Job.objects.none(),
               "segmentation_form": SegmentationForm(), "reconstruct_form": ReconstructForm(),
               "interchange_formats": INTERCHANGE_FORMATS, "metres_per_pixel": photo.metres_per_pixel(),
               "real_size_form": RealSizeForm(initial={
                   "side": "height" if photo.real_height_m is not None else "width",
                   "metres": photo.real_height_m if photo.real_height_m is not None else photo.real_width_m}),
               "visibility_form": VisibilityForm(initial={"visibility": photo.visibility})}
    return render(request, "facades/photo.html", context)


@login_required
@require_POST
def photo_visibility(request, code):
    return _set_visibility(request, access.get_rw_photo_for_user(request.user, code), "photo")


@login_required
@require_POST
def photo_real_size(request, code):
    """The facade's real width or height (empty: none), validated as the API's PATCH validates it."""
    photo = access.get_rw_photo_for_user(request.user, code)
    form = RealSizeForm(request.POST)
    if not form.is_valid():
        messages.error(request, "Give the real size as a number of metres.")
        return redirect(photo)
    side, metres = form.cleaned_data["side"], form.cleaned_data["metres"]
    data = {"real_width_m": None, "real_height_m": None}
    if metres is not None:
        data[f"real_{side}_m"] = metres
    change = PhotoSerializer(photo, data=data, partial=True)
    if not change.is_valid():
        messages.error(request, _errors_text(change.errors))
        return redirect(photo)
    change.save()
    messages.success(request, f"The facade is {metres:g} m {'wide' if side == 'width' else 'tall'}: its "
                              "procedures' CGA rules and meshes are at that scale." if metres is not None else
                     "The real size is cleared: exports take a storey as 3 m tall.")
    return redirect(photo)


@login_required
@require_POST
def photo_segmentation(request, code):
    photo = access.get_rw_photo_for_user(request.user, code)
    form = SegmentationForm(request.POST, request.FILES)
    if form.is_valid():
        upload, limit = form.cleaned_data["file"], settings.DATA_UPLOAD_MAX_MEMORY_SIZE
        if upload and upload.size > limit:
            messages.error(request, f"The segmentation file is {upload.size / 2**20:.1f} MB; at most "
                                    f"{limit / 2**20:.0f} MB are read.")
            return redirect(photo)
        raw = upload.read() if upload else form.cleaned_data["text"]
        if message := interchange.not_annotations(raw):  # the photo picked instead of its annotations
            messages.error(request, f"The segmentation could not be read: {message}.")
            return redirect(photo)
        try:
            # XML is a CVAT file, read as it is; JSON is ours, COCO's or LabelMe's, read with bounded nesting
            data = raw if raw.lstrip()[:1] in ("<", b"<") else jsonbody.loads(raw)
            seg, warnings = segmentations.add_segmentation(photo, data)
        except jsonbody.JSONError as exc:
            messages.error(request, f"The segmentation could not be read: {exc}")
        except Invalid as exc:
            messages.error(request, exc.text())
        else:
            messages.success(request, f"Segmentation version {seg.version} saved ({seg.rect_count} rectangles).")
            for line in warnings:
                messages.warning(request, f"Read with a change: {line}.")
    return redirect(photo)


@login_required
@require_POST
def photo_reconstruct(request, code):
    photo = access.get_rw_photo_for_user(request.user, code)
    seg = photo.latest_segmentation()
    form = ReconstructForm(request.POST)
    if seg is None:
        messages.error(request, "Add a segmentation first.")
        return redirect(photo)
    if not form.is_valid():
        messages.error(request, "Check the reconstruction settings.")
        return redirect(photo)
    try:
        job = jobs.submit_job(request.user, seg, form.cleaned_data["k"], form.cleaned_data["seed"],
                              structure=form.cleaned_data["structure"] or "editable")
    except TooManyJobs as exc:
        messages.error(request, str(exc))
        return redirect(photo)
    return redirect(job)


@login_required
def photo_editor(request, code):
    photo = access.get_rw_photo_for_user(request.user, code)
    segmentation = photo.latest_segmentation()
    return render(request, "facades/editor.html", {"photo": photo, "segmentation": segmentation,
                                                   "default_k": DEFAULT_K, "max_k": MAX_K,
                                                   "real_size_min": REAL_SIZE_M[0], "real_size_max": REAL_SIZE_M[1]})


def job(request, code):
    job = access.get_job_for_user(request.user, code)
    return render(request, "facades/job.html", {
        "job": job, "photo_visible": access.photo_visible_to(request.user, job.segmentation.photo),
        "note": jobs.state(job)[1]})


def procedure(request, code):
    proc = access.get_procedure_for_user(request.user, code)
    demo = access.is_demo(proc)
    owner = request.user == proc.owner and not demo  # the demo account sees the demo as anyone does: fork to edit
    photo_visible = access.photo_visible_to(request.user, proc.photo)
    hidden = disclosure.hidden(request.user, proc)  # nothing of the photo or its segmentation is shown
    current = proc.current_version()
    with throttling.heavy_slot(request) as held:  # a page that draws is a heavy request: a slot and the rate
        heavy = held and throttling.allow_heavy(request)[0]
        scale, drawable, note = _drawing(proc, request.user) if heavy else (None, True, BUSY_NOTE)
    return render(request, "facades/procedure.html", {
        "drawable": drawable, "picture_note": note, "scale_pending": not heavy,
        "proc": proc, "owner": owner, "demo": demo, "photo_visible": photo_visible, "current": current,
        "title": disclosure.title(request.user, proc),
        "figures": disclosure.figures(request.user, proc, proc.accuracy, proc.metrics, current and current.warning),
        "other_structure": _other_structure(proc),
        "can_rerun": owner and access.segmentation_visible_to(request.user, proc),
        "lineage": access.visible_lineage(request.user, proc), "rerun_form": RerunForm(),
        "data_json": disclosure.tree(proc.data) if hidden else proc.data,
        "visibility_form": ProcedureVisibilityForm(initial={"visibility": proc.visibility}),
        "may_share_photo": owner and sharing.may_share_photo(request.user, proc),
        "viewers_see": sharing.viewers_see(proc) if owner else "",
        "sharing_previews": sharing.previews(request.user, proc) if owner else {},
        "photo_hidden": hidden,
        "drawn_on": _drawn_on(proc) if photo_visible else None,
        "downloads": [(name, d.help, d.scaled) for name, d in DOWNLOADS.items() if photo_visible or not d.needs_photo],
        "max_scale": MAX_SCALE, "scale": scale})


BUSY_NOTE = "The site is busy: this page is shown without working out the downloads' scale; reload in a moment."


def _drawing(proc, viewer) -> tuple[tuple[float, str] | None, bool, str]:
    """(the metric downloads' scale for ``viewer``, whether the tree can be drawn, what to say if not): the tree is
    read under the request's work budget, charged before any of it is laid out. A tree stored before a limit it now
    breaks, or one past the budget, is shown without its picture."""
    try:
        return download_scale(proc, parse_procedure(proc.data), viewer), True, ""
    except (Invalid, ProcedureError) as exc:
        why = exc.text() if isinstance(exc, Invalid) else str(exc)
        return None, False, f"This procedure cannot be drawn ({why}). Its tree is below, and procedure.json has it."
    except WorkLimitError as exc:
        return None, False, f"This procedure is not drawn here: {exc}. Its tree is below, and procedure.json has it."


def _drawn_on(proc) -> dict:
    """The photo's image the procedure was drawn on (the original, drawn before rectifying, or the working image),
    its URL and size: the overlay lays the tree over that one."""
    photo = proc.photo
    if drawn_on_original(proc) or not photo.rectified:
        return {"url": f"/api/v1/photos/{photo.code}/image", "size": (photo.width, photo.height)}
    return {"url": f"/api/v1/photos/{photo.code}/image?rectified=1", "size": photo.working_size()}


def _other_structure(proc):
    """The latest version whose tree is the other of a real facade's two structures (editable, exact), if any."""
    here = (proc.metrics or {}).get("structure")
    if here not in ("editable", "exact"):
        return None
    for version in proc.versions.defer("data").order_by("-version"):
        there = (version.metrics or {}).get("structure")
        if there in ("editable", "exact") and there != here:
            return version
    return None


@login_required
@require_POST
def procedure_visibility(request, code):
    proc = access.get_rw_procedure_for_user(request.user, code)
    form = ProcedureVisibilityForm(request.POST)
    if form.is_valid():
        try:
            said = sharing.set_visibility(request.user, proc, form.cleaned_data["visibility"],
                                          form.cleaned_data["share_photo"])
        except Invalid as exc:
            messages.error(request, exc.text())
        else:
            messages.success(request, f"The procedure is now {proc.get_visibility_display().lower()}. {said}")
    else:
        messages.error(request, f"Not changed: {'; '.join(e for errors in form.errors.values() for e in errors)}")
    return redirect(proc)


@login_required
@require_POST
def procedure_fork(request, code):
    proc = access.get_procedure_for_user(request.user, code)
    allowed, wait = throttling.allow_heavy(request)
    if not allowed:
        messages.error(request, f"Too many forks and edits in a row; try again in {math.ceil(wait or 1)} s.")
        return redirect(proc)
    fork = procedures.fork_procedure(request.user, proc)
    messages.success(request, "Forked: this copy is yours to edit.")
    return redirect(fork)


@login_required
@require_POST
def procedure_rerun(request, code):
    proc = access.get_rw_procedure_for_user(request.user, code)
    form = RerunForm(request.POST)
    if not form.is_valid():
        messages.error(request, f"Re-running needs a node count from 1 to {MAX_NODES}.")
        return redirect(proc)
    try:
        job = procedures.rerun(request.user, proc, form.cleaned_data["nodes"])
    except Invalid as exc:
        text = exc.text().removeprefix("procedure: ")
        messages.error(request, f"{text[:1].upper()}{text[1:]}.")
        return redirect(proc)
    except TooManyJobs as exc:
        messages.error(request, str(exc))
        return redirect(proc)
    messages.info(request, f"Re-running version {job.params['prefix_version']}: the result will be the procedure's "
                           "next version, shown beside it.")
    return redirect(job)


@login_required
@require_POST
def procedure_delete(request, code):
    proc = access.get_rw_procedure_for_user(request.user, code)
    proc.delete()
    messages.success(request, "Procedure deleted.")
    return redirect("home")
