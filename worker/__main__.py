"""``python -m worker demo``: the demo made before the site opens (`worker.demo`)."""

from __future__ import annotations

import os
import sys


def main(argv: list[str]) -> int:
    if argv != ["demo"]:
        print("usage: python -m worker demo", file=sys.stderr)
        return 2
    import django

    os.environ.setdefault("DJANGO_SETTINGS_MODULE", "webapp.settings")
    django.setup()
    from worker.demo import make_demo

    print(make_demo())
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
