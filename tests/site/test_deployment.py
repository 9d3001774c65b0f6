"""The container setup, read without a Docker engine (none on the test machine): docker-compose.yml runs
PostgreSQL, Redis with an append-only file, the site under gunicorn and a GPU worker, each with a healthcheck, on
named volumes, configured by DATABASE_URL and REDIS_URL; the Dockerfile copies everything the settings and the
worker read; the set-up, CI and the image vendor three.js from npm at the lock file's version."""

from __future__ import annotations

import json
import re
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
    assert services["worker"]["command"][:3] == ["celery", "-A", "webapp.celery"]
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
        # plain http on port 8000 unless the operator puts a TLS proxy in front (docs/site.md, Security)
        assert env["FACAID_HTTPS"] == "${FACAID_HTTPS:-0}"
        assert {"FACAID_PROXY_SSL_HEADER", "FACAID_PROXY_COUNT"} <= set(env)
        for dep in ("postgres", "redis"):
            assert services[name]["depends_on"][dep]["condition"] == "service_healthy"
    used = {v.split(":")[0] for s in services.values() for v in s.get("volumes", [])}
    assert used <= set(c["volumes"]) and {"postgres", "redis", "media"} <= used


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
