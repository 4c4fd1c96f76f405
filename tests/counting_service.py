"""An HTTP service on 127.0.0.1 that counts the requests it gets: what the console's tests
point a fetching query at, to see from outside whether anything was fetched."""

from __future__ import annotations

import http.server
import threading
from collections.abc import Iterator
from contextlib import contextmanager


@contextmanager
def counting_service(body: bytes) -> Iterator[dict]:
    """Serve ``body`` to every GET; yields ``{"hits": requests so far, "url": its URL}``."""
    seen: dict = {"hits": 0}

    class Handler(http.server.BaseHTTPRequestHandler):
        def do_GET(self) -> None:
            seen["hits"] += 1
            self.send_response(200)
            self.send_header("Content-Length", str(len(body)))
            self.end_headers()
            self.wfile.write(body)

        def log_message(self, *args: object) -> None:
            pass  # the tests count requests; a line per request is noise

    server = http.server.HTTPServer(("127.0.0.1", 0), Handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    seen["url"] = f"http://127.0.0.1:{server.server_port}/secret.csv"
    try:
        yield seen
    finally:
        server.shutdown()
        server.server_close()
