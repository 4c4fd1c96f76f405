# The robotale dashboard and command line; docker-compose.yml runs it next to Neo4j.
# Build stage: wheels for robotale and its pinned dependencies (some need a compiler).
FROM python:3.11-slim AS build
RUN apt-get update \
 && apt-get install -y --no-install-recommends build-essential \
 && rm -rf /var/lib/apt/lists/*
WORKDIR /src
COPY pyproject.toml setup.py constraints.txt README.md LICENSE ./
COPY robotale ./robotale
COPY cypher ./cypher
RUN pip wheel --no-cache-dir --wheel-dir /wheels -c constraints.txt .

FROM python:3.11-slim
COPY --from=build /wheels /wheels
RUN pip install --no-cache-dir --no-index /wheels/*.whl && rm -rf /wheels \
 && useradd --create-home robotale
# The thesis' log and models, for `robotale demo` and for trying things out.
COPY --chown=robotale examples /home/robotale/examples
USER robotale
WORKDIR /home/robotale
ENV ROBOTALE_HOME=/home/robotale/.robotale
EXPOSE 5000
CMD ["robotale", "serve", "--host", "0.0.0.0", "--port", "5000"]
