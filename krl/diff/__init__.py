"""The semantic backup diff (`krl diff OLD NEW`, issue 26): two backups (folders or .zip
archives) or two files compared on the AST -- points, frames and loads, routines,
declarations and signals, inline-form motions. krl/diff/load.py reads the sides,
krl/diff/core.py compares them, krl/diff/text.py prints the text and HTML forms; the JSON form
is documented in docs/diff.md."""
