"""The API fuzzed from its own OpenAPI schema with schemathesis: every operation, anonymous and logged in, on
generated inputs and on the real objects of a small world (so that path parameters reach the views, not only the
404). No answer is a 5xx, and after a 4xx every row of the database is what it was before, every column.

Schemathesis draws text that UTF-8 can write; the strings of its cases are made awkward as a hostile client would:
lone surrogates (``"\\ud800"``, which JSON can write), NUL, U+FFFF and U+FFFE, and strings of 100,000 characters.

The cases are drawn by Hypothesis under the suite's 'repeatable' profile (the same cases each run);
HYPOTHESIS_PROFILE=explore and FACAID_FUZZ_EXAMPLES=N draw new and more."""

from __future__ import annotations

import json
import os
from contextlib import contextmanager

import pytest
import schemathesis
from django.core.wsgi import get_wsgi_application
from hypothesis import HealthCheck, settings
from hypothesis import strategies as st
from site_helpers import facade_png, upload

from facaid.generator import generate
from webapp.facades.downloads import DOWNLOADS

EXAMPLES = int(os.environ.get("FACAID_FUZZ_EXAMPLES", "15"))
WHO = ("anonymous", "alice", "alice", "bob")  # alice owns the world's objects (drawn half the time); bob does not

schema = schemathesis.openapi.from_wsgi("/api/v1/schema?format=json", get_wsgi_application())

# what a hostile client puts in a string; surrogates only in JSON (a URL or a form cannot carry them: their bytes are
# invalid UTF-8, which Django reads as U+FFFD)
AWKWARD = ("\x00", "a\x00b", "\uffff", "\ufffe", "x" * 100_000, "\u0301" * 1000)
SURROGATES = ("\ud800", "\udfff", "a\ud800b", "\udc00\ud800", "\ud83c")


def awkward(value, strings: tuple[str, ...]) -> st.SearchStrategy:
    """``value`` with some of its strings (and, in objects, an extra key) awkward: replaced, or prefixed or
    suffixed by one of ``strings``."""
    if isinstance(value, str):
        return st.one_of(st.just(value), st.sampled_from(strings).flatmap(
            lambda bad: st.sampled_from((bad, value + bad, bad + value))))
    if isinstance(value, list):
        return st.tuples(*(awkward(v, strings) for v in value)).map(list)
    if isinstance(value, dict):
        keys = list(value)
        extra = st.one_of(st.just({}), st.sampled_from(strings).map(lambda bad: {bad: bad}))
        return st.tuples(st.tuples(*(awkward(value[k], strings) for k in keys)), extra).map(
            lambda drawn: {**dict(zip(keys, drawn[0], strict=True)), **drawn[1]})
    return st.just(value)


def rows() -> dict[str, list[tuple]]:
    """Every row of the site's tables, all columns: the world is a few rows, so an edit shows as well as an
    insert."""
    from django.apps import apps

    return {m._meta.label: list(m.objects.order_by("pk").values_list()) for m in apps.get_models()
            if m._meta.app_label in ("facades", "auth", "authtoken")}


@contextmanager
def in_process():
    """Requests go through the real WSGI handler in this thread, inside the test's transaction: keep the
    handler from closing the connection at each request's start and end (as Django's test client does)."""
    from django.core import signals
    from django.db import close_old_connections

    for signal in (signals.request_started, signals.request_finished):
        signal.disconnect(close_old_connections)
    try:
        yield
    finally:
        for signal in (signals.request_started, signals.request_finished):
            signal.connect(close_old_connections)


@pytest.fixture
def world(django_user_model):
    """alice's private photo with a segmentation, her public procedure made from it, a job, bob's private
    procedure; a session and a CSRF token for each user."""
    from django.test import Client

    from webapp.facades.models import Job, Photo, Procedure, Segmentation

    alice = django_user_model.objects.create_user("alice", "a@example.com", "alice-password-1")
    bob = django_user_model.objects.create_user("bob", "b@example.com", "bob-password-1")
    sessions = {}
    for user in (alice, bob):
        client = Client()
        client.force_login(user)
        client.get("/")  # sets the CSRF cookie
        sessions[user.username] = {"sessionid": client.cookies["sessionid"].value,
                                   "csrftoken": client.cookies["csrftoken"].value}
        if user is alice:
            from rest_framework.test import APIClient

            api = APIClient()
            api.force_login(alice)
            data, seg = facade_png(seed=3)
            photo = Photo.objects.get(code=upload(api, data, title="fuzz").json()["code"])
            segmentation = Segmentation.objects.create(photo=photo, version=1, data=seg, rect_count=len(seg["rects"]))
    public = Procedure.objects.create(owner=alice, title="public", data=generate(3).procedure.to_dict(),
                                      photo=photo, segmentation=segmentation, visibility="public")
    public.data = generate(5).procedure.to_dict()
    public.save()  # a version 2
    private = Procedure.objects.create(owner=bob, title="private", data=generate(4).procedure.to_dict())
    job = Job.objects.create(owner=alice, segmentation=segmentation)
    codes = {"photos": [str(photo.code)], "segmentations": [str(segmentation.code)], "jobs": [str(job.code)],
             "procedures": [str(public.code), str(private.code)]}
    return {"sessions": sessions, "codes": codes}


def real_parameters(case, world, pick: int) -> None:
    """Point the case's path parameters at the world's objects of the right kind."""
    kind = case.path.split("/")[3]  # /api/v1/<kind>/{code}/...
    params = case.path_parameters or {}
    if "code" in params and kind in world["codes"]:
        choices = world["codes"][kind]
        params["code"] = choices[pick % len(choices)]
    if "name" in params:
        params["name"] = list(DOWNLOADS)[pick % len(DOWNLOADS)]
    if "number" in params:  # a procedure's version: each has version 1 (the public one a second)
        params["number"] = str(1 + pick % 3)
    case.path_parameters = params


@schema.parametrize()
@schema.given(who=st.sampled_from(WHO), real=st.sampled_from((True, True, True, False)), pick=st.integers(0, 100),
              text=st.data())
@settings(max_examples=EXAMPLES, deadline=None, suppress_health_check=list(HealthCheck))
@pytest.mark.django_db
def test_no_5xx_and_nothing_stored_by_a_4xx(case, who, real, pick, text, world):
    if real:
        real_parameters(case, world, pick)
    body = {}
    if case.query:
        case.query = text.draw(awkward(case.query, AWKWARD), label="query")
    if case.media_type == "application/json" and isinstance(case.body, dict | list | str):
        # sent as written, escapes and all: schemathesis checks a body against its schema before sending it, and
        # its validator cannot read a lone surrogate
        body["data"] = json.dumps(text.draw(awkward(case.body, AWKWARD + SURROGATES), label="body")).encode()
    elif isinstance(case.body, dict):
        case.body = text.draw(awkward(case.body, AWKWARD), label="form")
    headers, cookies = {}, {}
    if who != "anonymous":
        session = world["sessions"][who]
        cookies = dict(session)
        headers["X-CSRFToken"] = session["csrftoken"]
    before = rows()
    with in_process():
        response = case.call(headers=headers, cookies=cookies, **body)
    assert response.status_code < 500, (who, case.method, case.formatted_path, response.text[:500])
    if 400 <= response.status_code < 500:
        assert rows() == before, (who, case.method, case.formatted_path, response.status_code)


def _resolve(node: dict, components: dict) -> dict:
    while "$ref" in node:
        node = components[node["$ref"].split("/")[-1]]
    return node


def _fields(node: dict, components: dict, types: tuple[str, ...], bad, path=()):
    """Each field of a request body's schema of one of ``types``, as (its path, a body holding ``bad`` there and
    nothing else: the least nesting that reaches it)."""
    node = _resolve(node, components)
    if node.get("type") in types:
        yield path, bad
    for key, sub in node.get("properties", {}).items():
        if not sub.get("readOnly"):
            yield from ((p, {key: body}) for p, body in _fields(sub, components, types, bad, (*path, key)))
    if isinstance(node.get("additionalProperties"), dict):
        yield from ((p, {"floors": body}) for p, body in _fields(node["additionalProperties"], components, types,
                                                                  bad, (*path, "*")))
    if "items" in node:
        yield from ((p, [body]) for p, body in _fields(node["items"], components, types, bad, (*path, "[]")))
    for alternative in node.get("allOf", []) + node.get("oneOf", []) + node.get("anyOf", []):
        yield from _fields(alternative, components, types, bad, path)


def _json_bodies(client, world):
    """(method, path template, path, the JSON body's schema, the schema's components) of every operation."""
    spec = client.get("/api/v1/schema?format=json").json()
    for template, operations in spec["paths"].items():
        path = template.replace("{code}", world["codes"]["procedures"][0] if "/procedures/" in template
                                else world["codes"]["photos"][0])
        for method, operation in operations.items():
            body = operation.get("requestBody", {}).get("content", {}).get("application/json")
            if body is not None:
                yield method, template, path, body["schema"], spec["components"]["schemas"]


@pytest.mark.django_db
def test_every_number_of_every_json_body_refuses_booleans_and_strings(world):
    """Read from the schema: wherever a JSON body takes a number, ``true`` and ``"5"`` are a 400 that says why
    (DRF's fields would take them as 1 and 5)."""
    from django.contrib.auth import get_user_model
    from rest_framework.test import APIClient

    client = APIClient()
    client.force_login(get_user_model().objects.get(username="alice"))
    checked = []
    for method, template, path, schema_, components in _json_bodies(client, world):
        for bad, says in ((True, "not a boolean"), ("5", "not a string")):
            for where, data in _fields(schema_, components, ("number", "integer"), bad):
                r = getattr(client, method)(path, data, format="json")
                assert r.status_code == 400 and says in r.content.decode(), (method, template, where, bad,
                                                                             r.status_code, r.content[:300])
                checked.append((method, template, where))
    assert len({c[1] for c in checked}) >= 7 and len(checked) >= 2 * 14  # every operation the schema names


@pytest.mark.django_db
def test_every_boolean_of_every_json_body_is_true_or_false_only(world):
    """Read from the schema: wherever a JSON body takes a boolean, 0, 1 and "true" are a 400 naming the field (DRF's
    BooleanField takes them, and "yes" and "on", as booleans)."""
    from django.contrib.auth import get_user_model
    from rest_framework.test import APIClient

    client = APIClient()
    client.force_login(get_user_model().objects.get(username="alice"))
    before = rows()
    checked = []
    for method, template, path, schema_, components in _json_bodies(client, world):
        for bad in (0, 1, "true", "false"):
            for where, data in _fields(schema_, components, ("boolean",), bad):
                r = getattr(client, method)(path, data, format="json")
                assert r.status_code == 400 and r.json().get(where[0]) == ["A boolean is required: true or false."], \
                    (method, template, where, bad, r.status_code, r.content[:300])
                checked.append((method, template, where))
    assert {(c[1], c[2]) for c in checked} >= {("/api/v1/procedures/{code}/", ("share_photo",)),
                                               ("/api/v1/procedures/{code}/parameters", ("save",))}
    assert rows() == before
