"""What the API's shapes share: fields that take a JSON value strictly (text that is text, numbers that are not
booleans or strings, finite floats, booleans that are ``true`` or ``false``) and the viewer an answer is for."""

from __future__ import annotations

from django.contrib.auth.models import AnonymousUser
from django.http import QueryDict
from rest_framework import serializers

from facaid.numbers import finite


class TextField(serializers.CharField):
    """Text, and only text: DRF's CharField would store a number or a boolean sent as a title as its string."""

    default_error_messages = {"invalid": "Not text: give a string."}

    def to_internal_value(self, data):
        if not isinstance(data, str):
            self.fail("invalid")
        return super().to_internal_value(data)


def title_field() -> TextField:
    return TextField(max_length=200, required=False, allow_blank=True)


def _json_body(field: serializers.Field) -> bool:
    """Whether ``field`` reads a JSON body (a form or multipart body sends every number as text)."""
    return not isinstance(getattr(field.root, "initial_data", None), QueryDict)


def _not_a_number(field: serializers.Field, data) -> None:
    """Refuse a boolean (which Python counts as 0 or 1) and, in a JSON body, a number written as a string."""
    if isinstance(data, bool):
        field.fail("boolean")
    if isinstance(data, str) and _json_body(field):
        field.fail("string")


class NumberField(serializers.FloatField):
    """A finite JSON number: not a boolean, not a string (DRF's FloatField takes ``true`` as 1 and ``"5"`` as 5),
    not infinity, and no 500 for an integer too large for a float (DRF's raises OverflowError)."""

    default_error_messages = {"invalid": "A finite number is required.",
                              "boolean": "A number is required, not a boolean.",
                              "string": "A number is required, not a string: write it without quotes."}

    def to_internal_value(self, data):
        _not_a_number(self, data)
        try:
            value = super().to_internal_value(data)
        except OverflowError:
            self.fail("invalid")
        if not finite(value):
            self.fail("invalid")
        return value


class WholeNumberField(serializers.IntegerField):
    """A whole JSON number: not a boolean, not a string (DRF's IntegerField takes ``"5"`` as 5)."""

    default_error_messages = {"boolean": "A whole number is required, not a boolean.",
                              "string": "A whole number is required, not a string: write it without quotes."}

    def to_internal_value(self, data):
        _not_a_number(self, data)
        return super().to_internal_value(data)


class StrictBooleanField(serializers.BooleanField):
    """``true`` or ``false`` in a JSON body: DRF's BooleanField also takes 0, 1, "true", "yes" and "on", so that
    ``"save": 0`` passed as a boolean (a form or multipart body sends its booleans as text and is read as before)."""

    default_error_messages = {"invalid": "A boolean is required: true or false."}

    def to_internal_value(self, data):
        if not isinstance(data, bool) and _json_body(self):
            self.fail("invalid")
        return super().to_internal_value(data)


def viewer(serializer: serializers.Serializer):
    """The user the answer is for: the request's, else anonymous (who is shown the least)."""
    request = serializer.context.get("request")
    return request.user if request is not None else AnonymousUser()
