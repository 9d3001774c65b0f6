"""`facaid cga`, `mesh`, `export`, `convert` and `validate-cityjson`: procedures and annotations in other
formats, and a check of CityJSON files."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from facaid.cli.common import CliError, json_object, load_segmentation_or_procedure, open_photo, read_json


def cmd_cga(args: argparse.Namespace) -> None:
    from facaid.formats.cga import default_scale, procedure_cga
    from facaid.grammar.procedure import Procedure

    proc = Procedure.from_dict(read_json(args.input))
    scale = args.metres_per_pixel if args.metres_per_pixel is not None else default_scale(proc)
    text = procedure_cga(proc, args.metres_per_pixel, name=Path(args.input).name)
    Path(args.out).write_text(text, encoding="utf-8")
    print(f"wrote {args.out} ({text.count(' -->')} rules, {proc.width * scale:.2f} m x {proc.height * scale:.2f} m "
          f"at {scale:.4g} m per pixel)")


def cmd_mesh(args: argparse.Namespace) -> None:
    from facaid.formats.mesh import procedure_mesh
    from facaid.grammar.procedure import Procedure

    out = Path(args.out)
    if out.suffix.lower() != ".obj":
        raise CliError(f"--out must be a file name that ends in .obj (its materials go beside it), got {args.out}")
    proc = Procedure.from_dict(read_json(args.input))
    mtl_path = out.with_suffix(".mtl")
    obj, mtl = procedure_mesh(proc, args.metres_per_pixel, mtl_name=mtl_path.name)
    out.write_text(obj, encoding="utf-8")
    mtl_path.write_text(mtl, encoding="utf-8")
    print(f"wrote {out} ({obj.count(chr(10) + 'f ')} faces) and {mtl_path}")


def add_cga_and_mesh(sub) -> None:
    exports = (
        ("cga", cmd_cga, "a procedure as CityEngine CGA rules", "output .cga file",
         "Write a procedure as a CGA rule file: apply its start rule Facade to a facade shape in CityEngine. Fixed "
         "sizes keep their metres, floating ones share the rest and repeats lay out as many copies as fit "
         "(docs/pipeline.md)."),
        ("mesh", cmd_mesh, "a procedure as a relief mesh (OBJ and MTL)",
         "output .obj file; the .mtl of the same name is written beside it",
         "Write a procedure as a Wavefront OBJ relief mesh with its MTL beside it: windows, doors and shops set back, "
         "cornices, sills, pillars and balconies standing out, one material per label (docs/pipeline.md)."),
    )
    for name, func, summary, out_help, description in exports:
        e = sub.add_parser(name, help=summary, description=description)
        e.add_argument("input", help="procedure JSON")
        e.add_argument("--out", required=True, help=out_help)
        e.add_argument("--metres-per-pixel", type=float, default=None,
                       help="the scale (default: a storey, from the floors or the rows of windows, is 3 m tall; "
                            "12 m for the whole facade when it has neither)")
        e.set_defaults(func=func)


def cmd_export(args: argparse.Namespace) -> None:
    from facaid.formats.cga import STOREY_M, checked_scale
    from facaid.formats.exports import EXPORTS, export_for
    from facaid.grammar.procedure import Procedure

    found = export_for(args.out)
    if found is None:
        raise CliError(f"--out {args.out}: the format comes from the file's extension, one of {' '.join(EXPORTS)}")
    ext, export = found
    if args.metres_per_pixel is not None and not export.scaled:
        raise CliError(f"--metres-per-pixel sets the scale of the exports in metres; a {ext} file is in pixels")
    if args.photo and not export.photo:
        raise CliError(f"--photo is the texture of a .glb or .gltf, or under an .overlay.png; a {ext} file has none")
    if export.needs_photo and not args.photo:
        raise CliError(f"a {ext} file is drawn over the photo: give it with --photo")
    proc = Procedure.from_dict(read_json(args.input))
    photo = open_photo(args.photo) if args.photo else None
    if photo is not None and abs(photo.width * proc.height / (photo.height * proc.width) - 1) > 0.02:
        print(f"warning: the photo ({photo.width}x{photo.height}) is stretched over the procedure "
              f"({proc.width:g}x{proc.height:g}): give the rectified photo it was drawn on", file=sys.stderr)
    note = ""
    if export.scaled:
        try:
            scale = checked_scale(proc, args.metres_per_pixel)
        except ValueError as exc:
            raise CliError(f"--metres-per-pixel: {exc}") from None
        source = "given" if args.metres_per_pixel is not None else f"a storey {STOREY_M:g} m tall"
        note = f", {proc.width * scale:.2f} m x {proc.height * scale:.2f} m at {scale:.4g} m per pixel ({source})"
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    paths = export.write(proc, out, args.metres_per_pixel, photo)
    print(f"wrote {' and '.join(str(p) for p in paths)}: {export.what}{note}")


def add_export(sub) -> None:
    from facaid.formats.exports import EXPORTS

    x = sub.add_parser("export", help="a procedure in another format, chosen by the output's extension",
                       description="Write a procedure as " + "; ".join(f"{ext} {e.what}" for ext, e in EXPORTS.items())
                                   + ". The 3D formats and the CGA rules are in metres (docs/pipeline.md).")
    x.add_argument("input", help="procedure JSON")
    x.add_argument("--out", required=True, help="the file to write; its extension says the format")
    x.add_argument("--metres-per-pixel", type=float, default=None,
                   help="the scale of the metric formats (default: a storey, from the floors or the rows of windows, "
                        "is 3 m tall; 12 m for the whole facade when it has neither)")
    x.add_argument("--photo", help="the rectified photo the procedure was drawn on, shown on the fronts of a .glb or "
                                   ".gltf, or under an .overlay.png")
    x.set_defaults(func=cmd_export)


def cmd_convert(args: argparse.Namespace) -> None:
    from facaid.formats import interchange

    fmt = args.to or interchange.format_for_name(args.out)
    if fmt is None:
        raise CliError(f"say the format of {args.out} with --to, or end its name in .coco.json, .labelme.json, "
                       f".cvat.xml or .json")
    try:
        data = Path(args.input).read_bytes()
    except OSError as exc:
        raise CliError(f"cannot read {args.input}: {exc.strerror}") from None
    try:
        loaded = interchange.load(data, image=args.image)
        seg, source, name, warnings = loaded.segmentation, loaded.format, loaded.image, loaded.warnings
    except interchange.SeveralImages as exc:
        raise CliError(f"{args.input}: {exc} with --image NAME") from None
    except interchange.InterchangeError:
        obj = json_object(data)
        if not (isinstance(obj, dict) and ("procedure" in obj or obj.get("format") is not None)):
            raise
        from facaid.formats.annotation import written_as

        seg, source, name, warnings = written_as(load_segmentation_or_procedure(obj), fmt), "procedure", None, ()
    for line in warnings:
        print(f"warning: {line}", file=sys.stderr)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_bytes(interchange.write(seg, fmt, image=name or args.image or "facade.png"))
    print(f"wrote {out} ({fmt}, {seg.width}x{seg.height}, {len(seg.rects)} rectangles, read as {source})")


def add_convert(sub) -> None:
    cv = sub.add_parser("convert", help="convert annotations between COCO, LabelMe, CVAT and our segmentation",
                        description="Read rectangle annotations (COCO object detection JSON, LabelMe JSON, CVAT for "
                                    "images XML, a segmentation, or a procedure's), the format found from the "
                                    "content, and write them in another (docs/interchange.md). Edges are rounded to "
                                    "whole pixels and clipped to the image; polygons become their bounding boxes, "
                                    "with a warning.")
    cv.add_argument("input", help="annotation file")
    cv.add_argument("--out", required=True,
                    help="file to write; its format from --to, else from its name: .coco.json, .labelme.json, "
                         ".cvat.xml, or .json for the segmentation contract")
    cv.add_argument("--to", choices=("coco", "labelme", "cvat", "segmentation"), help="the format to write")
    cv.add_argument("--image", metavar="NAME",
                    help="the image to read from a COCO or CVAT file of several (its file name, with or without "
                         "folders, or its id); also names the image in the output where the input does not")
    cv.set_defaults(func=cmd_convert)


def cmd_validate_cityjson(args: argparse.Namespace) -> None:
    from facaid.formats.cityjson_check import SCHEMAS, check_cityjson

    invalid = 0
    for path in args.files:
        try:
            report = check_cityjson(Path(path).read_bytes())
        except OSError as exc:
            raise CliError(f"cannot read {path}: {exc.strerror}") from None
        if report.valid:
            schema = SCHEMAS[report.version].split(".min")[0]
            print(f"{path}: valid CityJSON {report.version} (schema {schema}, vertices, semantics, "
                  f"parents and children): {report.summary()}")
        else:
            invalid += 1
            print(f"{path}: not valid")
        for line in report.errors:
            print(f"  error: {line}")
        for line in report.warnings:
            print(f"  warning: {line}")
    if invalid:
        raise CliError(f"{invalid} of {len(args.files)} files are not valid CityJSON")


def add_validate_cityjson(sub) -> None:
    vc = sub.add_parser("validate-cityjson", help="check CityJSON files as the official validator (cjval) does",
                        description="Check CityJSON 2.0 and 1.0 files: the JSON, the official schema of their "
                                    "version (shipped), vertex indices, semantics arrays, parents and children; "
                                    "warn of duplicate and unused vertices. Exit status 2 when a file is not valid.")
    vc.add_argument("files", nargs="+", metavar="FILE", help="a .city.json file")
    vc.set_defaults(func=cmd_validate_cityjson)
