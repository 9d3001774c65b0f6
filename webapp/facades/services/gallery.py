"""The public gallery's pages, kept in each process's memory while no procedure has changed."""

from __future__ import annotations

import hashlib
from collections.abc import Callable
from typing import Any

from django.core.cache import caches
from django.db.models import Count, Max, Q

from webapp.facades.models import Procedure, Visibility

GALLERY_CACHE_SECONDS = 60  # how long an unchanged gallery page stays in a process's memory (the most a title edit
# committed out of order with another change could show late)


def gallery_page(where: tuple, build: Callable[[], Any]) -> Any:
    """The public gallery's page at ``where`` (the request's scheme, host and full path: the page's links are made
    from it), from each process's memory while no procedure has changed, else ``build()``'s. The key holds the time
    of the latest change and the counts, one aggregate query, so a procedure made private leaves the listing at
    once (the cache of pages holds at most 500 of them)."""
    changed = Procedure.objects.aggregate(at=Max("updated"), n=Count("id"),
                                          public=Count("id", filter=Q(visibility=Visibility.PUBLIC)))
    state = (changed["at"], changed["n"], changed["public"], *where)
    key = "gallery:" + hashlib.sha256(repr(state).encode()).hexdigest()
    pages = caches["pages"]
    page = pages.get(key)
    if page is None:
        page = build()
        pages.set(key, page, GALLERY_CACHE_SECONDS)
    return page
