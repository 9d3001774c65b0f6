"""The API's throttle for requests that cost real CPU: rendering a procedure (a preview, or its pictures as a save
commits), variations, rectifying a photo, building a download. A rate of its own (FACAID_API_HEAVY_RATE) on top of
the general ones, per account for users and per address for everyone else; reads of what is already kept
(a procedure's JSON, its `labels.png` file) do not count."""

from rest_framework.permissions import SAFE_METHODS
from rest_framework.settings import api_settings
from rest_framework.throttling import UserRateThrottle


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
        request.resolver_match.url_name in ("api-procedures", "api-procedure")


HEAVY = [*api_settings.DEFAULT_THROTTLE_CLASSES, HeavyRateThrottle]  # the site's throttles, and this one


def allow_heavy(request) -> tuple[bool, float | None]:
    """The same rate for a page's form (a fork from the procedure page): (allowed, seconds to wait)."""
    throttle = HeavyRateThrottle()
    if throttle.allow_request(request, None):
        return True, None
    return False, throttle.wait()
