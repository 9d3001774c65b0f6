"""Production defaults: with DEBUG off the site refuses to start without a SECRET_KEY of its own, is https-only
unless FACAID_HTTPS=0, and passes Django's deployment checks; scripts/run keeps a random key in var/."""

from __future__ import annotations

import os
import runpy
import secrets
import stat
import subprocess
import sys
from pathlib import Path

import pytest
from django.core.exceptions import ImproperlyConfigured

from webapp.env import EnvError

ROOT = Path(__file__).resolve().parents[2]
SETTINGS = ROOT / "webapp" / "settings.py"
# what tests/conftest.py sets for the suite, and what a production environment would not have
OURS = ("SECRET_KEY", "DEBUG", "ALLOWED_HOSTS", "FACAID_")


def bare_env(tmp_path: Path, **values: str) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if not k.startswith(OURS)}
    return {**env, "FACAID_VAR": str(tmp_path), "DJANGO_SETTINGS_MODULE": "webapp.settings", **values}


def load_settings(monkeypatch, tmp_path: Path, **values: str) -> dict:
    """webapp/settings.py run afresh in this process under exactly these variables."""
    for name in list(os.environ):
        if name.startswith(OURS):
            monkeypatch.delenv(name)
    monkeypatch.setenv("FACAID_VAR", str(tmp_path))
    for name, value in values.items():
        monkeypatch.setenv(name, value)
    return runpy.run_path(str(SETTINGS))


def production_key() -> str:
    return secrets.token_urlsafe(50)


def test_deploy_check_passes_in_production_mode(tmp_path):
    env = bare_env(tmp_path, DEBUG="0", SECRET_KEY=production_key(), ALLOWED_HOSTS="facade.example")
    r = subprocess.run([sys.executable, "manage.py", "check", "--deploy", "--fail-level", "WARNING"], cwd=ROOT,
                       env=env, capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "no issues" in r.stdout


def test_without_a_secret_key_debug_off_refuses_to_start(tmp_path):
    env = bare_env(tmp_path, DEBUG="0")
    r = subprocess.run([sys.executable, "-c", "from django.conf import settings; settings.SECRET_KEY"], cwd=ROOT,
                       env=env, capture_output=True, text=True, timeout=60)
    assert r.returncode != 0
    assert "ImproperlyConfigured: SECRET_KEY is not set" in r.stderr
    assert "export SECRET_KEY=" in r.stderr and "var/secret_key" in r.stderr  # it says how


def test_the_development_key_is_refused_too_and_allowed_under_debug(monkeypatch, tmp_path):
    with pytest.raises(ImproperlyConfigured, match="SECRET_KEY is not set"):
        load_settings(monkeypatch, tmp_path, DEBUG="0", SECRET_KEY="facaid-local-development-key-not-for-production")
    with pytest.raises(ImproperlyConfigured, match="SECRET_KEY is not set"):
        load_settings(monkeypatch, tmp_path)  # DEBUG is off by default
    s = load_settings(monkeypatch, tmp_path, DEBUG="1")
    assert s["SECRET_KEY"] == s["DEVELOPMENT_SECRET_KEY"]


def test_production_is_https_only_by_default(monkeypatch, tmp_path):
    s = load_settings(monkeypatch, tmp_path, DEBUG="0", SECRET_KEY=production_key())
    assert s["SESSION_COOKIE_SECURE"] and s["CSRF_COOKIE_SECURE"] and s["SECURE_SSL_REDIRECT"]
    assert s["SECURE_HSTS_SECONDS"] >= 365 * 24 * 3600
    assert s["SECURE_HSTS_INCLUDE_SUBDOMAINS"] and s["SECURE_HSTS_PRELOAD"]
    assert s["SECURE_CONTENT_TYPE_NOSNIFF"] and s["X_FRAME_OPTIONS"] == "DENY"
    assert s["SECURE_REFERRER_POLICY"] == "same-origin"
    assert "SECURE_PROXY_SSL_HEADER" not in s  # no header is trusted unless asked for
    assert s["REST_FRAMEWORK"]["NUM_PROXIES"] == 0  # a client's own X-Forwarded-For is not its address


def test_plain_http_with_facaid_https_0_or_debug(monkeypatch, tmp_path):
    for values in ({"DEBUG": "0", "SECRET_KEY": production_key(), "FACAID_HTTPS": "0"}, {"DEBUG": "1"},
                   {"DEBUG": "1", "FACAID_HTTPS": "1"}):
        s = load_settings(monkeypatch, tmp_path, **values)
        assert not (s["SESSION_COOKIE_SECURE"] or s["CSRF_COOKIE_SECURE"] or s["SECURE_SSL_REDIRECT"]), values
        assert s["SECURE_HSTS_SECONDS"] == 0, values


def test_proxy_settings_hsts_and_throttle_rates_come_from_the_environment(monkeypatch, tmp_path):
    s = load_settings(monkeypatch, tmp_path, DEBUG="0", SECRET_KEY=production_key(),
                      FACAID_PROXY_SSL_HEADER="X-Forwarded-Proto", FACAID_PROXY_COUNT="1",
                      FACAID_HSTS_SECONDS="3600", FACAID_HSTS_INCLUDE_SUBDOMAINS="0", FACAID_HSTS_PRELOAD="0",
                      FACAID_API_ANON_RATE="60/min", FACAID_API_USER_RATE="none", FACAID_API_HEAVY_RATE="30/min",
                      FACAID_SIGNUP_RATE="2/day")
    assert s["SECURE_PROXY_SSL_HEADER"] == ("HTTP_X_FORWARDED_PROTO", "https")
    assert s["REST_FRAMEWORK"]["NUM_PROXIES"] == 1
    assert s["SECURE_HSTS_SECONDS"] == 3600
    assert not s["SECURE_HSTS_INCLUDE_SUBDOMAINS"] and not s["SECURE_HSTS_PRELOAD"]
    assert s["REST_FRAMEWORK"]["DEFAULT_THROTTLE_RATES"] == {"anon": "60/min", "user": None, "heavy": "30/min",
                                                              "signup": "2/day"}
    defaults = load_settings(monkeypatch, tmp_path, DEBUG="1")
    assert defaults["REST_FRAMEWORK"]["DEFAULT_THROTTLE_RATES"] == {"anon": "300/min", "user": "1200/min",
                                                                     "heavy": "240/min", "signup": "10/hour"}
    assert defaults["AXES_FAILURE_LIMIT"] == 10 and defaults["AXES_COOLOFF_TIME"].total_seconds() == 15 * 60
    with pytest.raises(EnvError, match="FACAID_API_ANON_RATE must be a rate like 120/min"):
        load_settings(monkeypatch, tmp_path, DEBUG="1", FACAID_API_ANON_RATE="fast")


def test_https_only_requests(settings, client):
    """What the settings do to a request: http is redirected, https gets HSTS and secure cookies."""
    settings.SECURE_SSL_REDIRECT = True
    settings.SECURE_HSTS_SECONDS = 3600
    settings.CSRF_COOKIE_SECURE = True
    r = client.get("/accounts/login/")
    assert r.status_code == 301 and r["Location"] == "https://testserver/accounts/login/"
    r = client.get("/accounts/login/", secure=True)
    assert r.status_code == 200
    assert r["Strict-Transport-Security"].startswith("max-age=3600")
    assert r["X-Frame-Options"] == "DENY" and r["X-Content-Type-Options"] == "nosniff"
    assert r.cookies["csrftoken"]["secure"] and r.cookies["csrftoken"]["httponly"]


def test_secret_key_script_makes_one_private_key_and_keeps_it(tmp_path):
    env = {**os.environ, "FACAID_VAR": str(tmp_path / "var")}
    first = subprocess.run(["bash", "scripts/secret-key"], cwd=ROOT, env=env, capture_output=True, text=True,
                           check=True).stdout.strip()
    key_file = tmp_path / "var" / "secret_key"
    assert stat.S_IMODE(key_file.stat().st_mode) == 0o600
    assert len(first) >= 50 and len(set(first)) >= 20 and first.isalnum()
    again = subprocess.run(["bash", "scripts/secret-key"], cwd=ROOT, env=env, capture_output=True, text=True,
                           check=True).stdout.strip()
    assert again == first == key_file.read_text().strip()


def test_run_script_exports_the_kept_key_unless_one_is_set_and_serves_plain_http():
    text = (ROOT / "scripts" / "run").read_text()
    assert "SECRET_KEY=${SECRET_KEY:-$(bash scripts/secret-key)}" in text and "export SECRET_KEY" in text
    assert "export FACAID_HTTPS=${FACAID_HTTPS:-0}" in text
    # ... before anything loads the settings
    first_use = min(text.index(".venv/bin/python manage.py"), text.index(".venv/bin/python -m worker"),
                    text.index(".venv/bin/celery"),
                    text.index(".venv/bin/gunicorn"))
    assert text.index("export SECRET_KEY") < first_use and text.index("export FACAID_HTTPS") < first_use


def test_run_script_gives_each_server_its_own_control_socket_and_recycles_workers():
    """Two local servers (two PORTs) each keep their gunicorn control socket under var/: gunicorn's default, one
    path in the home folder, let stopping one remove the other's (issue 56)."""
    text = (ROOT / "scripts" / "run").read_text()
    line = text[text.index(".venv/bin/gunicorn"):].split("&")[0]
    assert '--control-socket "$VAR/gunicorn-$PORT.ctl"' in line and "--max-requests 1000" in line
    assert 'VAR=${FACAID_VAR:-var}' in text and '>"$VAR/worker.log"' in text  # the data folder the site uses
    assert "--max-requests-jitter" in line
