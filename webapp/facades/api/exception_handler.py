"""The API's answers to the services' errors (`webapp.facades.errors`), REST_FRAMEWORK's ``EXCEPTION_HANDLER``:
each kind its status (`webapp.error_pages.service_status`), in the JSON the API gives every error,
``{"<field>": "<message>"}`` where input is at fault (as DRF's `ValidationError` of a field) and
``{"detail": "<message>"}`` otherwise; what the request wrote is rolled back. Any other exception is DRF's."""

from __future__ import annotations

from rest_framework.exceptions import NotAuthenticated
from rest_framework.response import Response
from rest_framework.views import exception_handler as drf_exception_handler
from rest_framework.views import set_rollback

from webapp.error_pages import service_status
from webapp.facades.errors import NotSignedIn, ServiceError


def body(exc: ServiceError) -> dict:
    """The JSON of a service's error: its message under the field it names, else under ``detail``."""
    return {exc.field or "detail": exc.message}


def exception_handler(exc, context):
    if isinstance(exc, NotSignedIn):  # DRF's 401: its message and the authentication's challenge, as the view
        # gives them to its own NotAuthenticated (`APIView.handle_exception`)
        unsigned = NotAuthenticated()
        unsigned.auth_header = context["view"].get_authenticate_header(context["request"])
        return drf_exception_handler(unsigned, context)
    if isinstance(exc, ServiceError):
        set_rollback()
        return Response(body(exc), status=service_status(exc))
    return drf_exception_handler(exc, context)
