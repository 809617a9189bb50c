"""The abstract syntax tree: node classes (nodes), parse tree -> AST (build), AST -> KRL (printer)."""
