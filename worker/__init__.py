"""The worker: its Celery app (`worker.app`, started as ``celery -A worker``), its task (`worker.tasks`), what a
job computes on plain data, in the shape it stores (`worker.compute`), and the demo made before the site opens
(``python -m worker demo``). It calls `facaid` and stores through the site's models; the site sends it jobs by name
and never imports it."""
