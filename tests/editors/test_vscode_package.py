"""`make vsix`'s packaging step: @vscode/vsce builds the extension from editors/vscode, and the
.vsix holds what VS Code loads (the manifest with the krl language, grammar, debugger and
settings; the client with its run-time node packages) and none of the tests."""

from __future__ import annotations

import json
import zipfile
from pathlib import Path

from tests.editors.npm import build_vsix


def test_vsce_packages_the_extension(tmp_path: Path):
    vsix = build_vsix(tmp_path / "krl.vsix")
    with zipfile.ZipFile(vsix) as z:
        names = set(z.namelist())
        manifest = json.loads(z.read("extension/package.json"))
    for name in ("extension/extension.js", "extension/language-configuration.json",
                 "extension/syntaxes/krl.tmLanguage.json", "extension/readme.md",
                 "extension/node_modules/vscode-languageclient/node.js",
                 "extension/node_modules/vscode-jsonrpc/package.json"):
        assert name in names, name
    # tests, development tools and local files stay out
    assert not [n for n in names if n.startswith(("extension/test/", "extension/node_modules/@vscode/vsce",
                                                   "extension/node_modules/vscode-tmgrammar-test"))]
    assert "extension/.npm-ci.lock" not in names
    contributes = manifest["contributes"]
    assert contributes["languages"][0]["id"] == "krl"
    assert contributes["languages"][0]["extensions"] == [".src", ".dat", ".sub"]
    assert contributes["grammars"][0]["scopeName"] == "source.krl"
    debugger = contributes["debuggers"][0]
    launch = debugger["configurationAttributes"]["launch"]["properties"]
    assert debugger["type"] == "krl"
    assert launch["mode"]["enum"] == ["T1", "T2", "AUT", "EXT"]
    assert launch["runMode"]["enum"] == ["GO", "MSTEP", "ISTEP", "BSTEP"]     # krl run --run-mode's choices
    assert launch["interp"]["enum"] == ["tree", "vm"]
    # every krl run option (issue 37: submit and maxSimTime were missing), and the debugger's own
    assert {"program", "workspace", "inputs", "stopOnEntry", "submit", "noSubmit", "maxSimTime", "maxSteps",
            "robot", "pgno", "noCheck", "trace"} <= set(launch)
    settings = contributes["configuration"]["properties"]
    assert settings["krl.server.path"]["default"] == "krl" and settings["krl.server.args"]["default"] == ["lsp"]
