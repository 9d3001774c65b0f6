"""Django settings. Everything deployment-specific comes from the environment (see docs/site.md):
DATABASE_URL (SQLite in var/ by default), REDIS_URL (a local Redis by default), SECRET_KEY, DEBUG, ..."""

from __future__ import annotations

from datetime import timedelta
from pathlib import Path

import dj_database_url
from django.core.exceptions import ImproperlyConfigured

from webapp.env import env_bool, env_float, env_int, env_list, env_rate, env_str

BASE_DIR = Path(__file__).resolve().parent.parent
VAR_DIR = Path(env_str("FACAID_VAR", str(BASE_DIR / "var")))
VAR_DIR.mkdir(parents=True, exist_ok=True)

DEBUG = env_bool("DEBUG", False)
DEVELOPMENT_SECRET_KEY = "facaid-local-development-key-not-for-production"
SECRET_KEY = env_str("SECRET_KEY", "")
if not DEBUG and SECRET_KEY in ("", DEVELOPMENT_SECRET_KEY):
    raise ImproperlyConfigured(
        "SECRET_KEY is not set: with DEBUG off the site needs a secret key of its own. Set SECRET_KEY to a long "
        "random string (e.g. export SECRET_KEY=\"$(python3 -c 'import secrets; print(secrets.token_urlsafe(50))')\"; "
        "bash scripts/run keeps one in var/secret_key), or set DEBUG=1 for local development only.")
SECRET_KEY = SECRET_KEY or DEVELOPMENT_SECRET_KEY
ALLOWED_HOSTS = env_list("ALLOWED_HOSTS", ["127.0.0.1", "localhost", "testserver"])
CSRF_TRUSTED_ORIGINS = env_list("CSRF_TRUSTED_ORIGINS", [])

# HTTPS. With DEBUG off the site is https-only by default: secure cookies, a redirect of http to https, HSTS.
# FACAID_HTTPS=0 serves plain http (scripts/run on 127.0.0.1); DEBUG=1 does too. Behind a TLS-terminating proxy,
# FACAID_PROXY_SSL_HEADER names the header the proxy sets to "https" (e.g. X-Forwarded-Proto); only set it when
# the proxy overwrites that header on every request, as a client could send it otherwise.
HTTPS = not DEBUG and env_bool("FACAID_HTTPS", True)
SESSION_COOKIE_SECURE = HTTPS
CSRF_COOKIE_SECURE = HTTPS
CSRF_COOKIE_HTTPONLY = True  # the pages read the token from <meta name="csrf-token">, never from the cookie
SECURE_SSL_REDIRECT = HTTPS
SECURE_HSTS_SECONDS = env_int("FACAID_HSTS_SECONDS", 365 * 24 * 3600) if HTTPS else 0
SECURE_HSTS_INCLUDE_SUBDOMAINS = env_bool("FACAID_HSTS_INCLUDE_SUBDOMAINS", True)
SECURE_HSTS_PRELOAD = env_bool("FACAID_HSTS_PRELOAD", True)
_proxy_ssl_header = env_str("FACAID_PROXY_SSL_HEADER", "").strip()
if _proxy_ssl_header:
    SECURE_PROXY_SSL_HEADER = ("HTTP_" + _proxy_ssl_header.upper().replace("-", "_"), "https")
SECURE_CONTENT_TYPE_NOSNIFF = True
SECURE_REFERRER_POLICY = "same-origin"
SECURE_CROSS_ORIGIN_OPENER_POLICY = "same-origin"
X_FRAME_OPTIONS = "DENY"
CSRF_FAILURE_VIEW = "webapp.error_pages.csrf_failure"  # the site's 403 page, saying to reload the form
# proxies in front of the site that append the client's address to X-Forwarded-For: the address that the login
# lockouts and the API's anonymous throttle count is the one the outermost of them saw (0: REMOTE_ADDR, and a
# client's own X-Forwarded-For is ignored)
FACAID_PROXY_COUNT = env_int("FACAID_PROXY_COUNT", 0)
# what the trees one request reads and makes may cost (facaid.grammar.budget): node instances in all (20 trees at
# the grammar's limit, MAX_INSTANCES; the most an honest request made was 590,000: 32 variations of the largest CMP
# reconstruction in 5 ranges) and seconds of the request thread's CPU, checked as each tree is made
FACAID_REQUEST_WORK = env_int("FACAID_REQUEST_WORK", 2_000_000)
FACAID_REQUEST_SECONDS = env_float("FACAID_REQUEST_SECONDS", 2.0)
# heavy API requests (rendering, variations, rectifying, downloads: webapp/facades/throttling.py) one process serves
# at once; gunicorn's 4 threads a worker (scripts/run) keep 2 for the gallery, job status and pages
FACAID_HEAVY_SLOTS = env_int("FACAID_HEAVY_SLOTS", 2, minimum=1)
# megabytes an account may store: its photos' files, its segmentations (versions and drafts, as JSON) and its
# procedures (current trees as JSON, versions compressed); a phone's photo is 2-8 MB, a real facade's tree 2-20 KB
FACAID_STORAGE_QUOTA_MB = env_int("FACAID_STORAGE_QUOTA_MB", 1000, minimum=1)

INSTALLED_APPS = [
    "django.contrib.admin",
    "django.contrib.auth",
    "django.contrib.contenttypes",
    "django.contrib.sessions",
    "django.contrib.messages",
    "django.contrib.staticfiles",
    "rest_framework",
    "rest_framework.authtoken",
    "drf_spectacular",
    "drf_spectacular_sidecar",  # Swagger UI's JS and CSS as static files, for the API docs page
    "axes",
    "webapp.accounts",
    "webapp.facades",
]

MIDDLEWARE = [
    "django.middleware.security.SecurityMiddleware",
    "webapp.middleware.ContentSecurityPolicyMiddleware",  # every response, the error answers below included
    "webapp.middleware.RequestSizeLimitMiddleware",  # before anything reads the body
    "webapp.middleware.UnreadBodyMiddleware",  # what was answered before the body was read: the rest read
    "whitenoise.middleware.WhiteNoiseMiddleware",
    "django.contrib.sessions.middleware.SessionMiddleware",
    "django.middleware.common.CommonMiddleware",
    "django.middleware.csrf.CsrfViewMiddleware",
    "django.contrib.auth.middleware.AuthenticationMiddleware",
    "django.contrib.messages.middleware.MessageMiddleware",
    "django.middleware.clickjacking.XFrameOptionsMiddleware",
    "axes.middleware.AxesMiddleware",  # turns a login lockout into the 429 page
    "webapp.middleware.BusyDatabaseMiddleware",
    "webapp.middleware.WorkBudgetMiddleware",  # the trees one request may read and make (docs/site.md#security)
    "webapp.middleware.ServiceErrorMiddleware",  # a service's error a page did not catch: the error page
    "webapp.middleware.HeavySlotsMiddleware",  # heavy API requests at once per process, the rest a 503
]

ROOT_URLCONF = "webapp.urls"
WSGI_APPLICATION = "webapp.wsgi.application"
TEMPLATES = [{
    "BACKEND": "django.template.backends.django.DjangoTemplates",
    "DIRS": [BASE_DIR / "webapp" / "templates"],
    "APP_DIRS": True,
    "OPTIONS": {"context_processors": [
        "django.template.context_processors.request",
        "django.contrib.auth.context_processors.auth",
        "django.contrib.messages.context_processors.messages",
    ]},
}]

DATABASES = {"default": dj_database_url.parse(
    env_str("DATABASE_URL", f"sqlite:///{VAR_DIR / 'facaid.sqlite3'}"), conn_max_age=60)}
if DATABASES["default"]["ENGINE"].endswith("sqlite3"):
    # the worker and the site write the same file. Write-ahead logging lets reads go on while another process
    # writes; writers wait for the lock (busy timeout) instead of failing at once, and a write that still finds
    # it taken is a 503 (webapp.middleware.BusyDatabaseMiddleware)
    DATABASES["default"]["OPTIONS"] = {
        "timeout": env_int("FACAID_SQLITE_TIMEOUT", 20), "transaction_mode": "IMMEDIATE",
        "init_command": "PRAGMA journal_mode=WAL; PRAGMA synchronous=NORMAL;"}
    # connections are kept for a minute, as with PostgreSQL (opening one per request, with its pragmas, cost the
    # site a fifth of its throughput under load: bench/bench_site.py)
    # tests use a file, so that a worker process can share the test database
    DATABASES["default"]["TEST"] = {"NAME": str(VAR_DIR / "test.sqlite3")}
DEFAULT_AUTO_FIELD = "django.db.models.BigAutoField"

AUTH_PASSWORD_VALIDATORS = [
    {"NAME": "django.contrib.auth.password_validation.UserAttributeSimilarityValidator"},
    {"NAME": "django.contrib.auth.password_validation.MinimumLengthValidator", "OPTIONS": {"min_length": 8}},
    {"NAME": "django.contrib.auth.password_validation.CommonPasswordValidator"},
    {"NAME": "django.contrib.auth.password_validation.NumericPasswordValidator"},
]
LOGIN_URL = "login"
AUTHENTICATION_BACKENDS = [
    "axes.backends.AxesStandaloneBackend",  # first: refuses a locked-out username or address before the password
    "django.contrib.auth.backends.ModelBackend",
]
# Login lockouts (django-axes, counted in the database): FACAID_LOGIN_FAILURE_LIMIT failed logins for one
# username, from any addresses, or from one address, for any usernames, lock that username or that address out
# for FACAID_LOGIN_COOLOFF_MINUTES after the last attempt (an attempt during a lockout starts the wait again),
# with a 429 page. It covers the login page, the admin's login and anything else that calls authenticate().
AXES_FAILURE_LIMIT = env_int("FACAID_LOGIN_FAILURE_LIMIT", 10)
AXES_COOLOFF_TIME = timedelta(minutes=env_int("FACAID_LOGIN_COOLOFF_MINUTES", 15))
AXES_LOCKOUT_PARAMETERS = ["username", "ip_address"]
AXES_LOCKOUT_CALLABLE = "webapp.accounts.views.lockout"
AXES_CLIENT_IP_CALLABLE = "webapp.accounts.views.client_ip"
LOGIN_REDIRECT_URL = "home"
LOGOUT_REDIRECT_URL = "home"

LANGUAGE_CODE = "en-us"
TIME_ZONE = "UTC"
USE_I18N = True
USE_TZ = True

STATIC_URL = "static/"
STATIC_ROOT = VAR_DIR / "static"
STATIC_ROOT.mkdir(parents=True, exist_ok=True)  # WhiteNoise warns about a missing one before collectstatic
WHITENOISE_AUTOREFRESH = env_bool("WHITENOISE_AUTOREFRESH", DEBUG)  # re-read changed files (development)
# the pages' ES modules (frontend/: editor/, procedure/, job/, common/) as static/app/...
STATICFILES_DIRS = [BASE_DIR / "webapp" / "static", ("app", BASE_DIR / "frontend")]
MEDIA_URL = "media/"
MEDIA_ROOT = Path(env_str("MEDIA_ROOT", str(VAR_DIR / "media")))

# uploads: the limits the site promises (checked in facades/uploads.py); Django's own caps sit above them
FACAID_MAX_UPLOAD_BYTES = env_int("FACAID_MAX_UPLOAD_BYTES", 20 * 1024 * 1024)
FACAID_MAX_PIXELS = env_int("FACAID_MAX_PIXELS", 40_000_000)
FACAID_MAX_RECTIFIED_PIXELS = env_int("FACAID_MAX_RECTIFIED_PIXELS", 16_000_000)  # a rectified photo is shrunk to this
# JSON and form bodies up to 4 MB: a segmentation of the most rectangles (20,000) is about 1.5 MB, a procedure of the
# most nodes about 1 MB; what a body may cost once parsed grows with it (bench/bench_render_memory.py)
DATA_UPLOAD_MAX_MEMORY_SIZE = 4 * 1024 * 1024
FILE_UPLOAD_MAX_MEMORY_SIZE = 2_621_440

REDIS_URL = env_str("REDIS_URL", "redis://127.0.0.1:6379/0")
FACAID_MAX_ACTIVE_JOBS = env_int("FACAID_MAX_ACTIVE_JOBS", 5)  # a user's jobs waiting or running at once
# The API's throttle counts live in each process's memory: no request depends on Redis being up, and a limit
# holds per gunicorn worker (scripts/run's 2 workers let a client up to twice the rate through). Pages served from
# memory (the gallery) have a cache of their own, so that many of them never push throttle counts out.
CACHES = {"default": {"BACKEND": "django.core.cache.backends.locmem.LocMemCache", "LOCATION": "facaid"},
          "pages": {"BACKEND": "django.core.cache.backends.locmem.LocMemCache", "LOCATION": "facaid-pages",
                    "OPTIONS": {"MAX_ENTRIES": 500}}}
FACAID_CHECKPOINT = env_str("FACAID_CHECKPOINT", str(BASE_DIR / "checkpoints" / "facaid-small"))

REST_FRAMEWORK = {
    "DEFAULT_AUTHENTICATION_CLASSES": [
        # a token first: its "Token" challenge makes a missing or wrong token a 401 (Basic is gone: a password
        # per request can't be throttled like the login page is)
        "rest_framework.authentication.TokenAuthentication",
        "rest_framework.authentication.SessionAuthentication",
    ],
    "DEFAULT_PERMISSION_CLASSES": ["rest_framework.permissions.IsAuthenticatedOrReadOnly"],
    # per client address (anonymous) and per account; counted in the default cache (see CACHES)
    "DEFAULT_THROTTLE_CLASSES": ["rest_framework.throttling.AnonRateThrottle",
                                 "rest_framework.throttling.UserRateThrottle"],
    "DEFAULT_THROTTLE_RATES": {"anon": env_rate("FACAID_API_ANON_RATE", "300/min"),
                               "user": env_rate("FACAID_API_USER_RATE", "1200/min"),
                               # rendering, variations, rectifying, downloads (webapp/facades/throttling.py)
                               "heavy": env_rate("FACAID_API_HEAVY_RATE", "240/min"),
                               "signup": env_rate("FACAID_SIGNUP_RATE", "10/hour")},  # accounts/views.signup
    "NUM_PROXIES": FACAID_PROXY_COUNT,
    # JSON with bounded nesting (a RecursionError would be a 500) and plain text, then forms and uploads
    "DEFAULT_PARSER_CLASSES": ["webapp.facades.jsonbody.JSONParser", "rest_framework.parsers.FormParser",
                               "rest_framework.parsers.MultiPartParser"],
    # JSON that cannot fail on text UTF-8 cannot write (an unpaired surrogate: a 500 before), then the browsable API
    "DEFAULT_RENDERER_CLASSES": ["webapp.facades.jsonbody.JSONRenderer",
                                 "rest_framework.renderers.BrowsableAPIRenderer"],
    "DEFAULT_SCHEMA_CLASS": "drf_spectacular.openapi.AutoSchema",
    "DEFAULT_PAGINATION_CLASS": "webapp.facades.paging.Pagination",
    # the services' errors (not found, not allowed, invalid input, ...) as their statuses, in the API's JSON
    "EXCEPTION_HANDLER": "webapp.facades.api.exception_handler.exception_handler",
    "PAGE_SIZE": 24,  # (webapp.facades.paging.Pagination: at most 100)
}
SPECTACULAR_SETTINGS = {
    "TITLE": "FaçAID API",
    "DESCRIPTION": "Photos, segmentations, reconstruction jobs and procedures of the FaçAID site.",
    "VERSION": "1",
    "SERVE_INCLUDE_SCHEMA": False,
    # two models have a field `kind` with different choices: name each set, or the schema gets KindF8fEnum
    "ENUM_NAME_OVERRIDES": {"VersionKindEnum": "webapp.facades.models.ProcedureVersion.Kind",
                            "JobKindEnum": "webapp.facades.models.Job.Kind"},
    # the docs page (/api/v1/docs) loads Swagger UI from our static files and asks no other site for anything: no
    # validator badge, which would send the schema's address to swagger.io
    "SWAGGER_UI_DIST": "SIDECAR",
    "SWAGGER_UI_FAVICON_HREF": "SIDECAR",
    "SWAGGER_UI_SETTINGS": {"deepLinking": True, "validatorUrl": None, "docExpansion": "list",
                            "defaultModelsExpandDepth": 0},
}

LOGGING = {
    "version": 1,
    "disable_existing_loggers": False,
    "handlers": {"console": {"class": "logging.StreamHandler"}},
    "root": {"handlers": ["console"], "level": env_str("LOG_LEVEL", "WARNING")},
}
