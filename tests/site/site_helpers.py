"""Helpers of the site tests."""

from __future__ import annotations

import io
import os
import shutil
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path
from typing import TYPE_CHECKING

from PIL import Image
from rest_framework.test import APIClient

from facaid.editing.variation import vary
from facaid.formats.render import render_segmentation
from facaid.generator import generate
from facaid.grammar import Procedure as Tree
from facaid.grammar.procedure import GRAMMAR_VERSION

if TYPE_CHECKING:
    from webapp.facades.models import Procedure


def client_for(user=None) -> APIClient:
    client = APIClient()
    if user is not None:
        client.force_login(user)  # a session: both the pages and the API see the user
    return client


def image_bytes(fmt: str = "PNG", size=(64, 48), color=(120, 130, 140), **save) -> bytes:
    out = io.BytesIO()
    Image.new("RGB", size, color).save(out, fmt, **save)
    return out.getvalue()


def facade_png(seed: int = 3) -> tuple[bytes, dict]:
    """A 'photo' of a generated facade (its label map in the palette) and its segmentation JSON."""
    sample = generate(seed)
    out = io.BytesIO()
    render_segmentation(sample.segmentation).save(out, "PNG")
    return out.getvalue(), sample.segmentation.to_dict()


def photo_like(seed: int = 7):
    """A PNG photo of a generated facade seen in perspective on a street (`facaid.photo.photolike`) and its true corners
    (a (4, 2) array: TL, TR, BR, BL)."""
    import numpy as np

    from facaid.photo.photolike import facade_box, render_photo, warp

    g = generate(seed)
    facade = render_photo(g.segmentation, seed).crop(facade_box(g.segmentation))
    photo, corners = warp(facade, seed)
    out = io.BytesIO()
    photo.save(out, "PNG")
    return out.getvalue(), np.array(corners)


def upload(client, data: bytes, name: str = "photo.png", **fields):
    from django.core.files.uploadedfile import SimpleUploadedFile

    return client.post("/api/v1/photos/", {"image": SimpleUploadedFile(name, data), **fields}, format="multipart")


def wall(width, height) -> dict:
    """A procedure's JSON of a bare wall, ``width`` x ``height`` pixels."""
    return {"format": "facaid-procedure", "version": 1, "grammar": GRAMMAR_VERSION, "width": width,
            "height": height, "root": {"rule": "leaf", "label": "facade"}}


def stored_counts() -> tuple[int, ...]:
    """How many photos, segmentations, procedures and jobs are stored: what a refused request must leave as it was."""
    from webapp.facades.models import Job, Photo, Procedure, Segmentation

    return tuple(m.objects.count() for m in (Photo, Segmentation, Procedure, Job))


# --- a real Redis server and real worker processes ----------------------------------------------------------------

ROOT = Path(__file__).resolve().parents[2]


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Redis:
    def __init__(self, workdir: Path):
        self.port, self.workdir, self.proc = free_port(), workdir, None
        self.url = f"redis://127.0.0.1:{self.port}/0"

    def start(self) -> None:
        self.proc = subprocess.Popen(["redis-server", "--port", str(self.port), "--bind", "127.0.0.1",
                                      "--save", "", "--appendonly", "no", "--dir", str(self.workdir)],
                                     stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        deadline = time.time() + 10
        while time.time() < deadline:
            try:
                with socket.create_connection(("127.0.0.1", self.port), timeout=0.2) as s:
                    s.sendall(b"PING\r\n")
                    if s.recv(16).startswith(b"+PONG"):
                        return
            except OSError:
                time.sleep(0.05)
        raise RuntimeError("redis-server did not start")

    def stop(self) -> None:
        if self.proc:
            self.proc.kill()
            self.proc.wait()
            self.proc = None


def database_url() -> str:
    """The test database as a DATABASE_URL, for the processes a test starts (a worker)."""
    from django.db import connection

    d = connection.settings_dict
    if d["ENGINE"].endswith("sqlite3"):
        return f"sqlite:///{d['NAME']}"
    return f"postgres://{d['USER']}:{d['PASSWORD']}@{d['HOST'] or 'localhost'}:{d['PORT'] or 5432}/{d['NAME']}"


class Worker:
    def __init__(self, redis: Redis, log: Path):
        self.redis, self.log, self.proc = redis, log, None

    def start(self, **environ: str) -> None:
        """Start a worker on the test database; ``environ`` overrides its settings (the job timings are short)."""
        from django.conf import settings

        env = {**os.environ, "REDIS_URL": self.redis.url, "DATABASE_URL": database_url(),
               "MEDIA_ROOT": str(settings.MEDIA_ROOT),  # the test's: the worker keeps the pictures it renders there
               "FACAID_RECOVER_SECONDS": "1", "FACAID_JOB_STALE_SECONDS": "4", "FACAID_HEARTBEAT_SECONDS": "1",
               "FACAID_JOB_RESEND_SECONDS": "2", "PYTHONUNBUFFERED": "1", **environ}
        with open(self.log, "ab") as out:  # the worker keeps its own copy of the descriptor
            self.proc = subprocess.Popen(
                [sys.executable, "-m", "celery", "-A", "worker", "worker", "-Q", "gpu,default", "--pool",
                 "prefork", "--concurrency", "1", "--without-gossip", "--without-mingle", "-l", "info"],
                cwd=ROOT, env=env, stdout=out, stderr=subprocess.STDOUT, start_new_session=True)
        deadline = time.time() + 120
        while time.time() < deadline:
            if b"ready." in self.log.read_bytes():
                return
            if self.proc.poll() is not None:
                break
            time.sleep(0.2)
        raise RuntimeError("the worker did not start:\n" + self.log.read_text()[-3000:])

    def kill(self) -> None:
        if self.proc and self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGKILL)
            self.proc.wait()
        self.log.write_bytes(b"")  # the next start waits for its own "ready."




# --- the browser --------------------------------------------------------------------------------------------------

CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"  # Debian's; Playwright downloads no browser
CHROMIUM_ARGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync"]


def login(page, base: str, username: str, password: str) -> None:
    page.goto(f"{base}/accounts/login/")
    page.fill("#id_username", username)
    page.fill("#id_password", password)
    page.click("button[type=submit]")
    page.wait_for_url(f"{base}/")


def collect_errors(page, errors: list) -> list:
    """The page's uncaught errors and what its Content-Security-Policy refused (Chromium says so on the console: an
    inline script or style, a handler attribute, a load from elsewhere), into ``errors``."""
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.on("console", lambda m: errors.append(m.text) if "Content Security Policy" in m.text else None)
    return errors


def wait_for_function(page, expression: str, arg=None, *, timeout: float | None = None, polling=None) -> None:
    """`Page.wait_for_function` for pages under the site's Content-Security-Policy. Playwright's own compiles the
    expression in the page (``new Function``), which a policy without 'unsafe-eval' refuses; this one asks
    `Page.evaluate` until the expression holds, which DevTools runs outside the page's policy. Installed for
    every site test by conftest.py."""
    from playwright.sync_api import Error
    from playwright.sync_api import TimeoutError as PlaywrightTimeout

    deadline = time.monotonic() + (30_000 if timeout is None else timeout) / 1000
    pause = polling if isinstance(polling, int | float) else 50
    while True:
        try:
            if page.evaluate(expression, arg):
                return
        except Error as exc:  # a navigation under way: ask the next page, as Playwright's own does
            if "context was destroyed" not in str(exc) and "navigat" not in str(exc):
                raise
        if time.monotonic() > deadline:
            raise PlaywrightTimeout(f"Timeout {timeout}ms exceeded waiting for {expression!r}")
        page.wait_for_timeout(pause)  # (lets Playwright deliver the page's events meanwhile)


def offline_page(browser, base: str, viewport=(1280, 900)):
    """A page whose requests to anything but ``base`` are refused and listed in `page.elsewhere`; its uncaught
    errors and what its Content-Security-Policy refused collect in `page.errors`."""
    page = browser.new_context(viewport={"width": viewport[0], "height": viewport[1]}).new_page()
    page.elsewhere, page.errors = [], []

    def route(r):
        if r.request.url.startswith(base) or r.request.url.startswith("data:"):
            r.continue_()
        else:
            page.elsewhere.append(r.request.url)
            r.abort()

    page.route("**/*", route)
    collect_errors(page, page.errors)
    return page


def screenshot(target, name: str, tmp_path) -> str:
    """A picture of a page or of one element (a locator) as ``name``, in FACAID_SCREENSHOT_DIR when set (docs/img
    to update the docs' pictures), else in ``tmp_path``; its path."""
    path = os.path.join(os.environ.get("FACAID_SCREENSHOT_DIR") or str(tmp_path), name)
    target.screenshot(path=path)
    return path


# --- the procedure page and its versions ------------------------------------------------------------------------------

def open_as_alice(browser, live_server, proc: Procedure, viewport: dict, advanced: bool = True):
    """Alice's browser on the procedure's page (with its raw tree opened, unless not ``advanced``), and the list its
    script errors are gathered in."""
    page = browser.new_page(viewport=viewport)
    errors = collect_errors(page, [])  # script errors, and what the page's CSP refused
    login(page, live_server.url, "alice", "alice-password-1")
    page.goto(f"{live_server.url}/procedures/{proc.code}")
    if advanced:
        page.click("#advanced summary")
    return page, errors


def counted_repeats(node: dict) -> list[dict]:
    """The repeats of a procedure's JSON tree that have a count (not ``fill``), depth first, in the tree's order."""
    out = [node] if node["rule"] == "repeat" and node["count"] != "fill" else []
    for child in node.get("children", []):
        out += counted_repeats(child)
    return out


def faithful_procedure(alice, seg: dict, title: str = "Generated facade", **fields) -> Procedure:
    """Alice's procedure of the generated facade her photo shows (``seg``: its segmentation, the API's JSON), with
    the photo: its own true tree, at pixel accuracy 1 unless ``fields`` say otherwise."""
    from webapp.facades.models import Procedure, Segmentation

    segmentation = Segmentation.objects.get(code=seg["code"])
    fields.setdefault("accuracy", 1.0)
    return Procedure.objects.create(owner=alice, title=title, data=generate(3).procedure.to_dict(),
                                    segmentation=segmentation, photo=segmentation.photo, **fields)


def same_size_variant(data: dict, kind: str = "swap") -> dict:
    """A variation of the procedure's JSON tree ``data`` of the ``kind`` asked for, of the same size."""
    for v in vary(Tree.from_dict(data), 8, 0):
        if v.meta["variation"] == kind and (v.width, v.height) == (data["width"], data["height"]):
            return v.to_dict()
    raise AssertionError(f"no {kind} variation of the facade's size")


def procedure_url(proc, rest: str = "") -> str:
    """The API's address of a procedure, or of ``rest`` under it."""
    return f"/api/v1/procedures/{proc.code}/{rest}"


def version_history(client, proc) -> list[dict]:
    """The procedure's versions as ``client`` reads them, the newest first."""
    r = client.get(procedure_url(proc, "versions/"))
    assert r.status_code == 200, r.content
    return r.json()["results"]
