"""The site's settings from the environment: the worker's loud helpers (`worker.env`), and the throttle rates
only the site reads."""

from __future__ import annotations

import os

from worker.env import EnvError, env_bool, env_float, env_int, env_list, env_str

__all__ = ["EnvError", "env_bool", "env_float", "env_int", "env_list", "env_rate", "env_str"]

RATE_PERIODS = ("s", "m", "h", "d")


def env_rate(name: str, default: str | None) -> str | None:
    """A throttle rate as Django REST framework reads it ("120/min": a count per s, m, h or d; only the period's
    first letter counts), or None for "none" / "off" (no limit)."""
    raw = os.environ.get(name)
    if raw is None or raw.strip() == "":
        return default
    value = raw.strip().lower()
    if value in ("none", "off"):
        return None
    count, _, period = value.partition("/")
    if not count.isdigit() or int(count) < 1 or not period or period[0] not in RATE_PERIODS:
        raise EnvError(f"{name} must be a rate like 120/min (a count per s, min, hour or day) or 'none', "
                       f"got {raw!r}")
    return value
