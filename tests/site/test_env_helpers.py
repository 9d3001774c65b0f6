"""The loud environment helpers the worker and the site share: a malformed value names its variable."""

import pytest

from webapp.env import EnvError, env_bool, env_int, env_list, env_seconds


def test_values_and_defaults(monkeypatch):
    monkeypatch.setenv("X_BOOL", "yes")
    monkeypatch.setenv("X_INT", "42")
    monkeypatch.setenv("X_LIST", " a, b ,,c ")
    monkeypatch.setenv("X_OFF", "0")
    assert env_bool("X_BOOL", False) is True and env_int("X_INT", 1) == 42
    assert env_list("X_LIST", []) == ["a", "b", "c"] and env_seconds("X_OFF", 600) is None
    assert env_int("X_MISSING", 7) == 7 and env_seconds("X_MISSING", 600) == 600


@pytest.mark.parametrize("function, value, message", [
    (lambda: env_bool("X", False), "maybe", "X must be a boolean"),
    (lambda: env_int("X", 1), "1.5", "X must be an integer, got '1.5'"),
    (lambda: env_int("X", 1, minimum=1), "0", "X must be at least 1"),
    (lambda: env_seconds("X", 600), "-5", "X must be at least 0"),
])
def test_malformed_values_name_their_variable(monkeypatch, function, value, message):
    monkeypatch.setenv("X", value)
    with pytest.raises(EnvError, match=message):
        function()
