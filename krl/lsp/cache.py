"""The language server's persistent parse and check cache (docs/editors.md, "Speed"): the one
store that every command shares (krl/store.py: the SQLite database, its keys and limits;
krl/parsecache.py: the msgpack codec by schema). This module keeps the names the server uses.

Two kinds of entries: **parse**, one per (file content SHA-256, .dat or not), what ``krl check``
makes of the file, path-free, written and read by ``krl run``/``krl debug`` too (a file parsed
by one is a hit for the other); **check**, one per workspace (the SHA-256 of every file's path
and content and of the entries not read), the workspace's diagnostics after a full check.
Nothing is ever unpickled or evaluated; a corrupt entry is ignored (parsed again).
"""

from __future__ import annotations

from krl.parsecache import (_CLASSES, _INDEX, _LIST, _TUPLE, N, CorruptEntry, decode_diagnostics,  # noqa: F401
                            decode_loaded, encode_diagnostics, encode_loaded)
from krl.store import CODEC, LOCK_WAIT_S, Store, cache_dir, check_key, front_end_version, parse_key  # noqa: F401

__all__ = ["CODEC", "CorruptEntry", "Store", "cache_dir", "check_key", "decode_diagnostics", "decode_loaded",
           "encode_diagnostics", "encode_loaded", "front_end_version", "parse_key"]
