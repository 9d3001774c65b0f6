"""The demo the worker makes before the site opens (`worker.demo`, ``python -m worker demo``): the site's
``demo --hold``, then the worker's task run in that process with the shipped model. The demo as the site serves it,
read-only, is tested in tests/site/test_demo.py."""

from __future__ import annotations

import pytest

from webapp.facades.models import Procedure


@pytest.mark.django_db(transaction=True)
def test_the_demo_made_now_is_on_the_first_page_at_once(client):
    """Issue 68: `scripts/run` makes the demo's procedure before the site opens (``python -m worker demo``: the site's
    ``demo --hold``, then the worker's task run in that process with the shipped model): a newcomer's first page has
    its example and "Try the demo", never "Nothing public yet"."""
    from worker.demo import make_demo

    assert make_demo() == "the demo's procedure is made"
    assert make_demo() == "the demo was made before"
    proc = Procedure.objects.get(owner__username="demo")
    assert proc.visibility == "public" and proc.accuracy > 0.9
    assert proc.versions.get(version=1).kind == "created"
    page = client.get("/").content.decode()
    assert 'id="try-demo"' in page and proc.get_absolute_url() in page and "Nothing public yet" not in page
    shown = client.get(proc.get_absolute_url()).content.decode()  # anonymous: what works, and how to keep a copy
    assert "work without an account" in shown and "log in</a> or" in shown and "Fork it, or" not in shown
