"""Site-wide guards that answer before a view runs or when the database cannot: a request body larger than any
the site accepts is refused from its Content-Length (413) before a byte of it is read, and a database that is
locked or unreachable is a 503 that says so instead of a 500. Both answer JSON under /api/ and the site's error page
elsewhere (`webapp.error_pages`), drawn without the session or the database. Whatever is answered below the size
limit, what the view left unread of the body is read first, so that the connection can carry the next request. And every
request has a work budget: the trees it reads and makes may lay out at most ``FACAID_REQUEST_WORK`` node instances
in all and take ``FACAID_REQUEST_SECONDS`` of CPU (`facaid.grammar.budget`), past which it is a 400 that names the
limit. A service's error that a page does not catch (a photo or procedure not found, or not the viewer's to change, a
write past the storage quota) is the site's error page with its status and message."""

from __future__ import annotations

import logging
import secrets

from django.conf import settings
from django.contrib.auth.views import redirect_to_login
from django.db import OperationalError

from facaid.grammar.budget import WorkLimitError, work_budget
from webapp.error_pages import error_response, is_api, service_status
from webapp.facades import throttling
from webapp.facades.errors import NotSignedIn, ServiceError
from webapp.facades.throttling import is_heavy

log = logging.getLogger(__name__)

MULTIPART_SLACK = 1024 * 1024  # form fields and multipart boundaries around an upload of the largest size


def max_request_bytes(content_type: str) -> tuple[int, str]:
    """The largest body of this content type the site reads, and what it is."""
    if content_type.startswith("multipart/form-data"):
        return (settings.FACAID_MAX_UPLOAD_BYTES + MULTIPART_SLACK,
                f"uploads (photos up to {settings.FACAID_MAX_UPLOAD_BYTES / 2**20:.0f} MB)")
    return settings.DATA_UPLOAD_MAX_MEMORY_SIZE, "JSON and form bodies"


# What a page may load and run: only this site's own files (the pages are ES modules and stylesheets from
# /static/, three.js among them), no inline script but the 3D preview's import map (which browsers read only inline)
# by the request's nonce, no style attribute or <style> in markup (the scripts set styles as properties), pictures
# also as data: (the icon) and blob: URLs (pictures fetched, and the 3D model's textures), which three.js's loader
# also fetches; nothing framed, no plugin, forms posted here only.
CONTENT_SECURITY_POLICY = ("default-src 'self'; script-src 'self' 'nonce-{nonce}'; style-src 'self'; "
                           "img-src 'self' data: blob:; connect-src 'self' blob:; font-src 'self'; "
                           "object-src 'none'; base-uri 'none'; form-action 'self'; frame-ancestors 'none'")


class ContentSecurityPolicyMiddleware:
    """A ``Content-Security-Policy`` header on every response (`CONTENT_SECURITY_POLICY`), with a nonce made for the
    request (``request.csp_nonce``) that a template gives the one inline script it needs."""

    def __init__(self, get_response):
        self.get_response = get_response

    def __call__(self, request):
        request.csp_nonce = nonce = secrets.token_urlsafe(16)
        response = self.get_response(request)
        response.setdefault("Content-Security-Policy", CONTENT_SECURITY_POLICY.format(nonce=nonce))
        return response


class RequestSizeLimitMiddleware:
    """413 for a declared body over the largest the site accepts of its kind (a photo upload, or a JSON or form
    body). Django reads no more than Content-Length, so a body without one is read as empty."""

    def __init__(self, get_response):
        self.get_response = get_response

    def __call__(self, request):
        try:
            length = int(request.META.get("CONTENT_LENGTH") or 0)
        except ValueError:
            return error_response(request, 400, "Content-Length must be a whole number of bytes", static=True)
        limit, what = max_request_bytes(request.META.get("CONTENT_TYPE", ""))
        if length > limit:
            return error_response(request, 413, f"the request is {length / 2**20:.1f} MB; at most "
                                                f"{limit / 2**20:.0f} MB are accepted for {what}", static=True)
        return self.get_response(request)


class UnreadBodyMiddleware:
    """The rest of a request's body, where the answer came before the view read it all (a 503 of a busy process or
    database, a 403, a 429), is read and dropped before the answer goes out. A server that keeps the connection
    alive must skip those bytes to find the next request; gunicorn skips at most 64 KB and past that closes the
    connection it announced as kept alive, so a client's next request on it failed. The body is at most the size
    limit (`RequestSizeLimitMiddleware`, outside this one), and reading what a client sends costs no CPU to speak
    of. (A WSGI application cannot say ``Connection: close``: servers drop hop-by-hop headers.)"""

    CHUNK = 1 << 16

    def __init__(self, get_response):
        self.get_response = get_response

    def __call__(self, request):
        response = self.get_response(request)
        try:
            while request.read(self.CHUNK):  # bounded by Content-Length; nothing left, or what a view kept, reads b""
                pass
        except OSError:  # the client went away (Django's UnreadablePostError is one): no next request to keep
            pass
        return response


class BusyDatabaseMiddleware:
    """503 with Retry-After when the database is locked past its timeout or unreachable."""

    def __init__(self, get_response):
        self.get_response = get_response

    def __call__(self, request):
        return self.get_response(request)

    def process_exception(self, request, exception):
        if not isinstance(exception, OperationalError):
            return None
        log.warning("database unavailable for %s %s: %s", request.method, request.path, exception)
        return error_response(request, 503, "the database is busy or unavailable; try again in a few seconds",
                              static=True, **{"Retry-After": "5"})


class WorkBudgetMiddleware:
    """One work budget per request (`facaid.grammar.budget`): ``settings.FACAID_REQUEST_WORK`` node instances and
    ``settings.FACAID_REQUEST_SECONDS`` of CPU; the request that asks for more is a 400 naming the limit."""

    def __init__(self, get_response):
        self.get_response = get_response

    def __call__(self, request):
        with work_budget(settings.FACAID_REQUEST_WORK, settings.FACAID_REQUEST_SECONDS):
            return self.get_response(request)

    def process_exception(self, request, exception):
        if not isinstance(exception, WorkLimitError):
            return None
        return error_response(request, 400, str(exception))


class ServiceErrorMiddleware:
    """A service's error (`webapp.facades.errors`) that a page did not catch: the error page with the status of
    its kind (`webapp.error_pages.service_status`) and its message (a 404 for an object the viewer may not see,
    a 403 for one they may not change, a 400 for a write past the storage quota; a change asked without an account
    goes to the sign-in page). The API answers them itself (`webapp.facades.api.exception_handler`), in its JSON.
    And a page's empty 405 (a POST-only address opened as a link) becomes the site's error page."""

    def __init__(self, get_response):
        self.get_response = get_response

    def __call__(self, request):
        response = self.get_response(request)
        if response.status_code == 405 and not response.content and not is_api(request):  # a POST-only page opened
            # as a link (`require_POST` answers an empty 405): the site's page, its Allow kept
            return error_response(request, 405, Allow=response.get("Allow", ""))
        return response

    def process_exception(self, request, exception):
        if not isinstance(exception, ServiceError):
            return None
        if isinstance(exception, NotSignedIn):
            return redirect_to_login(request.get_full_path())
        return error_response(request, service_status(exception), exception.text())


class HeavySlotsMiddleware:
    """At most ``settings.FACAID_HEAVY_SLOTS`` requests to heavy API views (`webapp.facades.throttling.is_heavy`)
    at once in this process; another is a 503 with ``Retry-After`` at once, so that a burst of them (anonymous ones
    too) leaves the other threads to the gallery, job status and pages. It is answered before the view runs, which
    ``X-Facaid-Busy: slots`` tells clients: such a request is safe to send again, whatever its method."""

    def __init__(self, get_response):
        self.get_response = get_response

    def __call__(self, request):
        try:
            return self.get_response(request)
        finally:
            slots = getattr(request, "_heavy_slots", None)
            if slots is not None:
                request._heavy_slots = None
                slots.give_back()

    def process_view(self, request, view_func, view_args, view_kwargs):
        if not is_heavy(request, view_func, view_kwargs):
            return None
        slots = throttling.slots()
        if not slots.take():
            return throttling.busy(request, f"with {slots.slots} heavy requests (rendering, variations, downloads) in "
                                            "this process")
        request._heavy_slots = slots
        return None
