FROM python:3.11-slim
WORKDIR /app
ENV PYTHONUNBUFFERED=1 PIP_NO_CACHE_DIR=1
COPY pyproject.toml README.md ./
COPY facaid facaid
COPY webapp webapp
COPY worker worker
COPY frontend frontend
RUN pip install "torch==2.13.0" && pip install ".[postgres]"
COPY manage.py ./
COPY checkpoints checkpoints
EXPOSE 8000
