"""A JSON value stored compressed: a procedure's versions are trees of up to megabytes that are written once and read
rarely, and their JSON (repeated keys, sizes written out) shrinks about tenfold with zlib."""

from __future__ import annotations

import json
import zlib

from django.db import models

LEVEL = 6  # zlib's default: ~10x on procedure JSON, a few ms a megabyte


def pack(value) -> bytes:
    """The compressed JSON of ``value`` (as `CompressedJSONField` stores it)."""
    return zlib.compress(json.dumps(value, separators=(",", ":"), allow_nan=False).encode(), LEVEL)


def unpack(raw) -> object:
    return json.loads(zlib.decompress(bytes(raw)))


class CompressedJSONField(models.BinaryField):
    """Reads and writes like a JSONField (a dict in, a dict out) and stores zlib-compressed JSON bytes."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("editable", False)
        super().__init__(*args, **kwargs)

    def from_db_value(self, value, expression, connection):
        return None if value is None else unpack(value)

    def to_python(self, value):
        if isinstance(value, bytes | memoryview):
            return unpack(value)
        if isinstance(value, str):  # loaddata: the JSON text `value_to_string` wrote
            return json.loads(value)
        return value

    def get_db_prep_value(self, value, connection, prepared=False):
        if value is None:
            return None
        if not isinstance(value, bytes | memoryview):
            value = pack(value)
        return super().get_db_prep_value(value, connection, prepared)

    def value_to_string(self, obj):  # dumpdata: the JSON itself
        return json.dumps(self.value_from_object(obj))
