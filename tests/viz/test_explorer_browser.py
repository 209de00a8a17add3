"""The front explorer in a real browser: headless Chromium from the system packages
(``chromium``, ``chromium-driver``; ``.ci/run`` installs them), driven by Selenium, opens
``explorer.html`` of a result folder written by ``adept-traj plan``; brushes an axis of the
parallel coordinates (fewer members selected), clicks a member in the scatter plot (the
3-D view's pixels change, the certificate panel names that member), moves a weight slider
with the keyboard (the page's best trade-off is analysis.best_tradeoff's first certified
member for the slider values) and downloads the member's CSV (the numbers of
``adept-traj export``). Skipped with the reason when no Chromium or driver is installed."""

from __future__ import annotations

import csv
import io
import time
from pathlib import Path

import numpy as np
import pytest

from adept_traj.analysis import best_tradeoff
from adept_traj.cli import main
from adept_traj.results import PlanningResult
from tests.conftest import CHROMEDRIVER, CHROMIUM, NO_BROWSER, chromium_driver, wait_for

webdriver = pytest.importorskip("selenium.webdriver", reason="selenium not installed (test extra)")

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(CHROMIUM is None or CHROMEDRIVER is None, reason=NO_BROWSER),
]


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("explorer") / "run"
    code = main(["plan", "--pop", "40", "--gens", "20", "--seed", "3", "--no-plots", "--quiet",
                 "--out", str(out)])  # fmt: skip
    assert code == 0
    return out


@pytest.fixture(scope="module")
def browser(tmp_path_factory: pytest.TempPathFactory):
    with chromium_driver(tmp_path_factory.mktemp("profile"), "--window-size=1400,1800") as driver:
        yield driver


def png(driver, element_id: str) -> np.ndarray:
    from matplotlib.image import imread

    data = driver.find_element("id", element_id).screenshot_as_png
    return imread(io.BytesIO(data), format="png")


def test_explorer_in_a_real_browser(folder: Path, browser, tmp_path: Path) -> None:
    from selenium.webdriver.common.action_chains import ActionChains
    from selenium.webdriver.common.keys import Keys

    page = folder / "explorer.html"
    assert page.is_file()  # written by plan's finish
    result = PlanningResult.load(folder)
    n = len(result.front)
    downloads = tmp_path / "downloads"
    downloads.mkdir()
    browser.execute_cdp_cmd(
        "Page.setDownloadBehavior", {"behavior": "allow", "downloadPath": str(downloads)}
    )
    browser.get(page.resolve().as_uri())
    wait_for(lambda: browser.execute_script("return window.explorerReady === true"))
    assert f"{n} of {n} members" in browser.find_element("id", "selected-count").text
    shown = browser.find_element("id", "certificate").text
    assert f"member {result.best.index}" in shown

    # --- brush the z1 axis over its lower half: fewer members selected
    brush = browser.find_elements("css selector", "#parcoords .axis-brush")[0]
    height = brush.size["height"]
    ActionChains(browser).move_to_element_with_offset(brush, 0, int(0.48 * height)).click_and_hold(
    ).move_by_offset(0, -int(0.6 * height)).pause(0.3).release().perform()  # fmt: skip
    wait_for(lambda: f"{n} of {n}" not in browser.find_element("id", "selected-count").text)
    count = int(browser.find_element("id", "selected-count").text.split()[0])
    assert 0 < count < n

    # --- click another certified member in the scatter plot, one whose marker no other
    # marker covers: Plotly's click takes the topmost marker under the cursor (all markers
    # under it are equally close), so of two members 1 px apart a user can click only the
    # one drawn last (its number in the hover label). Which members crowd so depends on the
    # front, hence on the machine's floating point; the pixels are the page's own.
    browser.find_element("id", "play").click()  # pause: the view changes by the click only
    before = png(browser, "view3d")
    drawn = browser.execute_script(
        """const gd = document.getElementById('scatter'), L = gd._fullLayout, out = [];
        for (const tr of gd.data) tr.customdata.forEach((k, i) => out.push([k,
          L._size.l + L.xaxis.d2p(tr.x[i]), L._size.t + L.yaxis.d2p(tr.y[i]), tr.marker.size / 2]));
        return out;"""
    )  # [member, x [px], y [px], marker radius [px]] of every marker, in drawing order
    drawn = [d for d in drawn if d[1] is not None and d[2] is not None]  # NaN: not drawn

    def free(k: int) -> float:
        """[px] from member k's centre to the nearest edge of another member's marker."""
        x, y = next((d[1], d[2]) for d in drawn if d[0] == k)
        return min(np.hypot(x - d[1], y - d[2]) - d[3] for d in drawn if d[0] != k)

    certified = [k for k in range(n) if result.front.feasible[k] and k != result.best.index]
    member = max(certified, key=free)
    assert free(member) > 2.0, free(member)  # the cursor lands within 0.5 px of the centre
    xy = next((d[1], d[2]) for d in drawn if d[0] == member)
    plot = browser.find_element("css selector", "#scatter .main-svg")
    size = plot.size  # Selenium 4: the offset is from the element's centre
    ActionChains(browser).move_to_element_with_offset(
        plot, round(xy[0] - size["width"] / 2), round(xy[1] - size["height"] / 2)
    ).click().perform()
    wait_for(lambda: f"member {member}" in browser.find_element("id", "certificate").text)
    assert browser.find_element("id", "certificate").get_attribute("data-member") == str(member)
    assert f"member {member} " in browser.find_element("id", "shown-member").text + " "
    time.sleep(1.0)  # the 3-D redraw
    after = png(browser, "view3d")
    assert before.shape == after.shape
    changed = np.abs(before - after).max(axis=-1) > 0.05
    assert changed.mean() > 1e-4, changed.mean()  # the new member drawn (its path and pose)

    # --- move the w1 slider with the keyboard; the best trade-off follows best_tradeoff
    slider = browser.find_element("id", "w1")
    slider.click()
    slider.send_keys(*([Keys.ARROW_RIGHT] * 40))
    weights = [
        float(browser.find_element("id", f"w{i}").get_attribute("value")) for i in range(1, 7)
    ]
    assert weights[0] != 0.25
    choice = best_tradeoff(result.front.objectives, weights)
    ok = [int(k) for k in choice.order if result.front.feasible[k]]
    expected = ok[0] if ok else int(choice.order[0])
    got = browser.find_element("id", "best-weighted").get_attribute("data-member")
    assert int(got) == expected

    # --- download the shown member's CSV: the numbers of adept-traj export
    browser.find_element("id", "download-csv").click()
    target = downloads / f"member_{member}.csv"
    wait_for(lambda: target.is_file() and target.stat().st_size > 0, 30.0)
    exported = tmp_path / "export.csv"
    assert main(["export", str(folder), "--member", str(member), "--output", str(exported)]) == 0
    page_rows = list(csv.reader(target.open(encoding="utf-8")))
    cli_rows = list(csv.reader(exported.open(encoding="utf-8")))
    assert page_rows[0] == cli_rows[0]
    assert len(page_rows) == len(cli_rows)
    a, b = np.array(page_rows[1:], dtype=float), np.array(cli_rows[1:], dtype=float)
    assert np.array_equal(a[:, 0], b[:, 0])  # the same times, exactly
    np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-12)
