"""The site's errors, in its own words rather than HTTP's: what the services raise, and the layers below them
(the models, access, parsing, uploads) too. Each has a ``kind`` (what went wrong) and a message for a person;
`Invalid` also names the ``field`` of the input at fault. The JSON API answers each kind with its status
(`webapp.error_pages.service_status`, `webapp.facades.api.exception_handler`); the pages say the message where
they ask for the input, and show the site's error page for the rest (`webapp.middleware.ServiceErrorMiddleware`).

Others of the site's errors are of these kinds too: a refused upload (`webapp.facades.uploads.UploadError`) and
malformed JSON pasted in a page (`webapp.facades.jsonbody.JSONError`) are `Invalid`."""

from __future__ import annotations


class ServiceError(Exception):
    """What a service refused to do, and why (``message``, for the person who asked)."""

    kind = "error"

    def __init__(self, message: str, field: str | None = None):
        super().__init__(message)
        self.message = str(message)
        self.field = field

    def __str__(self) -> str:
        return self.message

    def text(self) -> str:
        """The message, after the field it names where it names one: ``"corners: corner (9, 9) lies far outside"``."""
        return f"{self.field}: {self.message}" if self.field else self.message


class Invalid(ServiceError):
    """Input the service cannot take: ``field`` names it (``image``, ``corners``, ``segmentation``, ``data``, ...)
    where one is at fault."""

    kind = "invalid"


class NotFound(ServiceError):
    """No such object, or none the asker may see: the two read the same, so that the error does not tell which."""

    kind = "not_found"


class NotAllowed(ServiceError):
    """An object the asker may see but not change (another's, or the demo's), or an account that may not do this."""

    kind = "not_allowed"


class NotSignedIn(NotAllowed):
    """A change asked without an account: the API answers it as DRF's 401 (with its ``WWW-Authenticate``), a page
    sends to the sign-in page. A `NotAllowed`: what catches that one catches it too."""

    kind = "not_signed_in"


class TooManyJobs(ServiceError):
    """The account has as many reconstructions waiting or running as it may (``FACAID_MAX_ACTIVE_JOBS``)."""

    kind = "too_many_jobs"


class QuotaError(ServiceError):
    """A write past its owner's storage quota; the message says how much is used, by what, and what to do."""

    kind = "over_quota"
