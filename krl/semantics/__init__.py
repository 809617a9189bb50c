"""Semantic analysis: built-in data, types, symbol tables, the type checker and diagnostics.

Entry points (see docs/architecture.md, "Front end"):

* ``krl.workspace.load_workspace(paths)`` / ``workspaces_for(path)`` / ``check_texts({path: text})``
  build a :class:`krl.workspace.Workspace`; ``ws.check()`` returns the diagnostics and leaves the
  AST annotated.
* ``krl.ast.nodes.type_of(expr)`` -> :class:`krl.semantics.types.KrlType`;
  ``krl.ast.nodes.symbol_of(name_or_call)`` -> :class:`krl.semantics.symbols.Symbol`.
* ``krl.survey.report.check_report(corpus, out_dir)`` -> (data, markdown) for KRC backups.
"""
