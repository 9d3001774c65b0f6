import math

from django.conf import settings
from django.contrib import messages
from django.contrib.auth import login
from django.contrib.auth.decorators import login_required
from django.shortcuts import redirect, render
from django.utils import timezone
from django.views.decorators.http import require_http_methods
from rest_framework.authtoken.models import Token
from rest_framework.throttling import BaseThrottle

from webapp.accounts.forms import SignupForm


def signup(request):
    if request.user.is_authenticated:
        return redirect("home")
    form = SignupForm(request.POST or None)
    if request.method == "POST" and form.is_valid():
        user = form.save()
        login(request, user, backend="django.contrib.auth.backends.ModelBackend")
        return redirect("home")
    return render(request, "registration/signup.html", {"form": form})


@login_required
@require_http_methods(["GET", "POST"])
def api_token(request):
    """The user's API token (Authorization: Token <key>): see it, create or regenerate it, revoke it."""
    if request.method == "POST":
        Token.objects.filter(user=request.user).delete()  # a new token replaces the old one at once
        if request.POST.get("action") == "revoke":
            messages.success(request, "Your API token is revoked: requests with it are refused now.")
        else:
            Token.objects.create(user=request.user)
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
