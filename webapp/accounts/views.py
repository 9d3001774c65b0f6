import math

from django.conf import settings
from django.contrib import messages
from django.contrib.auth import get_user_model, login
from django.contrib.auth.decorators import login_required
from django.db import transaction
from django.shortcuts import redirect, render, resolve_url
from django.utils import timezone
from django.utils.http import url_has_allowed_host_and_scheme
from django.views.decorators.cache import never_cache
from django.views.decorators.http import require_http_methods
from rest_framework.authtoken.models import Token
from rest_framework.throttling import AnonRateThrottle, BaseThrottle

from webapp.accounts.forms import SignupForm


class SignupThrottle(AnonRateThrottle):
    """New accounts per address (FACAID_SIGNUP_RATE): each account brings fresh API and login allowances."""

    scope = "signup"


def _next(request) -> str:
    """Where the page was asked to go after signing up (``next``), if it is a path of this site; else home."""
    target = request.POST.get("next") or request.GET.get("next") or ""
    safe = url_has_allowed_host_and_scheme(target, allowed_hosts={request.get_host()},
                                           require_https=request.is_secure())
    return target if target and safe else resolve_url("home")


def signup(request):
    if request.user.is_authenticated:
        return redirect(_next(request))
    form = SignupForm(request.POST or None)
    if request.method == "POST":
        throttle = SignupThrottle()
        if not throttle.allow_request(request, None):
            wait = math.ceil(throttle.wait() or 60)
            form.add_error(None, f"Too many new accounts from your address; try again in {math.ceil(wait / 60)} "
                                 "minutes.")
            response = render(request, "registration/signup.html", {"form": form, "next": _next(request)},
                              status=429)
            response["Retry-After"] = str(wait)
            return response
    if request.method == "POST" and form.is_valid():
        user = form.save()
        login(request, user, backend="django.contrib.auth.backends.ModelBackend")
        return redirect(_next(request))
    return render(request, "registration/signup.html", {"form": form, "next": _next(request)})


@never_cache  # the page shows the secret
@login_required
@require_http_methods(["GET", "POST"])
def api_token(request):
    """The user's API token (Authorization: Token <key>): see it, create or regenerate it, revoke it."""
    if request.method == "POST":
        with transaction.atomic():  # one change at a time per user (a double click is two POSTs)
            get_user_model().objects.select_for_update().filter(pk=request.user.pk).first()
            Token.objects.filter(user=request.user).delete()  # a new token replaces the old one at once
            if request.POST.get("action") != "revoke":
                Token.objects.create(user=request.user)
        if request.POST.get("action") == "revoke":
            messages.success(request, "Your API token is revoked: requests with it are refused now.")
        else:
            messages.success(request, "A new API token is made; the previous one, if any, no longer works.")
        return redirect("api-token")
    token = Token.objects.filter(user=request.user).first()
    return render(request, "accounts/api_token.html", {"token": token})


def client_ip(request) -> str | None:
    """The client's address for the login lockouts: the one the API's throttles count (REMOTE_ADDR, or with
    FACAID_PROXY_COUNT proxies in front, the address the outermost of them put in X-Forwarded-For)."""
    return BaseThrottle().get_ident(request)


def lockout(request, original_response=None, credentials=None):
    """django-axes' answer to a login while the username or the address is locked out: 429 with a page that says
    why and when to try again (an attempt during the lockout starts the wait again)."""
    wait = settings.AXES_COOLOFF_TIME
    minutes = math.ceil(wait.total_seconds() / 60)
    response = render(request, "registration/lockout.html", {
        "failure_limit": settings.AXES_FAILURE_LIMIT, "minutes": minutes,
        "until": timezone.now() + wait}, status=429)
    response["Retry-After"] = str(int(wait.total_seconds()))
    return response
