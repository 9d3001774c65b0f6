"""What every command of the command line shares: its error, reading and writing JSON, opening a photo."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any


class CliError(Exception):
    pass


def read_json(path: str) -> Any:
    try:
        text = Path(path).read_text(encoding="utf-8")
    except OSError as exc:
        raise CliError(f"cannot read {path}: {exc.strerror}") from None
    except UnicodeDecodeError:
        raise CliError(f"{path} is not a UTF-8 text file") from None
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise CliError(f"{path}: malformed JSON: {exc}") from None


def json_object(data: bytes) -> Any:
    """The JSON value of ``data``, or None where it is not JSON."""
    try:
        return json.loads(data)
    except (ValueError, RecursionError):
        return None


def write_json(path: str | None, payload: dict) -> None:
    if path:
        Path(path).parent.mkdir(parents=True, exist_ok=True)  # a long run's figures are not lost to a missing folder
        Path(path).write_text(json.dumps(payload, indent=2) + "\n")
        print(f"wrote {path}")


def open_photo(path: str):
    """The photo at ``path`` as a viewer shows it (`facaid.photo.files.open_photo`: EXIF orientation applied), or a
    `CliError` naming it."""
    from PIL import Image, UnidentifiedImageError

    from facaid.photo.files import open_photo as open_upright

    try:
        return open_upright(path)
    except FileNotFoundError:
        raise CliError(f"cannot read photo {path}: no such file") from None
    except UnidentifiedImageError as exc:
        raise CliError(f"cannot read photo {path}: not an image PIL reads ({exc})") from None
    except (OSError, Image.DecompressionBombError) as exc:
        raise CliError(f"cannot read photo {path}: {exc}") from None


def load_segmentation_or_procedure(obj: Any):
    """A segmentation from a segmentation, a procedure, or a dataset sample record."""
    from facaid.grammar.execute import to_segmentation
    from facaid.grammar.procedure import Procedure
    from facaid.segmentation import Segmentation

    if isinstance(obj, dict) and "procedure" in obj and "format" not in obj:
        obj = obj["procedure"]
    if isinstance(obj, dict) and obj.get("format") is not None:
        return to_segmentation(Procedure.from_dict(obj))
    return Segmentation.from_dict(obj)
