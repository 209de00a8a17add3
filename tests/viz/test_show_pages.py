"""The page server ``adept-traj show`` serves the folder's explorer and the member's
playback page with, on 127.0.0.1 beside meshcat (:class:`adept_traj.viz.page_server.
PageServer`): the bytes served, 404 for anything else, the loopback address only, the port
freed on close, bad input named. The command itself: tests/viz/test_playback_page.py."""

from __future__ import annotations

import pytest

from adept_traj.errors import InvalidInputError
from adept_traj.viz.page_server import PageServer
from tests.conftest import fetch, refused


def test_the_page_server_serves_its_pages_only_on_the_loopback_address() -> None:
    text = "<!DOCTYPE html><p>é</p>"
    with PageServer({"a.html": text, "b.html": b"\x00bytes"}) as pages:
        host, port = pages.address
        assert host == "127.0.0.1"
        assert pages.url("a.html") == f"http://127.0.0.1:{port}/a.html"
        status, body, headers = fetch(pages.url("a.html"))
        assert (status, body) == (200, text.encode("utf-8"))
        assert headers["Content-Type"] == "text/html; charset=utf-8"
        assert fetch(pages.url("b.html"))[:2] == (200, b"\x00bytes")
        assert fetch(pages.url("a.html") + "?x=1")[:2] == (200, text.encode("utf-8"))
        head = fetch(pages.url("a.html"), "HEAD")
        assert (head[0], head[1], head[2]["Content-Length"]) == (200, b"", str(len(body)))
        for path in ("", "c.html", "../a.html", "a.html/", "%2E%2E/result.json"):
            assert fetch(f"http://127.0.0.1:{port}/{path}")[0] == 404, path
    assert pages.closed
    assert refused(port)  # the port is free again: nothing answers
    pages.close()  # idempotent


@pytest.mark.parametrize(
    ("pages", "port", "match"),
    [
        ({}, 0, "non-empty mapping"),
        ({"a/b.html": "x"}, 0, "plain file name"),
        ({"": "x"}, 0, "plain file name"),
        ({"a.html": 3}, 0, "str or bytes"),
        ({"a.html": "x"}, 70000, r"port must be an integer in \[0, 65535\]; got 70000"),
        ({"a.html": "x"}, True, "port must be an integer"),
    ],
)
def test_the_page_server_names_bad_input(pages: dict, port: object, match: str) -> None:
    with pytest.raises(InvalidInputError, match=match):
        PageServer(pages, port=port)
