"""The live meshcat viewer: a local meshcat server and :func:`show`.

Why the server is started by hand: meshcat 0.3.2's ``Visualizer()`` binds its ZeroMQ socket
to 127.0.0.1 but its **web server on every interface** (tornado's ``listen(port)`` with no
address: ``0.0.0.0:7000`` and ``[::]:7000``), although it prints a 127.0.0.1 URL; and its
``Visualizer.close()`` fails (``ViewerWindow`` has no ``close``). :class:`_LocalWindow`
therefore starts the same meshcat server in a subprocess through a small launcher that
binds the web server to 127.0.0.1 too, prints nothing, and stops the subprocess on
``vis.close()`` or when Python exits.
"""

from __future__ import annotations

import atexit
import queue
import subprocess
import sys
import threading
import webbrowser
from typing import Any

import zmq

from adept_traj.errors import MeshcatServerError
from adept_traj.results import PlanningResult, Replay
from adept_traj.viz.meshcat_modules import viewer_modules
from adept_traj.viz.meshcat_scene import draw, member_page
from adept_traj.viz.playback import build_animation

__all__ = ["SERVER_TIMEOUT_S", "show"]

meshcat, ViewerWindow = viewer_modules()  # the live viewer needs meshcat's own

#: Seconds to wait for the meshcat server to start, and for each of its answers.
SERVER_TIMEOUT_S = 30.0

# The meshcat 0.3.2 server binds its web server on every interface (tornado's listen() with
# no address) although it prints a 127.0.0.1 URL; this launcher binds it to 127.0.0.1. It
# also serves the page read from its standard input (when not empty) at /static/, the URL
# the server hands out, ahead of meshcat's own page (still at /static/index.html).
_SERVER_SCRIPT = """
import functools, sys
import tornado.web
from meshcat.servers import zmqserver as z
PAGE = sys.stdin.buffer.read()
class Page(tornado.web.RequestHandler):
    def get(self):
        self.set_header("Content-Type", "text/html; charset=utf-8")
        self.set_header("Cache-Control", "no-store, no-cache, must-revalidate, max-age=0")
        self.write(PAGE)
_make_app = z.ZMQWebSocketBridge.make_app
def make_app(self):
    app = _make_app(self)
    if PAGE:
        app.add_handlers(r".*", [(r"/static/", Page)])
    app.listen = functools.partial(app.listen, address=self.host)
    return app
z.ZMQWebSocketBridge.make_app = make_app
sys.argv = ["meshcat-server"]
z.main()
"""


class _LocalWindow(ViewerWindow):
    """A meshcat server of our own on 127.0.0.1 (ZeroMQ and web), silent, closable, serving
    ``page`` (when given) at its URL, ``…/static/``."""

    def __init__(self, timeout: float = SERVER_TIMEOUT_S, page: str = "") -> None:
        # no super(): it prints
        self._closed = False
        self.server_proc = subprocess.Popen(
            [sys.executable, "-u", "-c", _SERVER_SCRIPT],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
        )
        atexit.register(self.close)
        stdin = self.server_proc.stdin
        if stdin is not None:  # the page served at /static/ ("": meshcat's own)
            try:
                stdin.write(page.encode("utf-8"))
                stdin.close()
            except BrokenPipeError:  # the server died at once: said below
                pass
        lines: queue.Queue[str | None] = queue.Queue()
        stdout = self.server_proc.stdout

        def pump() -> None:  # reads the server's stdout to the end: the pipe never fills
            for raw in stdout or ():
                lines.put(raw.decode("utf-8", "replace").strip())
            lines.put(None)

        threading.Thread(target=pump, name="meshcat-server-stdout", daemon=True).start()
        found: dict[str, str] = {}
        try:
            while len(found) < 2:
                line = lines.get(timeout=timeout)
                if line is None:
                    raise MeshcatServerError(
                        f"the meshcat server exited with code {self.server_proc.wait()}"
                    )
                key, _, value = line.partition("=")
                if key in ("zmq_url", "web_url"):
                    found[key] = value
        except queue.Empty:
            self.close()
            raise MeshcatServerError(
                f"the meshcat server did not start within {timeout:g} s"
            ) from None
        except BaseException:
            self.close()
            raise
        self.zmq_url, self.web_url = found["zmq_url"], found["web_url"]
        self.connect_zmq()

    def connect_zmq(self) -> None:
        self.zmq_socket = self.context.socket(zmq.REQ)
        self.zmq_socket.setsockopt(zmq.LINGER, 0)
        self.zmq_socket.setsockopt(zmq.RCVTIMEO, int(1000 * SERVER_TIMEOUT_S))
        self.zmq_socket.connect(self.zmq_url)

    def send(self, command: Any) -> None:
        try:
            super().send(command)
        except zmq.Again:
            raise MeshcatServerError("the meshcat server does not answer") from None

    def close(self) -> None:
        """Stop the server (idempotent)."""
        if self._closed:
            return
        self._closed = True
        atexit.unregister(self.close)
        socket = getattr(self, "zmq_socket", None)
        if socket is not None:
            socket.close(linger=0)
        if self.server_proc.poll() is None:
            self.server_proc.kill()
        self.server_proc.wait(timeout=10)

    @property
    def closed(self) -> bool:
        """True once :meth:`close` has run."""
        return self._closed


def show(
    result: PlanningResult,
    *,
    speed: float = 1.0,
    fps: float = 30.0,
    loop: bool = True,
    show_closest: bool = False,
    open_browser: bool = False,
    replay: Replay | None = None,
    member: int | None = None,
) -> meshcat.Visualizer:
    """Start a local meshcat server and play a member of ``result``'s front in it (default:
    the best trade-off).

    The server (a subprocess) listens on 127.0.0.1 only: its ZeroMQ socket and its web
    server. Nothing is printed; ``vis.url()`` is the page to open, ``vis.close()`` stops the
    server (it is also stopped when Python exits). The page
    (:func:`~adept_traj.viz.meshcat_scene.live_html`) is that of ``playback.html`` around
    the live viewer: the member's label (``#member-label``: algorithm, member, T,
    certified or not), the legend (``#legend``), play/pause (``#play-pause``), a scrubber
    (``#scrub``) and a time read-out (``#time-readout``), beside meshcat's own controls;
    meshcat's plain page stays at ``…/static/index.html``.

    Parameters
    ----------
    result: the planning result.
    speed, fps, show_closest, replay, member: see
        :func:`~adept_traj.viz.playback.build_animation`.
    loop: loop the animation forever (else play it once).
    open_browser: also open the page in the default web browser.

    Returns
    -------
    meshcat.Visualizer
        The visualizer, drawn and playing.

    Raises
    ------
    InvalidInputError: see :func:`~adept_traj.viz.playback.build_animation` (raised before
        any server starts).
    MeshcatServerError: the server did not start or does not answer.
    """
    playback = build_animation(
        result, speed=speed, fps=fps, show_closest=show_closest, replay=replay, member=member
    )
    window = _LocalWindow(page=member_page(result, playback, live=True))
    vis = meshcat.Visualizer(window=window)
    try:
        draw(vis, playback, loop=loop)
        if open_browser:
            webbrowser.open(vis.url(), new=2)
    except BaseException:
        window.close()
        raise
    return vis
