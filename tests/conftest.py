"""Shared fixtures: the paper problem (built once per session; evaluation is pure)."""

from __future__ import annotations

import contextlib
import os
import resource
import shutil
import signal
import socket
import time
import urllib.error
import urllib.request
from pathlib import Path

import pytest

from adept_traj import Robot, Scene
from adept_traj.problem import TrajectoryProblem

# A test run started in the background (`nohup … &`, a shell without job control) inherits
# SIGINT ignored, and so would every command the tests start (an ignored signal stays
# ignored across exec): the Ctrl-C tests would then see a command that Ctrl-C cannot stop.
# A Ctrl-C at a terminal reaches the foreground command: the tests run as under one.
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)


@pytest.fixture(scope="session")
def problem() -> TrajectoryProblem:
    """The paper scenario's problem with default settings."""
    scene = Scene.paper()
    return TrajectoryProblem(Robot.adept_one_xl(), scene, scene.start, scene.goal)


@pytest.fixture
def process_gone():
    """``gone(pid)``: whether process ``pid`` has ended and been reaped (not in the
    process table any more)."""

    def gone(pid: int) -> bool:
        try:
            os.kill(pid, 0)
        except ProcessLookupError:
            return True
        return False

    return gone


@pytest.fixture
def child_fault():
    """``faulty(real, fault)``: ``real`` wrapped so that in any process but this one it
    raises ``RuntimeError("broken in the child")`` (``fault="raises"``) or kills its
    process (``fault="killed"``); in this process it is ``real``."""
    caller = os.getpid()

    def faulty(real, fault: str):
        def wrapped(*args, **kwargs):
            if os.getpid() != caller:
                if fault == "killed":
                    os.kill(os.getpid(), signal.SIGKILL)
                raise RuntimeError("broken in the child")
            return real(*args, **kwargs)

        return wrapped

    return faulty


# ---------------------------------------------------------------- a real browser
CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")
CHROMEDRIVER = shutil.which("chromedriver")
NO_BROWSER = (
    "no headless Chromium and chromium-driver on this machine (.ci/run installs the Debian "
    "packages chromium and chromium-driver)"
)
#: The flags that render WebGL on a CPU-only machine (shared/design/measured-facts.md).
CHROMIUM_FLAGS = (
    "--headless", "--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
    "--disable-gpu", "--no-first-run", "--disable-background-networking",
    "--disable-component-update", "--disable-sync",
)  # fmt: skip


@contextlib.contextmanager
def chromium_driver(profile: Path, *flags: str):
    """A Selenium driver of the system's headless Chromium with a new profile folder and
    ``flags`` beside :data:`CHROMIUM_FLAGS`; the test is skipped, with the reason, where
    selenium, Chromium or its driver is missing. Quit when the block is left."""
    webdriver = pytest.importorskip(
        "selenium.webdriver", reason="selenium not installed (test extra)"
    )
    if CHROMIUM is None or CHROMEDRIVER is None:
        pytest.skip(NO_BROWSER)
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    for flag in (*CHROMIUM_FLAGS, *flags, f"--user-data-dir={profile}"):
        options.add_argument(flag)
    options.binary_location = CHROMIUM
    driver = webdriver.Chrome(service=Service(CHROMEDRIVER), options=options)
    try:
        yield driver
    finally:
        driver.quit()


# ---------------------------------------------------------------- local servers
def may_lower_niceness() -> bool:
    """Whether this process may lower a thread's niceness from 19 back to its own (root,
    or an ``RLIMIT_NICE`` that allows it): where not, ``Worker.hurry`` is refused."""
    soft, _ = resource.getrlimit(resource.RLIMIT_NICE)
    own = os.getpriority(os.PRIO_PROCESS, 0)
    return os.geteuid() == 0 or soft == resource.RLIM_INFINITY or 20 - soft <= own


def fetch(url: str, method: str = "GET") -> tuple[int, bytes, dict[str, str]]:
    """(status, body, headers) of a request to ``url`` (an HTTP error's status too)."""
    request = urllib.request.Request(url, method=method)
    try:
        with urllib.request.urlopen(request, timeout=10) as reply:
            return reply.status, reply.read(), dict(reply.headers)
    except urllib.error.HTTPError as exc:
        return exc.code, b"", dict(exc.headers)


def refused(port: int) -> bool:
    """Nothing listens on 127.0.0.1:port."""
    try:
        socket.create_connection(("127.0.0.1", port), timeout=2).close()
    except ConnectionRefusedError:
        return True
    return False


def wait_for(condition, timeout: float = 60.0, step: float = 0.1) -> None:
    """Poll ``condition()`` every ``step`` [s] until it is true; AssertionError after
    ``timeout`` [s]."""
    end = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > end:
            raise AssertionError("the page did not get there in time")
        time.sleep(step)


@pytest.fixture(scope="module")
def cluster():
    """A local Dask cluster of two single-threaded worker processes, one per test module
    that asks for it (the cycle tests)."""
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0"
    ) as c:
        yield c
