"""Numbers as JSON brings them: any integer, any double."""

from __future__ import annotations

import math


def finite(value: int | float) -> bool:
    """`math.isfinite`, where an integer too large for a float (JSON allows any) counts as not finite instead of
    raising OverflowError."""
    try:
        return math.isfinite(value)
    except OverflowError:
        return False
