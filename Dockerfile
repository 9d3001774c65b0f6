# the browser libraries the pages serve as static files (scripts/vendor-js: three.js at package-lock.json's version)
FROM node:20-slim AS vendor-js
WORKDIR /app
COPY package.json package-lock.json ./
COPY scripts/vendor-js scripts/
RUN bash scripts/vendor-js

FROM python:3.11-slim
WORKDIR /app
ENV PYTHONUNBUFFERED=1 PIP_NO_CACHE_DIR=1
# a C compiler builds the native code on first use (facaid/native/); without one decoding uses torch
RUN apt-get update && apt-get install -y --no-install-recommends gcc libc6-dev && rm -rf /var/lib/apt/lists/*
COPY pyproject.toml README.md ./
COPY facaid facaid
COPY webapp webapp
COPY --from=vendor-js /app/webapp/static/vendor webapp/static/vendor
COPY worker worker
COPY frontend frontend
RUN pip install "torch==2.13.0" && pip install ".[postgres]"
COPY manage.py ./
COPY checkpoints checkpoints
EXPOSE 8000
