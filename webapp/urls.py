from django.conf import settings
from django.contrib import admin
from django.urls import include, path
from drf_spectacular.views import SpectacularAPIView, SpectacularSwaggerSplitView


class ApiDocsView(SpectacularSwaggerSplitView):
    """The schema as a page (templates/api_docs.html). The split view serves Swagger UI's set-up script as a request
    of its own (``?script``), as the site's Content-Security-Policy runs no inline script, and leaves the site's own
    Cross-Origin-Opener-Policy alone (the other view loosens it to unsafe-none for OAuth2 pop-ups, which this API
    has none of)."""

    url_name = "schema"
    template_name = "api_docs.html"


urlpatterns = [
    path("admin/", admin.site.urls),
    path("accounts/", include("webapp.accounts.urls")),
    path("api/v1/schema", SpectacularAPIView.as_view(), name="schema"),
    # the schema as a page (Swagger UI from drf-spectacular-sidecar's static files: nothing from another site)
    path("api/v1/docs", ApiDocsView.as_view(), name="api-docs"),
    path("api/v1/", include("webapp.facades.api_urls")),
    path("", include("webapp.facades.urls")),
]

# the site's error pages, and JSON under /api/ (webapp/error_pages.py)
handler400 = "webapp.error_pages.bad_request"
handler403 = "webapp.error_pages.permission_denied"
handler404 = "webapp.error_pages.page_not_found"
handler500 = "webapp.error_pages.server_error"

if settings.DEBUG:
    from django.conf.urls.static import static

    urlpatterns += static(settings.MEDIA_URL, document_root=settings.MEDIA_ROOT)
