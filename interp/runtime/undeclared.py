"""What the run says when a program meets a name the backup itself never declares (issue 85,
item 9): the run-time error "unknown name X" of interp/runtime/names.py, completed with what
the checker knows and what KUKA's controller does with such a module.

The checker reports such a name as the program's error E101 at every line that uses it
(krl/semantics/outside.py: a name nothing declares and the checker does not classify as KUKA's
software); a run that does not check (``--no-check``, the audit's and the change report's runs)
reaches the line and stops there. On the controller the module does not get that far: KSS
compiles each module, a module with an error in its error list is not linked, and a program
whose modules do not link cannot be selected ("/R1/SPS linking error" with the compile errors
in the error list, https://industrialmonitordirect.com/blogs/knowledgebase/kuka-krc4-submit-interpreter-r1sps-linking-error-fix;
"the KRL interpreter validates program structure during the selection phase. If syntax errors
exist, the selection fails",
https://industrialmonitordirect.com/blogs/knowledgebase/kuka-krl-syntax-error-detection-via-program-selection).
"""

from __future__ import annotations

from pathlib import Path

from krl.diagnostics.codes import E101

from .errors import KrlRuntimeError

__all__ = ["explain_unknown"]


def explain_unknown(err: KrlRuntimeError, ws) -> None:
    """Complete the message of `err` ("unknown name X", its ``name`` X, its ``file``) in place
    when the checker of the run's workspace `ws` (krl.workspace.Workspace, its ``sink``) reports
    X as E101 -- in the error's file when it does there, else where it first does: "unknown name
    X: the backup declares no X (krl check: E101 at FILE:LINE:COL); KUKA's controller does not
    link MODULE with that error, so no program that is or calls MODULE can be selected" (MODULE:
    the error's file). Any other error,
    or a name the checker does not report, is left as it is."""
    name = err.name
    if not name or err.message != f"unknown name {name}" or ws is None:
        return
    said = E101(name=name)[1].lower()
    found = [d for d in ws.sink.sorted() if d.code == E101 and d.message.lower() == said]
    if not found:
        return
    here = [d for d in found if err.file and d.path == err.file]
    d = (here or found)[0]
    module = Path(err.file or d.path).name
    err.message = (f"unknown name {name}: the backup declares no {name} (krl check: {E101} at "
                   f"{Path(d.path).name}:{d.line}:{d.column}); KUKA's controller does not link {module} "
                   f"with that error, so no program that is or calls {module} can be selected")
