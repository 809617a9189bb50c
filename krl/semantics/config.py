"""Which diagnostics `krl check` reports, and how severe: `--ignore CODE` and ``krl.toml``.

A backup (or any folder checked as one workspace) may hold a ``krl.toml`` at its root::

    [check]
    ignore = ["W111", "W101"]          # never report these codes
    select = ["E", "W2"]               # optional: report only codes starting with these
    [check.severity]
    W202 = "error"                     # report a warning as an error (it then fails the check)
    E110 = "warning"                   # or an error as a warning
    W107 = "off"                       # same as ignore

Only the workspace's own root is looked at (and the folder given on the command line): a
``krl.toml`` in a folder above is never adopted silently. ``--ignore`` on the command line adds
to the file's list. A code is a full code (``E104``) or a prefix (``W1`` = every W1xx).
Unknown keys, unknown codes and bad severities are errors that name the file (docs/diagnostics.md).
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from krl.diagnostics import CODES, Diagnostic
from krl.limits import MAX_CONFIG_BYTES

CONFIG_NAME = "krl.toml"
SEVERITIES = ("error", "warning", "off")


class ConfigError(ValueError):
    """A krl.toml (or --ignore value) that cannot be used; the message names the file."""


def _known_prefix(code: str) -> bool:
    return any(c.startswith(code.upper()) for c in CODES)


@dataclass
class Selection:
    """Codes to drop, codes to keep (empty: all) and severity overrides."""

    ignore: set[str] = field(default_factory=set)
    select: set[str] = field(default_factory=set)
    severity: dict[str, str] = field(default_factory=dict)
    source: str = ""

    def merged(self, other: "Selection") -> "Selection":
        return Selection(self.ignore | other.ignore, self.select | other.select,
                         {**self.severity, **other.severity}, other.source or self.source)

    @staticmethod
    def _matches(code: str, patterns: set[str]) -> bool:
        return any(code.startswith(p) for p in patterns)

    def apply(self, diags: list[Diagnostic]) -> list[Diagnostic]:
        """The diagnostics that are kept, with severities overridden (new objects where changed)."""
        out = []
        for d in diags:
            code = d.code.upper()
            if self._matches(code, self.ignore):
                continue
            if self.select and not self._matches(code, self.select):
                continue
            sev = self.severity.get(code)
            if sev == "off":
                continue
            if sev is not None and sev != d.severity:
                d = Diagnostic(d.path, d.line, d.column, d.code, d.message, sev, d.end_line, d.end_column,
                               list(d.notes), d.help)
            out.append(d)
        return out


def parse_codes(values, where: str) -> set[str]:
    """Validated codes (or code prefixes) from a list; ConfigError names `where`."""
    out = set()
    for v in values:
        if not isinstance(v, str) or not v.strip():
            raise ConfigError(f"{where}: a code must be a string like \"W111\", not {v!r}")
        code = v.strip().upper()
        if not _known_prefix(code):
            raise ConfigError(f"{where}: unknown diagnostic code {v!r} (see docs/diagnostics.md)")
        out.add(code)
    return out


def load_config(path: Path) -> Selection:
    """Read one krl.toml; raises ConfigError with the file's name for any problem."""
    try:
        if path.stat().st_size > MAX_CONFIG_BYTES:
            raise ConfigError(f"{path}: larger than {MAX_CONFIG_BYTES} bytes")
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(f"{path}: cannot read: {exc}") from None
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{path}: not valid TOML: {exc}") from None
    unknown = set(data) - {"check"}
    if unknown:
        raise ConfigError(f"{path}: unknown table or key {sorted(unknown)[0]!r} (expected [check])")
    check = data.get("check", {})
    if not isinstance(check, dict):
        raise ConfigError(f"{path}: [check] must be a table")
    unknown = set(check) - {"ignore", "select", "severity"}
    if unknown:
        raise ConfigError(f"{path}: unknown key {sorted(unknown)[0]!r} in [check] "
                          "(expected ignore, select, severity)")
    sel = Selection(source=str(path))
    for key in ("ignore", "select"):
        values = check.get(key, [])
        if not isinstance(values, list):
            raise ConfigError(f"{path}: check.{key} must be a list of codes")
        setattr(sel, key, parse_codes(values, f"{path}: check.{key}"))
    sev = check.get("severity", {})
    if not isinstance(sev, dict):
        raise ConfigError(f"{path}: [check.severity] must be a table of CODE = \"error\"|\"warning\"|\"off\"")
    for code, level in sev.items():
        if code.upper() not in CODES:
            raise ConfigError(f"{path}: check.severity: unknown diagnostic code {code!r}")
        if level not in SEVERITIES:
            raise ConfigError(f"{path}: check.severity.{code}: {level!r} is not one of {', '.join(SEVERITIES)}")
        sel.severity[code.upper()] = level
    return sel


def config_for(root: str | Path, *extra: str | Path) -> Selection:
    """The selection of the krl.toml in the workspace root `root` (a folder, or a file's folder),
    else in the first of `extra` that holds one; an empty selection when there is none."""
    candidates = []
    for p in (root, *extra):
        if not p:
            continue
        p = Path(p)
        candidates.append(p if p.is_dir() else p.parent)
    for folder in candidates:
        f = folder / CONFIG_NAME
        if f.is_file():
            return load_config(f)
    return Selection()
