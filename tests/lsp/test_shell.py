"""The language server's shell: only krl/lsp/server.py and krl/lsp/convert.py import the protocol's
types (lsprotocol) and pygls (and the benchmark's client, krl/lsp/bench.py); the feature modules
return plain project types and import neither, directly or through another module. The
contracts are checked on the project's import graph and shown to fail when broken."""

from __future__ import annotations

from importlinter.contracts.protected import ProtectedContract

from tests.test_layers import ROOTS, _graph

SHELL = ["krl.lsp.server", "krl.lsp.convert", "krl.lsp.bench"]
PROTOCOL = ["lsprotocol", "pygls"]


def _protected(graph) -> bool:
    contract = ProtectedContract(name="lsp shell", session_options={"root_packages": list(ROOTS)},
                                 contract_options={"protected_modules": PROTOCOL, "allowed_importers": SHELL})
    return contract.check(graph, verbose=False).kept


def _features(graph) -> list[str]:
    return sorted(m for m in graph.find_children("krl.lsp") if m not in SHELL + ["krl.lsp.cli", "krl.lsp.__main__"])


def _forbidden(graph, features) -> bool:
    """True when no feature module reaches lsprotocol or pygls, directly or through others."""
    return not [(f, p) for f in features for p in PROTOCOL if graph.chain_exists(importer=f, imported=p)]


def test_only_the_shell_imports_the_protocol():
    graph = _graph()
    features = _features(graph)
    assert {"krl.lsp.calls", "krl.lsp.complete", "krl.lsp.folding", "krl.lsp.outline", "krl.lsp.text",
            "krl.lsp.navigate", "krl.lsp.parsing"} <= set(features)
    assert _protected(graph) and _forbidden(graph, features)
    graph.add_import(importer="krl.lsp.hover", imported="lsprotocol", line_number=1,
                     line_contents="from lsprotocol import types as L")
    assert not _protected(graph) and not _forbidden(graph, features)


def test_a_feature_reaching_the_protocol_through_the_shell_is_caught():
    graph = _graph()
    features = _features(graph)
    graph.add_import(importer="krl.lsp.outline", imported="krl.lsp.convert", line_number=1,
                     line_contents="from krl.lsp.convert import to_range")
    assert _protected(graph) and not _forbidden(graph, features)
