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
RUN pip wheel --no-cache-dir --wheel-dir /wheels -c constraints.txt ".[server]"

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
# waitress, a production WSGI server, not werkzeug's development one. The dashboard answers
# to localhost and 127.0.0.1 (the published port); add the names it is reached by to
# ROBOTALE_ALLOWED_HOSTS. ROBOTALE_SECRET_KEY keeps forms valid across restarts.
CMD ["waitress-serve", "--listen=0.0.0.0:5000", "--threads=8", "--call", "robotale.webapp:create_app"]
