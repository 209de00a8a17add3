"""A few self-contained pages served on 127.0.0.1: what ``adept-traj show`` serves beside
the live meshcat viewer (the folder's ``explorer.html`` and the playback page with its
controls).

:class:`PageServer` is the standard library's threaded HTTP server bound to the loopback
address only (an ephemeral port unless given), in a daemon thread, answering ``GET`` and
``HEAD`` of the pages it was given (their bytes are read once, at the start) and 404 for
anything else: no folder is listed, no other file is read. It logs nothing.
"""

from __future__ import annotations

import threading
from collections.abc import Mapping
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any, ClassVar

from adept_traj.errors import InvalidInputError, MeshcatServerError

__all__ = ["HOST", "PageServer"]

#: The only address the page server binds.
HOST = "127.0.0.1"


class PageServer:
    """Serve ``pages`` (name → HTML text or bytes, e.g. ``{"explorer.html": ...}``) at
    ``http://127.0.0.1:PORT/NAME`` until :meth:`close` (idempotent; also a context
    manager).

    Parameters
    ----------
    pages: the pages; names are plain file names (no ``/``), not empty.
    port: the port, in [0, 65535]; 0 (default): a free one chosen by the system.

    Raises
    ------
    InvalidInputError: no page, a name with a ``/`` or empty, or a bad port.
    MeshcatServerError: the port cannot be bound.
    """

    def __init__(self, pages: Mapping[str, str | bytes], *, port: int = 0) -> None:
        if not isinstance(pages, Mapping) or not pages:
            raise InvalidInputError("pages must be a non-empty mapping of name → page text")
        body: dict[str, bytes] = {}
        for name, page in pages.items():
            if not isinstance(name, str) or not name or "/" in name:
                raise InvalidInputError(f"a page name must be a plain file name; got {name!r}")
            if not isinstance(page, (str, bytes)):
                raise InvalidInputError(f"page {name!r} must be str or bytes")
            body["/" + name] = page.encode("utf-8") if isinstance(page, str) else bytes(page)
        if isinstance(port, bool) or not isinstance(port, int) or not 0 <= port <= 65535:
            raise InvalidInputError(f"port must be an integer in [0, 65535]; got {port!r}")
        handler = type("_Handler", (_PageHandler,), {"pages": body})
        try:
            self._httpd = ThreadingHTTPServer((HOST, port), handler)
        except OSError as exc:
            raise MeshcatServerError(f"cannot serve pages on {HOST}:{port}: {exc}") from None
        self._httpd.daemon_threads = True
        self._closed = False
        self._thread = threading.Thread(
            target=self._httpd.serve_forever,
            kwargs={"poll_interval": 0.05},  # [s]: close() waits for one poll at most
            name="adept-traj-pages",
            daemon=True,
        )
        self._thread.start()

    @property
    def port(self) -> int:
        """The port listened on."""
        return int(self._httpd.server_address[1])

    @property
    def address(self) -> tuple[str, int]:
        """(host, port) listened on."""
        host, port = self._httpd.server_address[:2]
        return str(host), int(port)

    def url(self, name: str) -> str:
        """The address of page ``name``."""
        return f"http://{HOST}:{self.port}/{name}"

    def close(self) -> None:
        """Stop serving and free the port (idempotent)."""
        if self._closed:
            return
        self._closed = True
        self._httpd.shutdown()
        self._httpd.server_close()
        self._thread.join(timeout=10)

    @property
    def closed(self) -> bool:
        """True once :meth:`close` has run."""
        return self._closed

    def __enter__(self) -> PageServer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class _PageHandler(BaseHTTPRequestHandler):
    pages: ClassVar[dict[str, bytes]] = {}

    def _answer(self, send_body: bool) -> None:
        page = self.pages.get(self.path.split("?", 1)[0])
        if page is None:
            self.send_error(404, "no such page")
            return
        self.send_response(200)
        self.send_header("Content-Type", "text/html; charset=utf-8")
        self.send_header("Content-Length", str(len(page)))
        self.send_header("Cache-Control", "no-store")
        self.end_headers()
        if send_body:
            self.wfile.write(page)

    def do_GET(self) -> None:
        self._answer(True)

    def do_HEAD(self) -> None:
        self._answer(False)

    def log_message(self, format: str, *args: Any) -> None:
        pass
