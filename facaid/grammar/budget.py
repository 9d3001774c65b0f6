"""A unit of work's budget, in node instances: what the trees it reads and makes cost to lay out.

Each tree is bounded on its own when it is parsed or validated (`limits.MAX_INSTANCES`, counted by
`layout.count_expansion` before any of the tree is executed). A request can still make many of them: a parameter
edit validates a tree per value, a variation per variant. `work_budget` bounds their sum: every validation inside it
charges the tree's instances, and the one past the budget raises `WorkLimitError`, before that tree's work is done.
Instances do not price every step alike (setting a named parameter of a tree with many exceptions costs more than
laying it out), so a budget may also bound the CPU seconds its thread spends, checked at each charge. A request
that is about to make many trees (n variants, k parameter values) `reserve`s them first, so that it is refused
before the first is made rather than after the work it could pay for.
The site opens one budget per request (`webapp.middleware.WorkBudgetMiddleware`); outside a budget nothing is
counted (the command line and the worker, whose jobs have their own limits).
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from time import thread_time

_budget: ContextVar[list[float] | None] = ContextVar("facaid_work_budget", default=None)


class WorkLimitError(Exception):
    """More work than the budget allows; the message names the limit and what to ask for instead."""


@contextmanager
def work_budget(instances: int, seconds: float | None = None) -> Iterator[None]:
    """Count the instances of every tree validated inside, and refuse the one that takes the sum past
    ``instances``, or that comes after ``seconds`` of this thread's CPU time."""
    token = _budget.set([instances, 0, float("inf") if seconds is None else seconds, thread_time()])
    try:
        yield
    finally:
        _budget.reset(token)


def charge(instances: int) -> None:
    budget = _budget.get()
    if budget is None:
        return
    budget[1] += instances
    if budget[1] > budget[0]:
        raise _past(budget)
    if thread_time() - budget[3] > budget[2]:
        raise WorkLimitError(
            f"this request needs more than {budget[2]:g} s of computing: ask for less at once (fewer values or "
            "variants) or use a smaller tree")


def reserve(instances: int) -> None:
    """Refuse now, before any of it is done, work the current budget cannot pay: ``instances`` more than it has
    spent (the trees a request is about to make, charged again as each is made). Outside a budget, nothing."""
    budget = _budget.get()
    if budget is not None and budget[1] + instances > budget[0]:
        raise _past(budget)


def _past(budget: list[float]) -> WorkLimitError:
    return WorkLimitError(
        f"this request would lay out more than {int(budget[0]):,} node instances in all (every tree it reads or "
        "makes, each node once per copy of it): ask for less at once (fewer values or variants) or use a "
        "smaller tree")


def seconds_left() -> float | None:
    """The CPU seconds the current budget has left (never below 0; inf where it bounds none; None outside one): what
    optional work (a check of a saved tree's edits) measures itself against, so as not to leave the request that
    asked for it without the time for its own work."""
    budget = _budget.get()
    return None if budget is None else max(0.0, budget[2] - (thread_time() - budget[3]))


def spent() -> int | None:
    """The instances charged so far in the current budget (None outside one)."""
    budget = _budget.get()
    return None if budget is None else int(budget[1])
