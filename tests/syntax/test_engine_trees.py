"""Parse trees from the Java engine (krl/syntax/engines/tree.py) and the batch path that uses
them (krl/workspace.py ``load_batch``): bad tree data, a worker that stops answering and a
whole backup checked through either engine.

The node-by-node equality of the rebuilt trees with the Python engine's, on every file of
the corpora, is in tests/syntax/test_engines.py.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
import gc
import weakref

import pytest
from antlr4 import ParserRuleContext
from antlr4.tree.Tree import TerminalNodeImpl

import krl.syntax.engines as engines_mod
import krl.workspace as workspace_mod
from krl.pool import run_tasks
from krl.syntax.engines import java as java_engine
from krl.syntax.engines import java_answers, parse_file, result_from_answer
from krl.syntax.engines.tree import RebuiltToken, TreeDataError, is_acyclic, stream_tokens, tree_from_raw
from krl.syntax.messages import syntax_diagnostics
from krl.syntax.tokens import lex
from krl.syntax.parse import default_bundle, prepare_text
from krl.source import SourceText, read_source
from tests.syntax.test_engines import SHARD_PARAMS, SHARDS, _files, _java_or_skip, _record, needs_java, tree_shape
from krl.project import collect_entries

TEXT = "DEF a()\nDECL INT x\nx = -(1 + 2) * 3\nIF x > 1 THEN\nx = x - 1\nENDIF\nEND\n"
BROKEN = "DEF b()\nx = = 1\nIF THEN\nEND\n"


def _first_terminal(tree: list[int], token: int) -> list[int]:
    """The tree data with its first terminal's token index replaced (preorder integers: a
    context takes 6, a terminal 2)."""
    tree, pos = list(tree), 0
    while tree[pos] >= 0:
        pos += 6
    tree[pos + 1] = token
    return tree


def _raw(text: str) -> dict:
    worker = java_engine.worker_for(java_engine.REPO_ROOT.joinpath("grammar", "KRL.g4").read_text(encoding="utf-8"))
    return dict(worker.parse_raw([prepare_text(text)], trees=True))[0]


@needs_java
@pytest.mark.parametrize("text", [TEXT, BROKEN])
def test_a_rebuilt_tree_is_the_python_engines_tree(text):
    _java_or_skip()
    py = parse_file(text, "a.src", engine="python", keep_tree=True)
    jv = parse_file(text, "a.src", engine="java", keep_tree=True)
    assert isinstance(jv.tree.start, RebuiltToken)
    assert tree_shape(jv.tree) == tree_shape(py.tree)
    assert _record(jv) == _record(py)
    assert jv.tree.getText() == py.tree.getText()


@pytest.fixture
def young_heap():
    """The objects (and the garbage) of the tests before frozen (gc.freeze: the permanent
    generation, which no collection looks at) while the test runs, so that its collections see
    only what it made: a full collection of a worker's heap took 2-5 s of CPU in make test,
    where the tests below collected it (2026-11-28); unfrozen after."""
    gc.freeze()
    yield
    gc.unfreeze()


def _without_parents(shape: list[tuple]) -> list[tuple]:
    """tree_shape rows with the parent's class (the row's last field but one for a context,
    the last for a terminal) left out."""
    return [row[:-1] if row[0] in ("terminal", "error") else row[:-2] + row[-1:] for row in shape]


@needs_java
@pytest.mark.parametrize("text", [TEXT, BROKEN])
def test_a_tree_rebuilt_without_parents_differs_only_there_and_is_freed_at_once(text, young_heap):
    """parents=False (krl/workspace.py ``load_parsed``): the same nodes, tokens and labels, every
    parentCtx None, and no cycle: with the cyclic collector off, dropping the root frees a leaf
    context at once (reference counting)."""
    _java_or_skip()
    raw = _raw(text)
    with_parents = tree_from_raw(raw, prepare_text(text), default_bundle())
    tree = tree_from_raw(raw, prepare_text(text), default_bundle(), parents=False)
    assert not is_acyclic(with_parents) and is_acyclic(tree)
    assert _without_parents(tree_shape(tree)) == _without_parents(tree_shape(with_parents))
    nodes, stack = [], [tree]
    while stack:
        n = stack.pop()
        nodes.append(n)
        stack.extend(getattr(n, "children", None) or ())
    assert len(nodes) > 20 and all(n.parentCtx is None for n in nodes)
    contexts = [n for n in nodes if isinstance(n, ParserRuleContext)]
    deepest = weakref.ref(contexts[-1])     # the last context in preorder: below the root
    assert contexts[-1] is not tree
    kept = weakref.ref(with_parents.children[0])
    del nodes, stack, n, contexts
    was = gc.isenabled()
    gc.disable()
    try:
        del tree
        assert deepest() is None            # freed without the collector
        del with_parents
        assert kept() is not None           # a tree with parent links is cyclic garbage ...
    finally:
        if was:
            gc.enable()
    gc.collect()
    assert kept() is None                   # ... until the collector runs


@needs_java
@pytest.mark.parametrize("damage", [
    lambda r: r.update(tree=r["tree"][:-1]),                       # ends inside a context
    lambda r: r.update(tree=r["tree"] + [-1, 0]),                   # a node after the root
    lambda r: r.update(tree=[-7] + r["tree"][1:]),                  # an unknown node kind
    lambda r: r.update(names=["NoSuchContext"] * len(r["names"])),  # a class the parser lacks
    lambda r: r.update(names=["__class__"] * len(r["names"])),      # not a context class
    lambda r: r.update(tokens=r["tokens"][:-1]),                    # not 6 integers per token
    lambda r: r.update(tree=[0, 10 ** 9, 0, 0, 0, 0]),              # a token that does not exist
    lambda r: r.update(tree=_first_terminal(r["tree"], -1)),         # a terminal with no token
    lambda r: r.update(labels=[[0, "op", "x", 1]]),                 # an unknown label kind
    lambda r: r.pop("tree"),
])
def test_bad_tree_data_is_an_error_and_the_python_engine_parses(damage):
    _java_or_skip()
    raw = _raw(TEXT)
    damage(raw)
    with pytest.raises(TreeDataError):
        tree_from_raw(raw, prepare_text(TEXT), default_bundle())
    src = SourceText("a.src", TEXT, "ascii", len(TEXT))
    res = result_from_answer(src, json.dumps(raw).encode(), keep_tree=True)
    assert res.ok and not isinstance(res.tree.start, RebuiltToken)
    assert tree_shape(res.tree) == tree_shape(parse_file(TEXT, "a.src", engine="python", keep_tree=True).tree)


def test_an_answer_is_read_by_orjson_or_else_by_json():
    """load_answer: the worker's JSON line as data; a lone surrogate escape, which orjson
    refuses, is read by the json module; a line that is no JSON raises ValueError."""
    assert java_engine.load_answer(b'{"id":3,"tokens":[1,2],"s":"\\u00e4"}') == {"id": 3, "tokens": [1, 2], "s": "\u00e4"}
    assert java_engine.load_answer(b'{"s":"\\ud800"}') == {"s": "\ud800"}
    with pytest.raises(ValueError):
        java_engine.load_answer(b'{"id":3,')


def test_a_worker_that_stops_answering_is_killed_after_the_stall(monkeypatch):
    """parse_raw(stall=...) gives up on a worker that reads its requests and never answers:
    WorkerError after about `stall` seconds, the process killed."""
    worker = java_engine.JavaWorker.__new__(java_engine.JavaWorker)
    worker.proc, worker.lock, worker.next_id, worker.threads = None, java_engine.threading.Lock(), 1, 1
    silent = [sys.executable, "-c", "import sys, time\nsys.stdin.buffer.read()\ntime.sleep(600)"]
    monkeypatch.setattr(worker, "_start", lambda: worker.proc or setattr(worker, "proc", subprocess.Popen(
        silent, stdin=subprocess.PIPE, stdout=subprocess.PIPE)) or worker.proc)
    proc = worker._start()
    start = time.monotonic()
    with pytest.raises(java_engine.WorkerError, match="no answer for 1 s"):
        list(worker.parse_raw(["DEF a()\nEND\n"] * 3, stall=1))
    assert 0.9 < time.monotonic() - start < 30
    assert proc.wait(timeout=10) != 0 and worker.proc is None


def test_java_answers_hands_every_unanswered_file_to_python(monkeypatch):
    """A worker that dies after two answers: those two come with their records, every other
    source with None (the Python engine parses it), none lost or repeated."""
    class Dying:
        def parse_raw(self, texts, **kw):
            for k in range(2):
                yield k, {"id": k, "stage": "sll", "lex": [], "syn": []}
            raise java_engine.WorkerError("the Java worker exited")

    # java_answers calls the name krl.syntax.engines imported (its import sits at the top)
    monkeypatch.setattr(engines_mod, "worker_for", lambda *a, **k: Dying())
    sources = [SourceText(f"f{i}.src", "DEF f()\nEND\n", "ascii", 12) for i in range(6)]
    sources.append(SourceText("bin.src", "", "", 3, "binary"))
    got = list(java_answers(enumerate(sources)))
    assert sorted(k for k, _, _ in got) == list(range(7))
    assert [k for k, _, raw in got if raw is not None] == [0, 1]
    assert got[0][0] == 6           # the source the worker never sees comes first


@needs_java
def test_a_backup_checks_the_same_through_either_engine(shared_corpus, monkeypatch):
    """krl check of a backup (load_batch, worker processes): the Java engine's batch path gives
    the same diagnostics and the same ASTs as the Python engine, and it really ran."""
    _java_or_skip()
    backup = shared_corpus / "rawpython__kukaKRLmagic"

    entries = collect_entries(backup)

    def load(engine: str):
        monkeypatch.setenv("KRL_ENGINE", engine)
        [ws] = workspace_mod.load_workspaces([(str(backup), entries)], timeout=60, jobs=2)
        return ws, list(ws.check(resolve=False))       # as krl check checks (app/check.py)

    monkeypatch.setattr(workspace_mod, "JAVA_BATCH_BYTES", 0)
    answered = []
    real = workspace_mod._parse_tasks

    def counting(*a, **kw):
        for key, (src, raw) in real(*a, **kw):
            answered.append(raw is not None)
            yield key, (src, raw)

    monkeypatch.setattr(workspace_mod, "_parse_tasks", counting)
    ws_py, diags_py = load("python")
    assert not any(answered)
    answered.clear()
    ws_jv, diags_jv = load("java")
    assert sum(answered) >= 30                     # of 34 files; the rest need a Python-only check
    assert diags_jv == diags_py and len(diags_py) > 0
    assert [f.path for f in ws_jv.files] == [f.path for f in ws_py.files]
    assert [f.module for f in ws_jv.files] == [f.module for f in ws_py.files]
    assert [[n.span for n in f.module.walk()] for f in ws_jv.files] == \
           [[n.span for n in f.module.walk()] for f in ws_py.files]


def _collector_state(src, raw=None):
    return gc.isenabled()


def test_load_batch_pauses_the_collector_here_but_never_in_the_workers(tmp_path, monkeypatch):
    """The main process pauses the cyclic collector while a batch's ASTs arrive (and restores
    it after); the worker processes, forked meanwhile, must collect as usual: their parse
    trees are cyclic garbage, file after file."""

    paths = []
    for i in range(4):
        (tmp_path / f"f{i}.src").write_text("DEF f()\nEND\n")
        paths.append(tmp_path / f"f{i}.src")
    monkeypatch.setattr(workspace_mod, "load_parsed", _collector_state)
    assert gc.isenabled()
    outcomes = workspace_mod.load_batch(paths, timeout=60, jobs=2)
    assert [o.status for o in outcomes] == ["done"] * 4
    assert [o.value for o in outcomes] == [True] * 4
    assert gc.isenabled()


@needs_java
@pytest.mark.parametrize("shard", SHARD_PARAMS)
def test_the_syntax_messages_read_the_rebuilt_token_stream(shared_corpus, shard):
    """A file with syntax errors is worded from the Java engine's token stream
    (``stream_tokens``), not lexed again: the stream is the Python lexer's, token by token,
    and the diagnostics are the same, on every corpus and negative-test file with an error
    (test_engines's shards: make test the first, 91 files of every kind, 36 with errors (one in
    six, 180 files, 73 with errors, until 2026-11-29); make nightly all twelve, every file: 1 075
    files, 449 with errors, 10.7 s of CPU on 2026-11-26)."""
    _java_or_skip()
    sources = [s for s in (read_source(p) for i, p in enumerate(_files(shared_corpus)) if i % SHARDS == shard)
               if s.status == "ok"]
    checked = 0
    for _i, src, raw in java_answers(enumerate(sources), threads=2, trees=True):
        if raw is None:
            continue
        res = result_from_answer(src, raw, keep_tree=True)
        if not res.errors:
            continue
        tokens = stream_tokens(res.tree)
        assert [(t.type, t.channel, t.text, t.line, t.column) for t in tokens] == \
            [(t.type, t.channel, t.text, t.line, t.column) for t in lex(prepare_text(src.text), default_bundle())], src.path
        assert syntax_diagnostics(res, src.text, tokens=tokens) == syntax_diagnostics(res, src.text), src.path
        checked += 1
    assert checked >= 10        # the corpus and tests/negative hold files with syntax errors
    assert stream_tokens(parse_file(TEXT, "a.src", engine="python", keep_tree=True).tree) is None


# (the Python engine's error recovery keeps the nodes it recovered in exception <-> context
# cycles: only its tree of a valid file is held to this)
@pytest.mark.parametrize("engine, text", [("java", TEXT * 20), ("java", BROKEN), ("python", TEXT * 20)])
def test_a_loaded_file_leaves_its_parse_tree_to_reference_counting(engine, text, young_heap):
    """load_parsed frees the parse tree its AST was built from (krl/workspace.py
    ``release_tree``): no node of it is left for the cyclic collector, and the AST is whole.
    (The Python engine's lexer and parser leave their own cycle: its tokens and the root.)"""
    if engine == "java":
        _java_or_skip()
    src = SourceText("a.src", text, "", len(text))
    raw = json.dumps(_raw(text)).encode() if engine == "java" else None
    was = gc.isenabled()
    gc.disable()
    gc.set_debug(gc.DEBUG_SAVEALL)
    try:
        lf = workspace_mod.load_parsed(src, raw)
        gc.collect()
        nodes = [o for o in gc.garbage if isinstance(o, (ParserRuleContext, TerminalNodeImpl))]
    finally:
        gc.set_debug(0)
        gc.garbage.clear()
        if was:
            gc.enable()
    # at most the root, childless, which the Python engine's parser holds in its own cycle
    assert len(nodes) <= (1 if engine == "python" else 0)
    assert all(isinstance(o, ParserRuleContext) and not o.children for o in nodes)
    assert [r.name.upper() for r in lf.module.routines] == (["A"] * 20 if text != BROKEN else ["B"])


def _load_here_in_worker(paths: list[str], engine: str) -> tuple:
    """In a worker process of krl.pool (as ``krl audit``'s check runs): its pid, the files
    loaded there (krl.workspace.load_here), how many the Java engine answered."""
    os.environ["KRL_ENGINE"] = engine
    answered = []
    real = workspace_mod.java_answers

    def counting(*a, **kw):
        for i, src, raw in real(*a, **kw):
            answered.append(raw is not None)
            yield i, src, raw

    workspace_mod.java_answers = counting
    loaded = workspace_mod.load_here([read_source(p) for p in paths], 60.0)
    return os.getpid(), sum(answered), [(lf.module, lf.diagnostics) for lf in loaded], \
        [[n.span for n in lf.module.walk()] for lf in loaded]


@needs_java
def test_load_here_parses_a_batch_with_the_java_engine_in_a_worker_process(shared_corpus):
    """krl.workspace.load_here in a worker process (a Dask worker may not start the pool of
    parse workers): a batch of at least JAVA_BATCH_BYTES goes to the Java engine's worker (started by
    that process), with the same ASTs, spans and diagnostics as the Python engine gives; a
    smaller batch is parsed by the Python engine."""
    _java_or_skip()
    backup = shared_corpus / "rawpython__kukaKRLmagic"
    paths = [e.path for e in collect_entries(backup) if e.kind == "file"]
    assert sum(read_source(p).size for p in paths) >= workspace_mod.JAVA_BATCH_BYTES
    small = [p for p in paths if read_source(p).size < 2000][:3]
    tasks = [("java", (paths, "auto")), ("python", (paths, "python")), ("small", (small, "auto"))]
    got = {o.key: o.value for o in run_tasks(_load_here_in_worker, tasks, jobs=2)}
    pid, answered, loaded_jv, spans_jv = got["java"]
    assert pid != os.getpid() and answered >= 30              # of 34 files; the rest need a Python-only check
    _d, answered_py, loaded_py, spans_py = got["python"]
    assert answered_py == 0
    assert loaded_jv == loaded_py and spans_jv == spans_py
    assert got["small"][1] == 0 and len(got["small"][2]) == len(small) > 0
