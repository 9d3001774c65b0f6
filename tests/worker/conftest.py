"""Fixtures of the worker's tests: the site's (`tests/site/site_fixtures.py`: the users, a media root and a fresh cache
per test, a real Redis server and a real worker process), since a job is submitted through the site and stored
through its models."""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "site"))  # site_fixtures and site_helpers

from site_fixtures import alice, bob, fresh_cache, media_root, redis, worker  # noqa: E402, F401
