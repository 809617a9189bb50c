"""The screenshots of docs/pendant.md are the page as it is (issue 36): the page on two corpus
backups — the milling cell on its KR 210 R2700-2 (HugoDanielson__ChinaMilling, the robot its own
$machine.dat names) and the palletizer on its KR 180 PA (ingeniado__KRC4-Robot-Palletizer) — at a
deterministic stop (MSTEP in T2, after the first real motion), compared with the committed PNGs.
`KRL_UPDATE_SCREENSHOTS=1` writes them anew. T2, not T1: the motion at the programmed speed, not
at T1's reduced one ($RED_T1), is the same stop, simulated (with the backup's SPS.SUB) and drawn
at 30 Hz for 0.8 s and 0.4 s of simulated time instead of 9.8 s and 4.6 s.

The comparison allows what differs between two machines' software rendering (anti-aliasing,
font hinting): at most 2 % of the pixels differ by more than 48 levels in a channel."""

from __future__ import annotations

import io
import os

import numpy as np
import pytest
from PIL import Image

from tests.chromium import POLL_MS
from tests.conftest import REPO_ROOT
from tests.pendant.harness import (CELLS, MILLING, PALLETIZER, browser_page, pendant_server, select, wait_drawn,
                                   wait_state)


DOCS = REPO_ROOT / "docs" / "pendant"
# name: (backup, cell file, program, MSTEP stops). ChinaMilling's Main calls Home(), whose first
# motion is PTP $POS_ACT (no movement); its second, PTP XHOME, moves the arm to $config.dat's XHOME.
SHOTS = {
    "kr210-milling": (MILLING, CELLS / "HugoDanielson__ChinaMilling.yaml", "KRC/R1/Program/KukaMiling/Main.src", 2),
    "palletizer": (PALLETIZER, CELLS / "ingeniado__KRC4-Robot-Palletizer.yaml", "Program/SACO_20/saco_20_m1.src", 1),
}


def shot(pw, backup, cell, program, stops) -> bytes:
    with pendant_server(backup, "--no-realtime", "--inputs", str(cell)) as url, browser_page(pw, url, (1400, 900), scale=1) as page:
        select(page, program, run_mode="MSTEP", mode="T2")
        for _ in range(stops):
            before = page.evaluate("() => window.pendant.state.pointers.step")
            page.click("#start")
            wait_state(page, f"s.state == 'stopped' && s.stop && s.stop.reason == 'step' && s.pointers.step > {before}")
        # everything of this stop has reached the page: the whole TCP path and the pose
        page.wait_for_function("() => { const s = window.pendant.state; return window.pendant.pathPoints === "
                               "s.path.points && window.pendant.renderedAxes().every((v, i) => "
                               "Math.abs(v - s.position.axes[i]) < 1e-3); }", polling=POLL_MS)
        page.click('#tabs button[data-tab="io"]')
        page.evaluate("() => document.activeElement && document.activeElement.blur()")
        wait_drawn(page)               # the drawn frame is this stop's, whatever the machine's load
        assert page.problems == []
        return page.screenshot()


@pytest.mark.parametrize("name", sorted(SHOTS))
def test_screenshot_is_current(pw, shared_corpus, name):
    png = shot(pw, *SHOTS[name])
    path = DOCS / f"{name}.png"
    if os.environ.get("KRL_UPDATE_SCREENSHOTS") == "1":
        path.write_bytes(png)
    assert path.exists(), f"{path} is missing: KRL_UPDATE_SCREENSHOTS=1 writes it"
    assert f"pendant/{name}.png" in (REPO_ROOT / "docs" / "pendant.md").read_text()
    new = np.asarray(Image.open(io.BytesIO(png)).convert("RGB"), dtype=np.int16)
    old = np.asarray(Image.open(path).convert("RGB"), dtype=np.int16)
    assert new.shape == old.shape
    differ = (np.abs(new - old).max(axis=2) > 48).mean()
    assert differ <= 0.02, f"{name}: {differ:.1%} of the pixels differ from {path}; KRL_UPDATE_SCREENSHOTS=1 updates it"
