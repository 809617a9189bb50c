"""Semantic analysis: built-in data, types, symbol tables, the type checker and diagnostics."""
