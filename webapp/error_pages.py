"""Error answers: JSON under /api/ (`{"detail": …}`, as the API's own errors), elsewhere the site's page with its
header and footer (templates/error.html). Wired as Django's handlers in webapp/urls.py and used by the middleware.

A page drawn with ``static=True`` reads nothing from the request (no session, no user, no messages): it renders
with the database unreachable. The 500 page, a 503 and the answers given before the session is read are drawn so."""

from __future__ import annotations

import logging

from django.http import HttpResponse, JsonResponse
from django.template import loader

log = logging.getLogger(__name__)

TITLES = {400: "Bad request", 403: "Not allowed", 404: "Not found", 405: "Not this way", 413: "Too large",
          500: "Server error", 503: "Try again in a moment"}
# what each page says besides the error's own message; the 404 reads the same for a page that does not exist and one
# the viewer may not see, so that it does not tell which
TEXTS = {
    400: "The request could not be read.",
    403: "You may look at this, but only its owner may change it.",
    404: "There is nothing here, or it is not shared with you.",
    405: "This address takes a form's button, not a link: go back and use the button.",
    500: "Something went wrong on our side. It has been logged; try again in a moment.",
}
# the services' errors (`webapp.facades.errors`) by kind, as the API answers them and the pages show them
SERVICE_STATUS = {"invalid": 400, "over_quota": 400, "not_found": 404, "not_allowed": 403, "not_signed_in": 401,
                  "too_many_jobs": 429}
# the page's last resort: what is answered if even the template fails
BARE_PAGE = ("<!doctype html><html lang=\"en\"><meta charset=\"utf-8\"><title>{title} · FaçAID</title>"
             "<p><a href=\"/\">FaçAID</a></p><h1>{title}</h1><p>{message}</p></html>")


def is_api(request) -> bool:
    return request.path.startswith("/api/")


def error_response(request, status: int, message: str = "", *, text: str | None = None, static: bool = False,
                   **headers: str) -> HttpResponse:
    """The answer to a request that failed with ``status``: JSON under /api/ (``message`` or the status's title as
    its ``detail``), else the site's error page saying ``message`` under ``text`` (by default the status's own);
    ``headers`` are added to either."""
    title = TITLES.get(status, "Error")
    if is_api(request):
        response = JsonResponse({"detail": message or f"{title}."}, status=status)
    else:
        if message and message[-1] not in ".!?)":
            message += "."
        context = {"status": status, "title": title, "message": message[:1].upper() + message[1:],
                   "text": TEXTS.get(status, "") if text is None else text}
        try:
            template = loader.get_template("error.html")
            html = template.render(context) if static else template.render(context, request)
        except Exception:  # a broken page must not hide the error it reports
            log.exception("the error page (%s) could not be drawn", status)
            html = BARE_PAGE.format(title=title, message=message or context["text"])
        response = HttpResponse(html, status=status)
    for name, value in headers.items():
        response[name] = value
    return response


def _message(exception) -> str:
    """The exception's own message where it is one (a resolver's 404 carries a dict of the patterns tried)."""
    message = exception.args[0] if exception is not None and exception.args else ""
    return message if isinstance(message, str) else ""


def service_status(exc) -> int:
    """The HTTP status of a service's error, from its kind (`SERVICE_STATUS`; an unknown kind is a bad request)."""
    return SERVICE_STATUS.get(getattr(exc, "kind", ""), 400)


def bad_request(request, exception=None):
    return error_response(request, 400)  # its message may echo the request (a Host header): not shown


def permission_denied(request, exception=None):
    return error_response(request, 403, _message(exception))


def page_not_found(request, exception=None):
    return error_response(request, 404, _message(exception))


def server_error(request):
    return error_response(request, 500, static=True)


def csrf_failure(request, reason: str = ""):
    """A form sent without its CSRF token (an old page, or cookies off): the 403 page, saying what to do."""
    return error_response(request, 403, text="The form had expired, or the browser blocks cookies: reload the "
                                             "page and send it again.")
