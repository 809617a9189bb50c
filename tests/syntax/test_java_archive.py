"""The Java parse engine's class-data archive (krl/syntax/engines/java.py ``class_archive``):
the build (``make java-parser``, which the set-up of ``make test`` runs) writes one for the
working tree's grammar, the JVM maps it, and an archive the JVM cannot use changes no answer
(the JVM's warning about it would otherwise be the first line the worker writes on stdout,
where the answers go)."""

from __future__ import annotations

import shutil
import subprocess

from krl.syntax.engines import java as J

GRAMMAR = (J.REPO_ROOT / "grammar" / "KRL.g4").read_text(encoding="utf-8")
# a module with a syntax error (line 4: IF without THEN), so that the answer carries records
TEXT = "DEF demo()\n  INT i\n  i = 1\n  IF i == 1\n    i = 2\n  ENDIF\nEND\n"


def _answer(worker: J.JavaWorker) -> dict:
    try:
        ((_k, record),) = list(worker.parse_raw([TEXT]))
    finally:
        worker.close()
    return _without_id(record)


def _without_id(record: dict) -> dict:
    return {k: v for k, v in record.items() if k != "id"}


def test_the_build_writes_the_archive_and_the_jvm_maps_it():
    classes, worker = J.grammar_classes(GRAMMAR), J.worker_classes()
    cp = J.class_path(classes, worker)
    assert cp.endswith(J.CLASSES_JAR)
    archive = J.class_archive(cp)
    assert archive.is_file(), "make java-parser writes the archive"
    data = TEXT.encode()
    # -Xshare:on: the JVM stops where it cannot map the archive (auto would go on without it)
    run = subprocess.run(["java", *[o for o in J.JAVA_OPTS if o != "-Xshare:auto"], "-Xshare:on",
                          f"-XX:SharedArchiveFile={archive}", "-cp", cp, "KrlWorker", "1"],
                         input=b"1 %d\n%s0 -1\n" % (len(data), data), capture_output=True, timeout=300, check=False)
    assert run.returncode == 0, run.stdout + run.stderr
    assert _without_id(J.load_answer(run.stdout.splitlines()[0])) == _answer(J.JavaWorker(GRAMMAR))


def test_an_archive_the_jvm_cannot_use_changes_no_answer(tmp_path, monkeypatch):
    classes, worker = J.grammar_classes(GRAMMAR), J.worker_classes()
    archive = J.class_archive(J.class_path(classes, worker))
    expected = _answer(J.JavaWorker(GRAMMAR))
    assert expected["syn"], expected            # the IF without THEN
    # the worker's jar copied elsewhere: the archive no longer matches the class path
    moved = tmp_path / worker.name
    moved.mkdir()
    shutil.copy2(worker / J.CLASSES_JAR, moved / J.CLASSES_JAR)
    monkeypatch.setattr(J, "worker_classes", lambda: moved)
    monkeypatch.setattr(J, "class_archive", lambda cp: archive)
    assert _answer(J.JavaWorker(GRAMMAR)) == expected
