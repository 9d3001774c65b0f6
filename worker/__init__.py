"""The Celery side of FaçAID: the app and its configuration (`worker.app`) and the computations a job runs
(`worker.compute`), on plain data. It imports `facaid`, never the site; the site's tasks call into it."""
