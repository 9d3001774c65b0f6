"""The API's procedures: list, store, read, edit, delete, fork, save as new, vary, named parameters, re-run,
the live preview and the downloads."""

from __future__ import annotations

from django.http import Http404, HttpResponse
from drf_spectacular.utils import OpenApiParameter, extend_schema
from rest_framework import status
from rest_framework.decorators import (
    api_view,
    parser_classes,
    permission_classes,
    throttle_classes,
)
from rest_framework.exceptions import ValidationError
from rest_framework.permissions import AllowAny, IsAuthenticated
from rest_framework.response import Response

from facaid.editing.parameters import named_parameters, set_parameters
from facaid.editing.variation import vary
from facaid.formats.relief import MAX_MESH_RECTS, drawn_leaves
from facaid.grammar import to_segmentation
from facaid.grammar.budget import reserve
from facaid.grammar.layout import count_expansion
from facaid.grammar.procedure import ProcedureError
from facaid.labels import LABELS
from webapp.facades import access, disclosure, downloads, drawing, editcheck
from webapp.facades.api.common import (
    page,
    stored_picture,
)
from webapp.facades.downloads import DOWNLOADS
from webapp.facades.jsonbody import JSONParser
from webapp.facades.models import (
    Procedure,
    tree_digest,
)
from webapp.facades.parsing import parse_procedure
from webapp.facades.serializers.jobs import JobSerializer, RerunSerializer
from webapp.facades.serializers.procedures import (
    ParametersSerializer,
    ProcedureEditSerializer,
    ProcedureSerializer,
    ProcedureSummarySerializer,
    ProcedureWriteSerializer,
    SaveAsNewSerializer,
    VariationsSerializer,
)
from webapp.facades.services import versions
from webapp.facades.services.procedures import create_procedure, fork_procedure, rerun
from webapp.facades.throttling import HEAVY


@extend_schema(methods=["GET"], responses=ProcedureSummarySerializer(many=True), summary="Your procedures")
@extend_schema(methods=["POST"], request=ProcedureWriteSerializer, responses={201: ProcedureSerializer},
               summary="Store a procedure JSON (imported or edited)")
@api_view(["GET", "POST"])
@throttle_classes(HEAVY)
@permission_classes([IsAuthenticated])
@parser_classes([JSONParser])
def procedure_list(request):
    if request.method == "GET":
        return page(request, access.listed(Procedure.objects.filter(owner=request.user)), ProcedureSummarySerializer)
    form = ProcedureWriteSerializer(data=request.data)
    form.is_valid(raise_exception=True)
    proc = create_procedure(request.user, form.validated_data)
    return Response(ProcedureSerializer(proc, context={"request": request}).data, status=status.HTTP_201_CREATED)


@extend_schema(methods=["GET"], responses=ProcedureSerializer, summary="A procedure")
@extend_schema(methods=["PATCH"], request=ProcedureEditSerializer, responses=ProcedureSerializer,
               summary="Edit title, visibility or the procedure itself: a changed tree is a new version, re-measured "
                       "(the answer's accuracy and metrics are the new version's)")
@extend_schema(methods=["DELETE"], responses={204: None}, summary="Delete a procedure")
@api_view(["GET", "PATCH", "DELETE"])
@throttle_classes(HEAVY)
@permission_classes([AllowAny])
@parser_classes([JSONParser])
def procedure_detail(request, code):
    if request.method == "GET":
        return Response(ProcedureSerializer(access.get_procedure_for_user(request.user, code),
                                           context={"request": request}).data)
    proc = access.get_rw_procedure_for_user(request.user, code)
    if request.method == "DELETE":
        proc.delete()
        return Response(status=status.HTTP_204_NO_CONTENT)
    form = ProcedureEditSerializer(data=request.data, partial=True)
    form.is_valid(raise_exception=True)
    versions.edit_procedure(request.user, proc, form.validated_data)
    return Response(ProcedureSerializer(proc, context={"request": request}).data)


@extend_schema(request=None, responses={201: ProcedureSerializer},
               summary="Fork: your own private copy, with a link to its parent")
@api_view(["POST"])
@throttle_classes(HEAVY)
@permission_classes([IsAuthenticated])
def procedure_fork(request, code):
    fork = fork_procedure(request.user, access.get_procedure_for_user(request.user, code))
    return Response(ProcedureSerializer(fork, context={"request": request}).data, status=status.HTTP_201_CREATED)


@extend_schema(request=SaveAsNewSerializer, responses={201: ProcedureSerializer},
               summary="Save as a new procedure: yours, private, whose parent is this one (kept with its photo as a "
                       "fork keeps it), holding 'data' (an edited tree or a variation; default: this one's tree) as "
                       "its first version, re-measured; titled from 'title', else from the variation that made it "
                       "or a running number, so that it is told apart from its parent")
@api_view(["POST"])
@throttle_classes(HEAVY)
@permission_classes([IsAuthenticated])
@parser_classes([JSONParser])
def procedure_save_as_new(request, code):
    proc = access.get_procedure_for_user(request.user, code)
    form = SaveAsNewSerializer(data=request.data)
    form.is_valid(raise_exception=True)
    copy = versions.save_as_new(request.user, proc, form.validated_data.get("data"),
                                form.validated_data.get("title", ""))
    return Response(ProcedureSerializer(copy, context={"request": request}).data, status=status.HTTP_201_CREATED)


@extend_schema(request=VariationsSerializer, responses={200: dict},
               summary="Variants of a procedure (counts, resizes, swaps), deterministic by seed; not stored: "
                       "{'variants': [...], 'left_out': [{'name', 'reason'}]}, by default without the counts whose "
                       "edits are not clean (include_unchecked: those too)")
@api_view(["POST"])
@throttle_classes(HEAVY)
@permission_classes([AllowAny])
@parser_classes([JSONParser])
def procedure_variations(request, code):
    proc = access.get_procedure_for_user(request.user, code)
    form = VariationsSerializer(data=request.data)
    form.is_valid(raise_exception=True)
    asked = {k: tuple(v) for k, v in form.validated_data.get("ranges", {}).items()}
    try:
        tree = parse_procedure(proc.data)
        # by default only parameters whose edits are not known to be unclean vary (`editcheck`); the rest are said
        held = {} if form.validated_data["include_unchecked"] else \
            editcheck.unclean(editcheck.for_tree(tree, proc.digest, proc.metrics))
        ranges, left_out = _checked_ranges(asked, held)
        if asked and not ranges:
            raise ValueError("every range names a parameter whose edits are not clean (" + "; ".join(
                f"{o['name']}: {o['reason']}" for o in left_out) + "): ask with include_unchecked to vary them")
        reserve(VARIANT_WORK * form.validated_data["n"] * _units(tree))  # the variants, refused before they are made
        variants = vary(tree, form.validated_data["n"], form.validated_data["seed"], ranges or None,
                        hold=() if ranges else tuple(held))
    except (ProcedureError, ValueError) as exc:
        field = "ranges" if form.validated_data.get("ranges") else "data"
        raise ValidationError({field: f"no variations of this procedure: {exc}"}) from None
    shown = disclosure.tree if disclosure.hidden(request.user, proc) else dict  # no accuracy of a private photo's
    return Response({"variants": [shown(v.to_dict()) for v in variants], "left_out": left_out})


# the side a count's repeats lie along: a range of it recounts them (a taller facade holds more floors)
RECOUNTED_BY = {"floors": "height", "bays": "width"}


def _checked_ranges(asked: dict, held: dict[str, str]) -> tuple[dict, list[dict]]:
    """The ranges to draw, of those ``asked``, and those left out with why (``{"name", "reason"}``): none of a
    count ``held`` (its edits are not clean: its words), nor of the side it lies along. Without ranges, the held
    counts themselves are what is left out."""
    if not asked:
        return {}, [{"name": name, "reason": reason} for name, reason in held.items()]
    ranges, left_out = {}, []
    side_of = {side: count for count, side in RECOUNTED_BY.items()}
    for name, bounds in asked.items():
        if name in held:
            left_out.append({"name": name, "reason": held[name]})
        elif side_of.get(name) in held:
            count = side_of[name]
            left_out.append({"name": name, "reason": f"a new {name} recounts the {count}, whose edits are not "
                                                     f"clean: {held[count]}"})
        else:
            ranges[name] = bounds
    return ranges, left_out


# what making a variant, or setting a named parameter, costs per unit of its tree's (`count_expansion`), measured on
# the heaviest accepted trees (bench/bench_request_cost.py: 3.8 and 2.5 us a unit, where laying a tree out is 1)
VARIANT_WORK = 4
PARAMETER_WORK = 3


def _units(tree) -> int:
    return count_expansion(tree.root, tree.width, tree.height).instances


def _judged(tree, digest: str, metrics: dict | None) -> list[dict]:
    """The tree's named parameters, each with ``checked`` and ``check`` (`editcheck.judged`): by the verdicts kept in
    ``metrics`` where they judged this very tree (``digest``), else by a check made now."""
    params = named_parameters(tree)
    return editcheck.annotate([p.to_dict() for p in params], editcheck.for_tree(tree, digest, metrics))


def _leaves(tree) -> list | None:
    """Where the tree draws each leaf, for the page's picture-to-tree selection: [label, x0, y0, x1, y1, node path]
    in whole pixels; None past `MAX_MESH_RECTS` rectangles (a real facade draws a few hundred)."""
    rows, paths = drawn_leaves(tree)
    if len(rows) > MAX_MESH_RECTS:
        return None
    return [[LABELS[r[0]], *r[1:], path] for r, path in zip(rows.tolist(), paths, strict=True)]


@extend_schema(methods=["GET"], request=None, responses={200: dict},
               summary="The named parameters (floors, floor height, bays, ...), each checked or not (its edits "
                       "judged: checked, check), and where each leaf is drawn: "
                       "{'parameters': [...], 'leaves': [[label, x0, y0, x1, y1, node path], ...]}")
@extend_schema(methods=["POST"], request=ParametersSerializer, responses={200: dict},
               summary="Set named parameters: {'data', 'parameters', 'leaves', 'accuracy', 'metrics', 'version'}; "
                       "with save, the result is the next version (the accuracy is that version's, measured on save)")
@api_view(["GET", "POST"])
@throttle_classes(HEAVY)
@permission_classes([AllowAny])
@parser_classes([JSONParser])
def procedure_parameters(request, code):
    proc = access.get_procedure_for_user(request.user, code)
    if request.method == "GET":
        tree = parse_procedure(proc.data)
        return Response({"parameters": _judged(tree, proc.digest, proc.metrics), "leaves": _leaves(tree)})
    form = ParametersSerializer(data=request.data)
    form.is_valid(raise_exception=True)
    if form.validated_data["save"]:  # refused before the work, not after it
        proc = access.get_rw_procedure_for_user(request.user, code)
    try:
        tree = parse_procedure(form.validated_data.get("data") or proc.data)
        reserve(PARAMETER_WORK * len(form.validated_data["values"]) * _units(tree))  # a tree a value, at least
        edited = set_parameters(tree, form.validated_data["values"])
    except (ProcedureError, ValueError) as exc:
        raise ValidationError({"values": str(exc)}) from None
    answer = {"data": edited.to_dict(), "leaves": _leaves(edited), "accuracy": None, "metrics": None,
              "version": None}
    if form.validated_data["save"]:  # (its edits checked as it is saved)
        versions.save_parameters(proc, answer["data"], form.validated_data["values"])
        shown = disclosure.figures(request.user, proc, proc.accuracy, proc.metrics)
        answer.update(accuracy=shown["accuracy"], metrics=shown["metrics"], version=proc.current_version().version)
    answer["parameters"] = _judged(edited, tree_digest(answer["data"]), proc.metrics)
    if disclosure.hidden(request.user, proc):  # the tree's meta: no accuracy of a photo not shared with the viewer
        answer["data"] = disclosure.tree(answer["data"])
    return Response(answer)


@extend_schema(request={"application/json": dict}, responses={(200, "image/png"): bytes},
               summary="Render a procedure JSON (the live preview of edited parameters)")
@api_view(["POST"])
@throttle_classes(HEAVY)
@permission_classes([AllowAny])
@parser_classes([JSONParser])
def render_preview(request):
    seg = to_segmentation(parse_procedure(request.data))
    return HttpResponse(drawing.label_map_png(seg, 1024), content_type="image/png")


@extend_schema(parameters=[OpenApiParameter("alpha", float, description="overlay opacity, 0..1"),
                           OpenApiParameter("metres_per_pixel", float,
                                            description="the scale of procedure.cga, mesh.zip and the 3D models "
                                                        "(default: the procedure's own scale, from its photo's real "
                                                        "size, else a storey is 3 m)")],
               responses={(200, "application/octet-stream"): bytes},
               summary="Downloads: procedure.json, segmentation.json (executed; segmentation.coco.json, "
                       "segmentation.labelme.json and segmentation.cvat.xml its elements as another tool's "
                       "annotations of its photo), labels.png, labels.svg (one group "
                       "of rectangles per class), procedure.cga (CityEngine CGA rules), mesh.zip (a relief mesh: "
                       "facade.obj and facade.mtl), facade.glb and facade.gltf (glTF), facade-photo.glb (with the "
                       "photo), facade.ifc (IFC4), facade.city.json (CityJSON 2.0), overlay.png")
@api_view(["GET"])
@throttle_classes(HEAVY)
@permission_classes([AllowAny])
def procedure_download(request, code, name):
    download = DOWNLOADS.get(name)
    if download is None:
        raise Http404(f"no download named {name!r}; there are {', '.join(DOWNLOADS)}")
    if download.build is None:  # kept in storage: served as a file, the tree read only if it must be drawn
        proc = access.get_procedure_picture_for_user(request.user, code)
        resp = stored_picture(request, proc, name)
    else:
        proc = access.get_procedure_for_user(request.user, code)
        if download.needs_photo and not access.photo_visible_to(request.user, proc.photo):
            raise ValidationError({"photo": f"{name} is drawn with the photo, and this procedure has no photo you "
                                            "may see"})
        resp = HttpResponse(downloads.build(name, proc, request.query_params, request.user),
                            content_type=download.content_type)
        resp["Cache-Control"] = "private"  # what it holds depends on who asks (the photo's title, its real size)
    resp["Content-Disposition"] = f'attachment; filename="{downloads.stem(proc)}-{name}"'
    return resp


@extend_schema(responses={(200, "image/png"): bytes, 304: None},
               summary="The procedure's thumbnail (its label map, at most 320 px a side), as the gallery shows it")
@api_view(["GET"])
@permission_classes([AllowAny])
def procedure_thumbnail(request, code):
    return stored_picture(request, access.get_procedure_picture_for_user(request.user, code), "thumbnail.png")


@extend_schema(request=RerunSerializer, responses={202: JobSerializer},
               summary="Re-run inference keeping the procedure's first `nodes` nodes (BFS)")
@api_view(["POST"])
@permission_classes([IsAuthenticated])
@parser_classes([JSONParser])
def procedure_rerun(request, code):
    proc = access.get_rw_procedure_for_user(request.user, code)
    form = RerunSerializer(data=request.data)
    form.is_valid(raise_exception=True)
    job = rerun(request.user, proc, form.validated_data["nodes"], form.validated_data["k"])
    return Response(JobSerializer(job, context={"request": request}).data, status=status.HTTP_202_ACCEPTED)

