"""The API's throttle for requests that cost real CPU (rendering a procedure, variations, rectifying a photo,
building a download): a rate of its own (FACAID_API_HEAVY_RATE) on top of the general ones, per account for
users and per address for everyone else."""

from rest_framework.throttling import AnonRateThrottle, UserRateThrottle


class HeavyRateThrottle(UserRateThrottle):
    scope = "heavy"


HEAVY = [AnonRateThrottle, UserRateThrottle, HeavyRateThrottle]
