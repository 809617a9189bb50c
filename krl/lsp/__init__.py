"""`krl lsp`: a Language Server Protocol server for KRL on stdio (pygls 2, lsprotocol).

The server puts the front end in the editor: the parser (krl/syntax), the AST (krl/ast), the
workspace and its symbol tables (krl/workspace.py, krl/semantics). One module per job:

* :mod:`krl.lsp.text`      -- lines, code units, tokens of a line;
* :mod:`krl.lsp.parsing`   -- buffers parsed through krl/syntax/pieces.py (a change re-parses one routine);
* :mod:`krl.lsp.roots`     -- which files form the workspace of an opened file (the backup root);
* :mod:`krl.lsp.project`   -- open buffers over disk files, one checked :class:`Analysis` per root;
* :mod:`krl.lsp.analysis`  -- a checked workspace and the look-ups the features share;
* :mod:`krl.lsp.navigate`  -- what a name at a position means: definition, references;
* :mod:`krl.lsp.hover`, :mod:`krl.lsp.outline`, :mod:`krl.lsp.folding`, :mod:`krl.lsp.complete`;
* :mod:`krl.lsp.convert`   -- the shell with the server: plain results and krl diagnostics as LSP types;
* :mod:`krl.lsp.server`    -- the pygls server and its handlers; :mod:`krl.lsp.cli` the command;
* :mod:`krl.lsp.sample`    -- a synthetic program of a chosen length (the server's warm-up, the benchmark's);
* :mod:`krl.lsp.bench`     -- time from didChange to publishDiagnostics (``python -m krl.lsp.bench``).
"""
