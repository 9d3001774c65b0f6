"""The container setup, read without a Docker engine (none on the test machine): docker-compose.yml runs
PostgreSQL, Redis with an append-only file, the site under gunicorn and a GPU worker, each with a healthcheck, on
named volumes, configured by DATABASE_URL and REDIS_URL; the Dockerfile copies everything the settings and the
worker read; the set-up, CI and the image vendor three.js from npm at the lock file's version."""

from __future__ import annotations

import json
import os
import re
import secrets
import subprocess
import sys
from pathlib import Path

import yaml

from webapp import settings

ROOT = Path(__file__).resolve().parents[2]


def compose() -> dict:
    return yaml.safe_load((ROOT / "docker-compose.yml").read_text())


def test_compose_services_healthchecks_volumes_and_gpu():
    c = compose()
    services = c["services"]
    assert set(services) == {"postgres", "redis", "web", "worker"}
    for name, service in services.items():
        assert service["healthcheck"]["test"], name
    assert "--appendonly" in services["redis"]["command"]
    assert "'X-Forwarded-Proto': 'https'" in services["web"]["healthcheck"]["test"][-1]  # passes https-only too
    assert "gunicorn webapp.wsgi" in services["web"]["command"]
    assert services["worker"]["command"][:3] == ["celery", "-A", "worker"]
    assert "gpu" in services["worker"]["command"][services["worker"]["command"].index("-Q") + 1].split(",")
    devices = services["worker"]["deploy"]["resources"]["reservations"]["devices"]
    assert devices[0]["capabilities"] == ["gpu"] and devices[0]["driver"] == "nvidia"
    for name in ("web", "worker"):
        env = services[name]["environment"]
        assert env["DATABASE_URL"].startswith("postgres://") and "@postgres:5432/" in env["DATABASE_URL"]
        assert env["REDIS_URL"] == "redis://redis:6379/0"
        # the settings refuse to start without a key when DEBUG is off; compose refuses before that
        assert env["SECRET_KEY"].startswith("${SECRET_KEY:?") and "DEBUG" not in env
        assert "FACAID_REQUIRE_SECRET" not in env  # gone: a key is always required in production
        # https-only behind a TLS proxy on the host unless told otherwise (docs/site.md, Security)
        assert env["FACAID_HTTPS"] == "${FACAID_HTTPS:-1}"
        assert env["FACAID_PROXY_SSL_HEADER"] == "${FACAID_PROXY_SSL_HEADER:-X-Forwarded-Proto}"
        assert env["FACAID_PROXY_COUNT"] == "${FACAID_PROXY_COUNT:-1}"
        for dep in ("postgres", "redis"):
            assert services[name]["depends_on"][dep]["condition"] == "service_healthy"
    # the proxy's headers are trusted, so only this host reaches the port (plain http too: FACAID_HTTPS=0)
    assert services["web"]["ports"] == ["127.0.0.1:8000:8000"]
    assert all("ports" not in s for name, s in services.items() if name != "web")
    used = {v.split(":")[0] for s in services.values() for v in s.get("volumes", [])}
    assert used <= set(c["volumes"]) and {"postgres", "redis", "media"} <= used


def compose_environment(**given: str) -> dict[str, str]:
    """The site's environment in docker-compose.yml as compose would resolve it, ``given`` set in the shell."""
    def value(match: re.Match) -> str:
        name, how, default = match.groups()
        return given.get(name) or (default if how == ":-" else "")

    spec = compose()["services"]["web"]["environment"]
    return {k: re.sub(r"\$\{(\w+)(:-|:\?)([^}]*)\}", value, str(v)) for k, v in spec.items()}


def deploy_check(tmp_path, **given: str) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("SECRET_KEY", "DEBUG", "ALLOWED_HOSTS", "FACAID_",
                                                                     "CSRF_"))}
    env.update(compose_environment(SECRET_KEY=secrets.token_urlsafe(50), **given), FACAID_VAR=str(tmp_path))
    return subprocess.run([sys.executable, "manage.py", "check", "--deploy", "--fail-level", "WARNING"], cwd=ROOT,
                          env=env, capture_output=True, text=True, timeout=120)


def test_the_compose_environment_passes_the_deployment_checks(tmp_path):
    """As shipped, `check --deploy` has nothing to say; with FACAID_HTTPS=0 (this host only) it names what plain http
    gives up: HSTS, the redirect, secure session and CSRF cookies (W004, W008, W012, W016)."""
    r = deploy_check(tmp_path)
    assert r.returncode == 0 and "no issues" in r.stdout, r.stdout + r.stderr
    r = deploy_check(tmp_path, FACAID_HTTPS="0")
    assert r.returncode != 0 and all(f"security.{w}" in r.stderr + r.stdout
                                          for w in ("W004", "W008", "W012", "W016")), r.stdout + r.stderr


def test_dockerfile_copies_what_the_site_and_worker_read():
    text = (ROOT / "Dockerfile").read_text()
    copied = set(re.findall(r"^COPY (\S+)", text, flags=re.M))
    static_dirs = [d[1] if isinstance(d, tuple) else d for d in settings.STATICFILES_DIRS]
    needed = {Path(d).relative_to(settings.BASE_DIR).parts[0] for d in static_dirs}
    needed |= {"facaid", "webapp", "worker", "checkpoints", "manage.py", "pyproject.toml"}
    assert needed <= copied, f"the Dockerfile does not copy {sorted(needed - copied)}"
    assert 'torch==2.13.0' in text
    ignored = (ROOT / ".dockerignore").read_text().split()
    assert not any(n in ignored for n in needed)


def test_the_set_up_ci_and_the_image_vendor_three_js_at_the_locked_version():
    pinned = json.loads((ROOT / "package.json").read_text())["dependencies"]["three"]
    locked = json.loads((ROOT / "package-lock.json").read_text())["packages"]["node_modules/three"]
    assert re.fullmatch(r"\d+\.\d+\.\d+", pinned) and locked["version"] == pinned  # exact, never a range
    assert locked["integrity"].startswith("sha512-")
    assert "bash scripts/vendor-js" in (ROOT / "scripts" / "setup").read_text()
    assert "need+=(npm)" in (ROOT / ".ci" / "run").read_text()
    docker = (ROOT / "Dockerfile").read_text()
    assert re.search(r"^FROM node:\S+ AS vendor-js$", docker, flags=re.M) and "RUN bash scripts/vendor-js" in docker
    assert "COPY --from=vendor-js /app/webapp/static/vendor webapp/static/vendor" in docker
    # made, never committed: git and the image's build context leave the copies out
    assert {"/node_modules/", "/webapp/static/vendor/"} <= set((ROOT / ".gitignore").read_text().split())
    assert {"node_modules", "webapp/static/vendor"} <= set((ROOT / ".dockerignore").read_text().split())
