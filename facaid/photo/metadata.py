"""What an image file says beside its pixels (EXIF with the camera and the place, XMP, comments, text), dropped from
the file's bytes without decoding it: a photo kept as it was uploaded is published without them, as a re-encoded
one always was."""

from __future__ import annotations

import struct

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
PNG_DROPPED = {b"eXIf", b"tEXt", b"zTXt", b"iTXt", b"tIME", b"iCCP"}  # what the pixels do not need
JPEG_KEPT = {0xE0, 0xEE}  # APP0 (JFIF) and APP14 (Adobe: how the colours are transformed); other APPn and COM go
SOS = 0xDA


def stripped(data: bytes, fmt: str) -> bytes:
    """``data`` (a JPEG or PNG file) without its metadata; ValueError for a file whose structure is broken."""
    if fmt == "PNG":
        return _png(data)
    if fmt == "JPEG":
        return _jpeg(data)
    raise ValueError(f"no metadata stripping for {fmt}")


def _png(data: bytes) -> bytes:
    if not data.startswith(PNG_SIGNATURE):
        raise ValueError("not a PNG file")
    out, at = [PNG_SIGNATURE], len(PNG_SIGNATURE)
    while at + 8 <= len(data):
        (length,), kind = struct.unpack(">I", data[at: at + 4]), data[at + 4: at + 8]
        end = at + 12 + length
        if end > len(data):
            raise ValueError("a PNG chunk runs past the end of the file")
        if kind not in PNG_DROPPED:
            out.append(data[at:end])
        at = end
        if kind == b"IEND":
            break
    return b"".join(out)


def _jpeg(data: bytes) -> bytes:
    if not data.startswith(b"\xff\xd8"):
        raise ValueError("not a JPEG file")
    out, at = [data[:2]], 2
    while at + 4 <= len(data):
        if data[at] != 0xFF:
            raise ValueError("a JPEG marker was expected")
        marker = data[at + 1]
        if marker == 0xFF:  # fill byte
            at += 1
            continue
        (length,) = struct.unpack(">H", data[at + 2: at + 4])
        end = at + 2 + length
        if marker == SOS:  # the compressed picture follows, to the end: kept as it is
            out.append(data[at:])
            return b"".join(out)
        if not (0xE0 <= marker <= 0xEF or marker == 0xFE) or marker in JPEG_KEPT:
            out.append(data[at:end])
        at = end
    raise ValueError("the JPEG has no picture (no start of scan)")
