"""`facaid rectify`: a photo's facade corners proposed, and the photo rectified."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from facaid.cli.common import CliError, open_photo, write_json


def _corners_arg(text: str) -> list[list[float]]:
    """``--corners``: a JSON list of four [x, y] points, or "x,y x,y x,y x,y"."""
    try:
        value = json.loads(text) if text.lstrip().startswith("[") else [
            [float(v) for v in point.split(",")] for point in text.split()]
    except ValueError:
        raise CliError(f"--corners: give four points as \"x,y x,y x,y x,y\" or a JSON list, got {text!r}") from None
    return value


def cmd_rectify(args: argparse.Namespace) -> None:
    from facaid.photo.corners import propose_corners
    from facaid.photo.rectify import output_size, rectify

    if not (args.propose or args.corners):
        raise CliError("give --propose (find the corners) or --corners (use these)")
    if args.corners and args.propose:
        raise CliError("give --propose or --corners, not both")
    photo = open_photo(args.photo)  # corners are where a viewer shows them
    if args.propose:
        found = propose_corners(photo)
        corners = found["corners"]
        print(f"proposed corners (TL, TR, BR, BL) of the {photo.width}x{photo.height} photo: "
              + " ".join(f"{x:g},{y:g}" for x, y in corners) + f"; confidence {found['confidence']:.2f}")
        for note in found["notes"]:
            print(f"note: {note}")
    else:
        corners = _corners_arg(args.corners)
        found = {"corners": corners}
    try:
        out = rectify(photo, corners) if args.out else None
        output_size(corners)
    except ValueError as exc:
        raise CliError(f"--corners: {exc}") from None
    if out is not None:
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        try:
            out.save(args.out)
        except (ValueError, OSError) as exc:  # an extension PIL has no writer for
            raise CliError(f"--out {args.out}: {exc}") from None
        print(f"wrote {args.out} ({out.width}x{out.height})")
    write_json(args.json, {**found, "width": photo.width, "height": photo.height})


def add_rectify(sub) -> None:
    rc = sub.add_parser("rectify", help="propose a photo's four facade corners, or rectify it from four corners",
                        description="Find the facade's four corners in a photo from its straight lines and vanishing "
                                    "points (--propose), or take them (--corners), and write the fronto-parallel "
                                    "image (--out) and the corners (--json). Corners are top-left, top-right, "
                                    "bottom-right, bottom-left, in the photo's pixels as a viewer shows it (EXIF "
                                    "orientation applied).")
    rc.add_argument("photo", help="the photo (JPEG, PNG, WebP, ...)")
    rc.add_argument("--propose", action="store_true", help="find the corners from the photo's lines")
    rc.add_argument("--corners", help='four points: "x,y x,y x,y x,y" or a JSON list [[x, y], ...]')
    rc.add_argument("--out", help="write the rectified image to this file (its format from the extension)")
    rc.add_argument("--json", help="write the corners (with the proposal's confidence and notes) to this JSON file")
    rc.set_defaults(func=cmd_rectify)
