"""The site under gunicorn as `scripts/run` serves it (gthread workers), read over a raw socket: an answer given
before the view read the request's body (a 503 of the heavy slots, a 401) leaves the keep-alive connection able to
carry the next request. gunicorn skips at most 64 KB of an unread body and past that closes a connection it
announced as kept alive; the probe of issue 66 saw a 503 before a 137 KB body break the next request."""

from __future__ import annotations

import json
import os
import secrets
import socket
import subprocess
import sys
import time

import pytest
from site_helpers import ROOT, database_url, free_port

from facaid.grammar.procedure import GRAMMAR_VERSION
from webapp.facades.models import Procedure

pytestmark = pytest.mark.django_db(transaction=True)  # the server reads the test database from another process

LARGE = json.dumps({"pad": "x" * 137_000}).encode()  # the probe's 137 KB


@pytest.fixture
def gunicorn(tmp_path):
    """One gunicorn worker of 4 threads with one heavy slot, on the test database; its port."""
    port = free_port()
    env = {**os.environ, "DATABASE_URL": database_url(), "SECRET_KEY": secrets.token_urlsafe(50), "FACAID_HTTPS": "0",
           "MEDIA_ROOT": str(tmp_path / "media"), "FACAID_VAR": str(tmp_path), "FACAID_HEAVY_SLOTS": "1",
           "FACAID_API_ANON_RATE": "none", "FACAID_API_HEAVY_RATE": "none", "DEBUG": "0"}
    with open(tmp_path / "gunicorn.log", "wb") as log:  # the server keeps its own copy of the descriptor
        server = subprocess.Popen([sys.executable, "-m", "gunicorn", "webapp.wsgi", "--bind", f"127.0.0.1:{port}",
                                   "--workers", "1", "--threads", "4", "--no-control-socket"], cwd=ROOT, env=env,
                                  stdout=log, stderr=subprocess.STDOUT)
    deadline = time.time() + 60
    while time.time() < deadline:
        try:
            socket.create_connection(("127.0.0.1", port), timeout=0.2).close()
            break
        except OSError:
            assert server.poll() is None, (tmp_path / "gunicorn.log").read_text()[-3000:]
            time.sleep(0.1)
    yield port
    server.terminate()
    server.wait()


def request(method: str, path: str, body: bytes = b"") -> bytes:
    head = f"{method} {path} HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
    return head.encode() + (b"Content-Length: %d\r\n" % len(body) if body else b"") + b"\r\n" + body


def response(f) -> tuple[int, dict, bytes]:
    """One HTTP/1.1 response read from the socket's file: (status, headers, body); status 0 if the connection was
    closed."""
    status = f.readline()
    if not status:
        return 0, {}, b""
    headers = {}
    while (line := f.readline()) not in (b"\r\n", b""):
        name, value = line.decode("latin-1").split(":", 1)
        headers[name.strip().lower()] = value.strip()
    return int(status.split()[1]), headers, f.read(int(headers.get("content-length", 0)))


def test_an_answer_before_the_body_is_read_keeps_the_connection_usable(gunicorn):
    owner = Procedure._meta.get_field("owner").related_model.objects.create_user("alice", "a@example.com", "pw-1-abcd")
    Procedure.objects.create(owner=owner, title="shown", visibility="public",
                             data={"format": "facaid-procedure", "version": 1, "grammar": GRAMMAR_VERSION,
                                   "width": 10, "height": 10, "root": {"rule": "leaf", "label": "facade"}})
    # a render whose body never ends holds the one heavy slot: every other render is a 503 at once
    holder = socket.create_connection(("127.0.0.1", gunicorn), timeout=30)
    holder.sendall(request("POST", "/api/v1/render", b"{" + b" " * 99)[:-50])
    time.sleep(0.5)
    try:
        for first, expected in [(request("POST", "/api/v1/render", LARGE), 503)] * 3 + [
                (request("POST", "/api/v1/jobs/", LARGE), 401)]:  # anonymous: refused before it is read too
            with socket.create_connection(("127.0.0.1", gunicorn), timeout=30) as s:
                f = s.makefile("rb")
                s.sendall(first)
                status, headers, body = response(f)
                assert status == expected and headers.get("connection") != "close", (status, headers, body[:200])
                if expected == 503:
                    assert headers["x-facaid-busy"] == "slots"
                s.sendall(request("GET", "/api/v1/gallery/"))  # the next request on the same connection
                status, _, body = response(f)
                assert status == 200 and [p["title"] for p in json.loads(body)["results"]] == ["shown"], body[:200]
    finally:
        holder.close()
