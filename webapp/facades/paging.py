"""Pages of the API's lists: ``?limit=`` (24 by default, at most 100) and ``?offset=``."""

from rest_framework.pagination import LimitOffsetPagination


class Pagination(LimitOffsetPagination):  # the default limit is REST_FRAMEWORK's PAGE_SIZE
    max_limit = 100  # ?limit= beyond this gives this many (an unbounded one reached the database as an overflow)
