"""The page's vendored bundle (issue 36, "Stack"): pendant/static/pendant.js is what
`make pendant-assets` builds from pendant/web (three.js and urdf-loader from the npm registry at
the versions of the committed package-lock.json, bundled by esbuild), so the committed bundle
that pip users get is current; and the lock file pins every package with its integrity hash."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

from tests.conftest import REPO_ROOT
from tests.editors.npm import npm_ci

WEB = REPO_ROOT / "pendant" / "web"
STATIC = REPO_ROOT / "pendant" / "static"


def test_lock_file_pins_the_3d_libraries():
    lock = json.loads((WEB / "package-lock.json").read_text())
    pkgs = lock["packages"]
    for name in ("three", "urdf-loader", "esbuild"):
        entry = pkgs[f"node_modules/{name}"]
        assert entry["version"] == json.loads((WEB / "package.json").read_text()).get(
            "dependencies", {}).get(name, json.loads((WEB / "package.json").read_text())["devDependencies"].get(name))
        assert entry["integrity"].startswith("sha512-")


def test_committed_bundle_is_what_make_builds(tmp_path: Path):
    npm_ci(WEB)
    out = tmp_path / "pendant.js"
    build = json.loads((WEB / "package.json").read_text())["scripts"]["build"]
    cmd = build.replace("../static/pendant.js", str(out)).split()
    run = subprocess.run(["npx", "--no-install", *cmd], cwd=WEB, capture_output=True, text=True, timeout=600,
                         check=False)
    assert run.returncode == 0, run.stdout + run.stderr
    assert out.read_bytes() == (STATIC / "pendant.js").read_bytes(), \
        "pendant/static/pendant.js is stale: run `make pendant-assets` and commit it"
    # the page loads nothing from elsewhere: no CDN, no remote font
    for f in ("index.html", "pendant.css"):
        text = (STATIC / f).read_text()
        assert "http://" not in text and "https://" not in text
