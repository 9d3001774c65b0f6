"""The API's throttle for requests that cost real CPU: rendering a procedure (a preview, or its pictures as a save
commits), variations, rectifying a photo, uploading one, building a download. A rate of its own
(FACAID_API_HEAVY_RATE) on top of the general ones, per account for users and per address for everyone else; reads
of what is already kept (a procedure's JSON, its `labels.png` file) do not count. And a cap on how many such
requests one process serves at once (`HeavySlots`, `slots`), so that a burst of them leaves threads for the light
pages: the API's heavy views take a slot before they run (`webapp.middleware.HeavySlotsMiddleware`), and the pages
and pictures that must draw take one where they draw (`heavy_slot`)."""

import threading
from collections.abc import Iterator
from contextlib import contextmanager
from types import SimpleNamespace

from django.conf import settings
from rest_framework.permissions import SAFE_METHODS
from rest_framework.settings import api_settings
from rest_framework.throttling import UserRateThrottle

from webapp.error_pages import error_response


class HeavyRateThrottle(UserRateThrottle):
    scope = "heavy"

    def allow_request(self, request, view) -> bool:
        if _light(request, view):
            return True
        return super().allow_request(request, view)


def _light(request, view) -> bool:
    """Writes of procedures render pictures; their reads do not. Downloads are built, but for the kept label map."""
    kwargs = getattr(view, "kwargs", {}) or {}
    if "name" in kwargs:  # a download
        return kwargs["name"] == "labels.png"
    return request.method in SAFE_METHODS and request.resolver_match is not None and \
        request.resolver_match.url_name in ("api-procedures", "api-procedure", "api-photos")


HEAVY = [*api_settings.DEFAULT_THROTTLE_CLASSES, HeavyRateThrottle]  # the site's throttles, and this one


def allow_heavy(request) -> tuple[bool, float | None]:
    """The same rate for a page's form (a fork from the procedure page): (allowed, seconds to wait)."""
    throttle = HeavyRateThrottle()
    if throttle.allow_request(request, None):
        return True, None
    return False, throttle.wait()


def is_heavy(request, view_func, view_kwargs) -> bool:
    """Whether a request goes to a view with the heavy throttle, and is not one of its light ones."""
    cls = getattr(view_func, "cls", None)  # an API view (rest_framework's api_view)
    classes = getattr(cls, "throttle_classes", ())
    return any(issubclass(t, HeavyRateThrottle) for t in classes) and \
        not _light(request, SimpleNamespace(kwargs=view_kwargs))


class HeavySlots:
    """At most ``slots`` heavy requests at once in this process (each gunicorn worker has its own): one past them is
    answered at once (`webapp.middleware.HeavySlotsMiddleware`, a 503 with Retry-After) instead of taking a thread
    that a light page needs."""

    def __init__(self, slots: int):
        self.slots = slots
        self._free = threading.BoundedSemaphore(slots)

    def take(self) -> bool:
        return self._free.acquire(blocking=False)

    def give_back(self) -> None:
        self._free.release()


_slots: HeavySlots | None = None
_slots_lock = threading.Lock()


def slots() -> HeavySlots:
    """This process's heavy slots, ``settings.FACAID_HEAVY_SLOTS`` of them (new ones when the setting changes, in a
    test; requests give back the ones they took)."""
    global _slots
    with _slots_lock:
        if _slots is None or _slots.slots != settings.FACAID_HEAVY_SLOTS:
            _slots = HeavySlots(settings.FACAID_HEAVY_SLOTS)
        return _slots


@contextmanager
def heavy_slot(request) -> Iterator[bool]:
    """Hold a heavy slot for the block, where a page or a picture must draw: yields True with one (or where the
    request holds one already, a heavy API view's), False when none is free, at once."""
    if getattr(request, "_heavy_slots", None) is not None:
        yield True
        return
    held = slots()
    if not held.take():
        yield False
        return
    try:
        yield True
    finally:
        held.give_back()


def busy(request, what: str):
    """The answer to a heavy request that found no slot free: a 503 with ``Retry-After``, answered before any of its
    work, which ``X-Facaid-Busy: slots`` tells clients (safe to send again, whatever its method)."""
    return error_response(request, 503, f"the site is busy {what}; try again in a moment",
                          **{"Retry-After": "2", "X-Facaid-Busy": "slots"})
