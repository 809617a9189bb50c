"""Corpus-wide measurements of the front end: the check report of every KRC backup of a corpus
(`report`, part of the recovery report), the seeded-error recall (`mutants`), checking against
parsing cost (`bench`) and the KSS tables derived from KUKA's system files (`derive_tables`).
Each runs as ``python -m krl.survey.NAME CORPUS``."""
