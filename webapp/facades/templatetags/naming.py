"""How the pages name things to the viewer: `{% load naming %}{% photo_name photo %}`."""

from __future__ import annotations

from django import template

from webapp.facades import access, disclosure

register = template.Library()


@register.simple_tag(takes_context=True)
def photo_name(context, photo) -> str:
    """The photo's title, else 'untitled photo' and its short code. A photo the viewer may not see (a fork's job's,
    made private since) is not named: neither its title nor its code."""
    if not access.photo_visible_to(context["user"], photo):
        return "a photo not shared with you"
    return photo.title or f"untitled photo {str(photo.code)[:8]}"


@register.simple_tag(takes_context=True)
def procedure_title(context, proc) -> str:
    """The procedure's title as the viewer is shown it: not one that repeats a photo they may not see
    (`disclosure.title`)."""
    return disclosure.title(context["user"], proc)


@register.simple_tag(takes_context=True)
def procedure_accuracy(context, proc) -> float | None:
    """The procedure's pixel accuracy, None to a viewer who may not see the photo it was measured against."""
    return None if disclosure.hidden(context["user"], proc) else proc.accuracy


@register.filter
def percent(share) -> str:
    """A share in [0, 1] as a percentage with one decimal ("99.7 %"), or "" when there is none."""
    if share is None:
        return ""
    return f"{100 * float(share):.1f} %"


@register.filter
def percent2(share) -> str:
    """A share in [0, 1] as a percentage with two decimals ("99.89 %"): a procedure's versions told apart."""
    if share is None:
        return ""
    return f"{100 * float(share):.2f} %"
