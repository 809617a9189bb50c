"""One fuzz target under atheris (libFuzzer): ``python -m tests.fuzz.atheris_main TARGET [libFuzzer args]``.

The project's modules are imported inside ``atheris.instrument_imports`` so that coverage
guides the fuzzer (the generated ANTLR parser is left out: its size slows every run and its
states are reached through the grammar rules anyway). tests/fuzz/run.py starts one process
per target with the seeds, the time budget and the artifact folder.
"""

from __future__ import annotations

import sys

import atheris

with atheris.instrument_imports(include=["krl", "interp", "robot", "conformance"],
                                exclude=["krl.syntax.generated"]):
    import krl.ast.build  # noqa: F401
    import krl.fmt.core  # noqa: F401
    import krl.lsp.project  # noqa: F401
    import krl.source  # noqa: F401
    import krl.syntax.parse  # noqa: F401
    import krl.workspace  # noqa: F401
    import robot.stimuli  # noqa: F401

from tests.fuzz.targets import TARGETS  # noqa: E402


def main() -> None:
    name = sys.argv.pop(1)
    target = TARGETS[name]
    if name == "interp":
        with atheris.instrument_imports(include=["interp", "conformance"]):
            # the subject of this test: imported inside instrument_imports, so that atheris instruments them
            import conformance.harness  # noqa: F401
            import interp.run  # noqa: F401
    atheris.Setup(sys.argv, target)
    atheris.Fuzz()


if __name__ == "__main__":
    main()
