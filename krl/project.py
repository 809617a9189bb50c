"""The project model: which KRC backup a path belongs to, and which files make a program.

One rule, used by ``krl check``, ``krl run``, ``krl asm``, ``krl lsp``, ``krl fmt`` and the
static check of ``krl recover`` (docs/architecture.md, "Project model"):

1. **A backup.** A folder *B* is the *base* of a KRC backup when ``B/System/$config.dat`` is a
   regular file (folder and file names in any letter case; links are never followed), or when
   *B* is named ``R1``, holds a ``Program``, ``System`` or ``Mada`` folder and its parent holds
   ``STEU`` (the ``KRC`` folder of a controller archive as KUKA writes it: ``KRC/R1/{Program,
   System,TP,Mada}`` beside ``KRC/STEU/{Mada,$config.dat}``, ../shared/event-logs/README.md;
   krl/kssarchive.py reads the rest of such an archive). The backup's *root* is the folder
   holding *B* when *B* is named ``R1`` (``KRC/R1/System``: the root is ``KRC``, so ``KRC/STEU``
   belongs to it), else *B* itself (a flat export of R1).
2. **The backup of a path** is the *outermost* backup root among the path's folders: a backup
   inside another one is part of it. With ``within`` (``krl run --workspace DIR``), only folders
   inside ``DIR`` (``DIR`` included) count, so a folder above it is never adopted.
3. **A program's files** (:func:`project_of`): in a backup, every KRL file (``.src``, ``.dat``,
   ``.sub``, any case) below its root; outside one, every KRL file below the program's folder
   (``within``, else the folder holding the program). Folders are walked by
   :func:`krl.files.walk` (iterative; links, FIFOs, unreadable and too deep folders are listed,
   never read: warning W002), in its order (the files of a folder before its sub-folders,
   names sorted), which decides which of two declarations comes first.
4. **The BASIS** (:func:`with_basis`): a program outside a backup runs on the project's own
   BASIS (``interp/basis``: ``$config.dat``, ``bas.src``, ``ir_stopm.src``), added after its
   files as its System folder. A backup's ``$config.dat`` holds KUKA's BASIS part and the
   cell's own part in one data list; so the BASIS ``$config.dat`` merges with a program's own
   ``$config.dat`` as a backup's would — both are read, the program's first (its declarations
   win, the BASIS's fill in the rest: system data lists may repeat a declaration, the first
   one holds it) — while any other BASIS module is left out when the program has a module of
   that name (its own ``bas.src`` replaces the BASIS's).
5. **Modules** (:func:`modules_of`): ``NAME.src`` or ``NAME.sub`` and ``NAME.dat`` in one
   folder (any case) form one module, the data list being its module scope; when a folder
   holds both ``NAME.src`` and ``NAME.sub``, the first in walk order pairs with ``NAME.dat``
   and the other is a module of its own. A ``.sub`` file is a submit program
   (:func:`is_submit_file`).
6. **A folder given to ``krl check``, ``krl recover`` or ``krl fmt``** (:func:`folder_groups`)
   is split by the same rule, from one walk: one program per backup below it, then one per
   top-level folder for the files outside every backup (a folder without backups is one
   program).
7. **KUKA's system folders** (:data:`SYSTEM_DIRS`: ``System``, ``TP``, ``Mada``, ``STEU``, any
   case; :func:`system_folder_of`) hold KUKA's software, not the cell's programs: the one list
   for the checker's leniency (:func:`is_system_path`), the real-programs report and the cell
   starter. Where the folders are gone (a backup's files lying flat in one folder), a file's
   own header lines say it (:func:`header_folder`): ``&PARAM DISKPATH`` naming one of those
   folders, or KUKA's delivery header (``&ACCESS`` without ``V`` and a ``&COMMENT`` title, as
   bas.src, ir_stopm.src, p00.src come); the checker (krl.workspace.is_kuka_file) reads both,
   and :func:`kuka_folder` gives the folder from both for the entry points
   (interp/realprograms.py) and the cell starter (interp/cellinit.py).
8. **A controller archive** (KUKA's *File > Archive*; the layout of
   ../shared/event-logs/README.md: ``am.ini``, ``KRC/R1/...``, ``KRC/STEU``, ``C/KRC/Roboter/...``,
   ``Log Files/``) is one backup, its ``KRC`` folder: the archive's ``C`` folder holds the
   controller's configuration and KUKA's templates (``C/KRC/Roboter/Template/*.src``, which the
   controller offers when a module is created and never runs), its ``Log Files`` the logbook
   (krl/kssarchive.py reads both). So in a folder that holds a backup root named ``KRC`` (any case),
   or the manifest of an archive (``am.ini``, ``ArchiveInfo.xml``), the folders ``C`` and
   ``Log Files`` beside it are never a program (:func:`archive_parts`, used by
   :func:`folder_groups`).

:func:`find_backups` lists the backup roots below a folder; :func:`backup_of` answers rule 2.
"""

from __future__ import annotations

import functools
import os
import stat
import time
from dataclasses import dataclass, field
from pathlib import Path

from krl import files as _files   # the one folder walk (called through the module: tests count its calls)
from krl.files import Entry
from krl.limits import MAX_FOLDER_DEPTH
from krl.source import is_krl_file

__all__ = ["ARCHIVE_PARTS", "ProgramFiles", "SYSTEM_DIRS", "archive_parts", "backup_of", "cell_program", "collect_entries", "collect_files", "config_file", "find_backups",
           "folder_entries", "folder_groups", "header_folder", "header_folder_of", "header_lines", "is_submit_file", "is_system_path", "kuka_folder", "machine_data_file", "module_key",
           "modules_of", "program_folder", "project_of", "system_folder", "system_folder_of", "with_basis"]

#: KUKA's system folders of a backup (rule 7), lower case
SYSTEM_DIRS = ("system", "tp", "mada", "steu")
#: the folders of a controller archive beside its ``KRC`` folder that hold no program (rule 8):
#: the controller's configuration and templates, the logbook; lower case
ARCHIVE_PARTS = ("c", "log files")
#: the manifests a controller archive's folder holds (rule 8; krl/kssarchive.py reads them), lower case
ARCHIVE_MANIFESTS = ("am.ini", "archiveinfo.xml")


@dataclass
class ProgramFiles:
    """The files of one program (rule 3). ``root``: the backup root or the folder; ``backup``:
    True inside a KRC backup; ``system``: the backup's System folder (None outside a backup);
    ``entries``: the walk of ``root`` (:class:`krl.files.Entry`: files, and the entries not read)."""
    root: Path
    backup: bool
    system: Path | None
    entries: list[Entry] = field(default_factory=list)

    @property
    def files(self) -> list[Path]:
        """The regular KRL files, in walk order."""
        return [e.path for e in self.entries if e.kind == "file"]


def _is_dir(p: Path | None) -> bool:
    return p is not None and not p.is_symlink() and p.is_dir()


def _is_base(folder: Path) -> bool:
    """Rule 1: `folder` holds ``System/$config.dat``, or is the ``R1`` of an archive's ``KRC``
    folder (beside ``STEU``, holding ``Program``, ``System`` or ``Mada``); any case, no links."""
    system = _files.child(folder, "system")
    if _is_dir(system):
        config = _files.child(system, "$config.dat")
        if config is not None and not config.is_symlink() and config.is_file():
            return True
    if folder.name.lower() != "r1" or not _is_dir(_files.child(folder.parent, "steu")):
        return False
    return any(_is_dir(_files.child(folder, n)) for n in ("program", "system", "mada"))


def _root_of_base(base: Path) -> Path:
    return base.parent if base.name.lower() == "r1" else base


def backup_of(path: str | Path, within: str | Path | None = None) -> Path | None:
    """Rule 2: the root of the outermost KRC backup holding `path` (a file or folder), else
    None. With `within`, only folders inside it (itself included) are looked at."""
    path = Path(path)
    folders = [path, *path.parents] if path.is_dir() and not path.is_symlink() else list(path.parents)
    if within is not None:
        w = Path(within)
        folders = [d for d in folders if d == w or w in d.parents]
    found = None
    for d in folders:
        if _is_base(d):
            root = _root_of_base(d)
            if within is None or root == Path(within) or Path(within) in root.parents:
                found = root
            else:
                found = d
        else:
            r1 = _files.child(d, "r1")       # a file beside R1 (STEU/, KRC/): the backup holding R1
            if r1 is not None and r1.is_dir() and not r1.is_symlink() and _is_base(r1):
                found = d
    return found


def system_folder(root: Path) -> Path | None:
    """The System folder of the backup rooted at `root` (``R1/System`` or ``System``)."""
    r1 = _files.child(root, "r1")
    for base in ([r1] if r1 is not None else []) + [root]:
        if _is_base(base):
            return _files.child(base, "system")
    return None


def program_folder(root: Path) -> Path | None:
    """The folder of the programs an operator selects at the pendant: ``R1/Program`` of the
    backup rooted at `root` (``Program`` of a flat export), any letter case, links never
    followed; None when the backup has none."""
    sysdir = system_folder(root)
    if sysdir is None:
        return None
    f = _files.child(sysdir.parent, "program")
    return f if f is not None and not f.is_symlink() and f.is_dir() else None


def machine_data_file(root: Path) -> Path | None:
    """The robot's machine data of the backup rooted at `root`: ``R1/Mada/$machine.dat`` (or
    ``Mada/$machine.dat`` of a flat export), any letter case, links never followed; None when
    the backup has none (robot/mada.py builds the robot model from it)."""
    r1 = _files.child(root, "r1")
    for base in ([r1] if r1 is not None else []) + [root]:
        if base.is_symlink() or not base.is_dir():
            continue
        mada = _files.child(base, "mada")
        if mada is None or mada.is_symlink() or not mada.is_dir():
            continue
        f = _files.child(mada, "$machine.dat")
        if f is not None and not f.is_symlink() and f.is_file():
            return f
    return None


def config_file(root: Path) -> Path | None:
    """The ``$config.dat`` of the backup or program folder rooted at `root`: its System
    folder's (``R1/System`` or ``System``), else the one at `root`'s top (a flat layout: the
    backup's files in one folder, issue 85 item 6); any letter case, links never followed; None
    when there is none."""
    sysdir = system_folder(root)
    for folder in ([sysdir] if sysdir is not None else []) + [root]:
        f = _files.child(folder, "$config.dat")
        if f is not None and not f.is_symlink() and f.is_file():
            return f
    return None


def cell_program(root: Path) -> Path | None:
    """The backup's cell program, which the controller selects in Automatic External (KUKA System
    Software 8: the external PLC starts ``CELL.SRC``): ``R1/cell.src`` (or ``cell.src`` at a flat
    export's top), beside its System folder; any letter case, links never followed; None when the
    backup has none."""
    sysdir = system_folder(root)
    r1 = _files.child(root, "r1")
    base = sysdir.parent if sysdir is not None else r1 if r1 is not None else root
    f = _files.child(base, "cell.src")
    return f if f is not None and not f.is_symlink() and f.is_file() else None


def submit_program(root: Path) -> Path | None:
    """The backup's submit program, which the controller starts at boot (reference §9):
    ``R1/SPS.SUB`` (or ``SPS.SUB`` at a flat export's top), else ``SPS.SUB`` in its System
    folder; any letter case, links never followed; None when the backup has none."""
    sysdir = system_folder(root)
    if sysdir is None:
        return None
    for d in (sysdir.parent, sysdir):
        f = _files.child(d, "sps.sub")
        if f is not None and not f.is_symlink() and f.is_file():
            return f
    return None


def boot_submit(program: str | Path, within: str | Path | None = None) -> Path | None:
    """The submit program that runs beside `program` as the controller starts it at boot:
    the :func:`submit_program` of the KRC backup holding it (:func:`backup_of`); None outside
    a backup, when the backup has none, or when `program` is that submit program itself."""
    prog = _files.spelled_within(program, within)
    root = backup_of(prog, _files.spelled(within) if within else None)
    sub = submit_program(root) if root is not None else None
    return sub if sub is not None and not _files.same_file(sub, prog) else None


def project_of(path: str | Path, within: str | Path | None = None, limit: int | None = None,
               max_entries: int | None = None) -> ProgramFiles:
    """Rule 3: the program of the file `path` (``krl run``, ``krl check FILE``, the language
    server's open file). `within`: the folder the caller names (``--workspace``, the editor's
    folder). `limit`, `max_entries`: stop the walk after that many KRL files / entries looked
    at (the language server's bounds, krl.limits.MAX_LSP_*). `path` itself is always among
    the files (it may be an unsaved editor buffer)."""
    path = Path(path)
    root = backup_of(path, within)
    if root is not None:
        project = ProgramFiles(root, True, system_folder(root))
    else:
        folder = Path(within) if within is not None else path.parent
        project = ProgramFiles(folder, False, None)
    entries = list_entries(project.root, limit, max_entries)
    if root is None and any(e.kind == "file" and e.path.name.lower() == "$config.dat"
                            and e.path.parent.name.lower() == "system" for e in entries):
        # rule 6: the folder holds backups; a file outside them belongs to its top-level group
        try:
            rel = path.relative_to(project.root)
        except ValueError:
            rel = Path(path.name)
        if len(rel.parts) > 1:
            project.root = project.root / rel.parts[0]
            entries = [e for e in entries if e.rel.split("/")[0] == rel.parts[0] and "/" in e.rel]
        else:
            entries = [e for e in entries if "/" not in e.rel]
    project.entries = entries
    if path not in project.files:
        project.entries.append(Entry(path, path.name, "file"))
    return project


class _Budget(Exception):
    """The walk looked at `max_entries` entries."""


def list_entries(folder: Path, limit: int | None = None, max_entries: int | None = None) -> list[Entry]:
    """The KRL entries below `folder` in walk order (krl.files.walk), up to `limit` KRL files,
    looking at no more than `max_entries` entries (None: no bound)."""
    if limit is None and max_entries is None:
        return _kept_entries(folder)
    seen = 0

    def match(name: str) -> bool:
        nonlocal seen
        seen += 1
        if max_entries is not None and seen > max_entries:
            raise _Budget
        return is_krl_file(Path(name))

    out: list[Entry] = []
    files = 0
    try:
        for e in _files.walk(folder, match=match):
            out.append(e)
            files += e.kind == "file"
            if limit is not None and files >= limit:
                break
    except _Budget:
        pass
    return out


@functools.lru_cache(maxsize=16384)
def system_folder_of(path: str | Path) -> str | None:
    """The KUKA system folder (rule 7, lower case: ``"system"``, ``"tp"``, ``"mada"``,
    ``"steu"``) that a file `path` lies in (any of its folders), else None. Remembered per path
    (a check asks for each file many times; a path is parsed in ~30 us)."""
    for part in Path(path).parts[:-1]:
        if part.lower() in SYSTEM_DIRS:
            return part.lower()
    return None


#: bytes of a file's start read for its header lines (rule 7); KUKA's headers are 1-6 short lines
HEADER_BYTES = 2048
#: the header lines the header rule reads (reference 1.3: ``&`` in column 1, before DEF/DEFDAT)
HEADER_LINES = 20


def header_lines(head: str) -> list[str]:
    """The header lines at the start `head` of a KRL file (reference 1.3: lines starting with
    ``&`` in column 1 before ``DEF``/``DEFDAT``; blank lines skipped), at most
    :data:`HEADER_LINES`, stripped."""
    out: list[str] = []
    for line in head.splitlines()[:HEADER_LINES]:
        if line.startswith("&"):
            out.append(line.strip())
        elif line.strip():
            break
    return out


def header_folder_of(head: str) -> str | None:
    """The KUKA system folder the header lines of a file's start `head` place it in (rule 7),
    else None: from ``&PARAM DISKPATH = KRC:\\R1\\TP\\BrakeTest`` (the controller's own
    record of the folder it keeps the file in; a folder of :data:`SYSTEM_DIRS` among its parts,
    lower case), or ``"kuka"`` for KUKA's delivery header, ``&ACCESS`` without ``V`` (a module
    not visible to the operator) together with a non-empty ``&COMMENT`` title (``&ACCESS R4``,
    ``&COMMENT BASIS package``; no folder named). Read on the corpus and history (2026-11-28):
    the 122 files whose DISKPATH names a system folder and the 115 read-only titled files all lie
    in KUKA's system folders; the 196 read-only files outside them (hand-written libraries)
    have no title or an empty one."""
    hidden = titled = False
    for line in header_lines(head):
        word, _, rest = line[1:].partition(" ")
        word, rest = word.upper(), rest.strip()
        if word == "PARAM":
            key, eq, value = rest.partition("=")
            if eq and key.strip().upper() == "DISKPATH":
                folder = system_folder_of(value.strip().replace("\\", "/").replace(":", "/") + "/x")
                if folder is not None:
                    return folder
        elif word == "ACCESS":
            hidden = bool(rest) and "V" not in rest.upper()
        elif word == "COMMENT":
            titled = titled or bool(rest)
    return "kuka" if hidden and titled else None


def header_folder(path: str | Path) -> str | None:
    """:func:`header_folder_of` the first :data:`HEADER_BYTES` of the file `path` (latin-1, as
    KUKA writes; links are not followed), None when it cannot be read."""
    try:
        p = Path(path)
        if p.is_symlink() or not p.is_file():
            return None
        with p.open("rb") as f:
            head = f.read(HEADER_BYTES).decode("latin-1")
    except OSError:
        return None
    return header_folder_of(head)


def kuka_folder(path: str | Path, root: str | Path | None = None) -> str | None:
    """Rule 7, whole: the KUKA system folder a file `path` is kept in, lower case -- the one it
    lies in (:func:`system_folder_of`, of its path below `root` when given: a backup under a
    folder named ``System`` is not KUKA's for that), else the one its own header lines name
    (:func:`header_folder`: a folder of :data:`SYSTEM_DIRS`, or ``"kuka"`` for KUKA's delivery
    header, which names none) -- else None (the user's file). The one answer for the entry points
    (interp/realprograms.py) and the cell starter (interp/cellinit.py), in both layouts."""
    p = Path(path)
    rel = p
    if root is not None:
        try:
            rel = p.relative_to(root)
        except ValueError:
            pass
    return system_folder_of(rel) or header_folder(p)


@functools.lru_cache(maxsize=16384)
def is_system_path(path: str) -> bool:
    """True for KUKA system files of a backup (rule 7, or a $-file): they rely on $operate.dat
    declarations that a backup never contains (see W101/W105/W106). Remembered per path (the
    checker asks for each file's symbols: 180 times per check of a backup's program,
    krl/survey/mutants.py; 35 us a call)."""
    return Path(path).name.startswith("$") or system_folder_of(path) is not None


def is_submit_file(path: str | Path) -> bool:
    """True for a submit program's file (``.sub``, any case; rule 5)."""
    return str(path).lower().endswith(".sub")


def module_key(path: str | Path) -> tuple[str, str]:
    """What the files of one module share (rule 5): their folder and name, any case."""
    return _module_of(str(path))[0]


@functools.lru_cache(maxsize=16384)
def _module_of(path: str) -> tuple[tuple[str, str], str, bool]:
    """(:func:`module_key`, the stem as written, whether the name ends in ``.dat``, any case) of
    the file `path`; remembered per path (a check of a backup's program asks for each of its
    files: 28 us a call)."""
    p = Path(path)
    return (str(p.parent).lower(), p.stem.lower()), p.stem, p.suffix.lower() == ".dat"


def modules_of(paths, is_data=None) -> list[tuple[str, object, object]]:
    """Rule 5: the modules of `paths` (file paths, or objects with a ``path``), in the order of
    their first file: ``(name, code file or None, data list file or None)``, where the name is
    the stem of the module's first file. `is_data(f)`: True for a file that is a data list
    whatever its name (a parsed ``DEFDAT``); by default a ``.dat`` file is one."""
    def path_of(x) -> str:
        return x if isinstance(x, (str, Path)) else x.path

    by_key: dict[tuple[str, str], list] = {}
    out: list[list] = []
    for f in paths:
        key, stem, dat = _module_of(str(path_of(f)))
        unit = by_key.get(key)
        if unit is None:
            unit = by_key[key] = [stem, None, None]
            out.append(unit)
        if dat or (is_data is not None and is_data(f)):
            if unit[2] is None:
                unit[2] = f
        elif unit[1] is None:
            unit[1] = f
        else:          # NAME.src and NAME.sub: the second code file is a module of its own
            out.append([stem, f, None])
    return [tuple(u) for u in out]


def module_files(path: str | Path, paths) -> list:
    """The files of `path`'s module among `paths` (rule 5): its code file and data list."""
    p = str(Path(path))
    for _name, code, dat in modules_of(paths):
        files = [f for f in (code, dat) if f is not None]
        if any(str(Path(f if isinstance(f, (str, Path)) else f.path)) == p for f in files):
            return files
    return [path]


def with_basis(project: ProgramFiles, basis: list[Path]) -> list[Path]:
    """Rule 4: the files of the project's BASIS (`basis`: its files, in order) that a program
    outside a backup adds to its own, after them; none inside a backup. The BASIS
    ``$config.dat`` is always added (it merges with the program's own); another BASIS file only
    when the program has no module of its name (its own ``bas.src`` replaces the BASIS's)."""
    if project.backup:
        return []
    own = {f.stem.lower() for f in project.files}
    return [f for f in basis if f.name.lower() == "$config.dat" or f.stem.lower() not in own]


def find_backups(root: str | Path) -> list[Path]:
    """The backup roots below `root` (rule 1 and 2: a backup inside another is part of it),
    sorted. The walk is krl.files.walk: iterative, links never followed."""
    root = Path(root)
    if not root.is_dir():
        return []
    return _backups_in(_files.walk(root, match=lambda n: n.lower() == "$config.dat"))


def _backups_in(entries) -> list[Path]:
    """:func:`find_backups` from the entries of a walk (krl.files.walk) of the folder: its
    regular files named $config.dat in folders at most MAX_FOLDER_DEPTH levels deep: in a
    ``System`` folder, or in the ``STEU`` folder beside an archive's ``R1`` (rule 1)."""
    found: set[Path] = set()
    for e in entries:
        if e.kind != "file" or e.path.name.lower() != "$config.dat" or _levels(e.rel) - 1 > MAX_FOLDER_DEPTH:
            continue
        system = e.path.parent
        if system.name.lower() == "steu":
            r1 = _files.child(system.parent, "r1")
            if r1 is not None and _is_base(r1):
                found.add(system.parent)
            continue
        if system.name.lower() != "system":
            continue
        found.add(_root_of_base(system.parent))
    # a root below another is part of it: each root's own parents looked up in the set (the
    # pairwise test of every two roots took 10 s for a folder of a few hundred backups)
    return sorted(r for r in found if not any(p in found for p in r.parents))


def _levels(rel: str) -> int:
    """Folder levels of a walk entry's `rel` below the walk's root ("" and "." are the root)."""
    return 0 if rel in ("", ".") else rel.count("/") + 1


def group_walk(path: Path) -> list:
    """The one walk of the folder `path` that :func:`folder_groups` splits (krl.files.walk, deep
    enough for every root's own limit, folders listed), its ``.zip`` files listed too
    (krl/backups.py reads a folder's archives from the same walk)."""
    return list(_files.walk(path, match=lambda n: is_krl_file(Path(n)) or n.lower().endswith(".zip"),
                            max_depth=2 * MAX_FOLDER_DEPTH + 1, folders=True))


def _zip_entry(e) -> bool:
    return e.kind != "folder" and e.path.name.lower().endswith(".zip") and not is_krl_file(e.path)


def folder_groups(path: str | Path, walked: list | None = None) -> list[tuple[str, list]] | None:
    """Rule 6, from one walk of the folder (krl.files.walk): the (root, entries) groups -- one
    per backup (:func:`find_backups`), then one per top-level folder for the entries outside
    every backup, sorted; a folder without backups is one group. The entries are those that
    :func:`collect_entries` of each root gives (each root's own MAX_FOLDER_DEPTH, its own
    ``rel``). None when `path` is not a folder (or is a link)."""
    p = Path(path)
    if not p.is_dir() or p.is_symlink():
        return None
    # deep enough for every root's own limit: a backup root is at most MAX_FOLDER_DEPTH levels
    # down; folder events are kept only where some root's limit may cut (past MAX_FOLDER_DEPTH);
    # `walked`: that walk made already (:func:`group_walk`, krl/backups.py ``opened``)
    entries = [e for e in (walked if walked is not None else group_walk(p))
               if not _zip_entry(e) and (e.kind != "folder" or _levels(e.rel) > MAX_FOLDER_DEPTH)]
    backups = _backups_in(entries)
    parts = [a.relative_to(p).as_posix() for a in archive_parts(p, backups) if p in a.parents]
    if parts:       # rule 8: an archive's configuration and logbook are no program
        entries = [e for e in entries if not any(e.rel == a or e.rel.startswith(a + "/") for a in parts)]
    whole = _as_walk_of(entries, "")
    if not backups:
        return [(str(p), whole)]
    groups = []
    prefixes = []
    for b in backups:
        rel = b.relative_to(p).as_posix()
        rel = "" if rel == "." else rel
        prefixes.append(rel)
        groups.append((str(b), _as_walk_of(
            [e for e in entries if not rel or e.rel == rel or e.rel.startswith(rel + "/")], rel)))
    # entries outside every backup: one program per top-level folder of `path`
    rest: dict[str, list] = {}
    for e in whole:
        if any(not r or e.rel == r or e.rel.startswith(r + "/") for r in prefixes):
            continue
        parts = e.rel.split("/")
        key = str(p / parts[0]) if len(parts) > 1 else str(p)
        rest.setdefault(key, []).append(e)
    return groups + sorted(rest.items())


def archive_parts(folder: Path, backups: list[Path]) -> list[Path]:
    """Rule 8: the folders below `folder` (itself included) that are a controller archive's
    ``C`` or ``Log Files`` (any case, links never followed): those beside a backup root named
    ``KRC`` among `backups` (the roots of :func:`find_backups`), or beside an archive's manifest."""
    archives = {b.parent for b in backups if b.name.lower() == "krc" and (b.parent == folder or folder in b.parent.parents)}
    if any(_files.child(folder, n) is not None for n in ARCHIVE_MANIFESTS):
        archives.add(folder)
    out = []
    for a in sorted(archives):
        for name in ARCHIVE_PARTS:
            part = _files.child(a, name)
            if _is_dir(part):
                out.append(part)
    return out


def _as_walk_of(entries: list, rel: str) -> list:
    """The entries a walk of the folder `rel` (of a deeper walk with folder events) would have
    given: ``rel`` relative to it, folders past MAX_FOLDER_DEPTH below it ``too_deep`` and not
    entered, folder events dropped."""
    base = _levels(rel)
    cut = len(rel) + 1 if rel else 0
    out = []
    pruned = None
    for e in entries:
        if pruned is not None and (e.path == pruned or pruned in e.path.parents):
            continue
        pruned = None
        own = e.rel[cut:] if cut and e.rel != rel else (e.rel if not cut else ".")
        if e.kind == "folder":
            if _levels(e.rel) - base > MAX_FOLDER_DEPTH:
                out.append(Entry(e.path, own, "too_deep"))
                pruned = e.path
            continue
        out.append(e if not cut else Entry(e.path, own, e.kind, e.detail, e.size))
    return out


def folder_entries(folder: Path) -> list:
    """The KRL entries (:class:`krl.files.Entry`) of `folder` in walk order, as ``krl check``,
    ``krl fmt`` and ``krl recover`` walk a folder they are given (a folder named through a link
    is walked; krl/files.py: links inside listed, never followed; unreadable or too deep folders
    listed), without a controller archive's ``C`` and ``Log Files`` folders (rule 8,
    :func:`archive_parts`: KUKA's templates and configuration are no program of the backup;
    naming such a folder itself walks it)."""
    folder = Path(folder)
    return _without_archive_parts(folder, list(_files.walk(folder)))


def _without_archive_parts(folder: Path, entries: list) -> list:
    """The `entries` of a walk of `folder` without those in its controller archives' ``C`` and
    ``Log Files`` folders (:func:`folder_entries`)."""
    parts = [a.relative_to(folder).as_posix() for a in archive_parts(folder, _backups_in(entries))
             if folder in a.parents]
    if parts:
        entries = [e for e in entries if not any(e.rel == a or e.rel.startswith(a + "/") for a in parts)]
    return entries


def collect_entries(path: Path) -> list:
    """The KRL entries (:class:`krl.files.Entry`) of a file or folder, in walk order: a folder is
    walked (krl/files.py: links and FIFOs listed, never read; unreadable or too deep folders
    listed); anything else that exists is one ``file`` entry, classified when it is read."""
    path = Path(path)
    if path.is_dir() and not path.is_symlink():
        return folder_entries(path)
    if path.is_symlink() and path.is_dir():
        return [Entry(path, path.name, "symlink")]
    return [Entry(path, path.name, "file")]


#: folder (as given) -> (((folder, (device, inode, modification and change times in ns)), ...)
#: of every folder its walk entered, its entries): :func:`_kept_entries`'s, at most
#: :data:`_KEPT_FOLDERS` (the oldest goes first), each of at most :data:`_KEPT_ENTRIES` entries
_KEPT: dict[str, tuple] = {}
_KEPT_FOLDERS = 64
_KEPT_ENTRIES = 20_000


def _kept_entries(folder: Path) -> list:
    """:func:`collect_entries` of `folder` (a project's, :func:`list_entries`), its walk kept and
    given again while it is the folder's as it is now: every folder the walk entered has the
    identity and the times it had when listed (adding, removing or renaming an entry, or
    changing who may read a folder, changes them; a folder changed just before its listing is
    never kept: krl/files.py ``_settled``, as ``child`` keeps a listing) and every file listed
    is still a regular file of the size listed (a file written in place keeps its folder's
    times). A run lists its program's project at each start (krl run, interp/runtime/program.py
    ``program_files``): ChinaMilling's backup, 156 files in 29 folders, took 2.2 ms of CPU, its
    check 0.5 ms (2026-11-29, load 9)."""
    path = Path(folder)
    key = str(path)
    kept = _KEPT.get(key)
    if kept is not None:
        stamps, entries = kept
        if all(_stamp(f)[0] == ident for f, ident in stamps) and \
                all(_file_size(e.path) == e.size for e in entries if e.kind == "file"):
            return list(entries)
        _KEPT.pop(key, None)
    if not (path.is_dir() and not path.is_symlink()):
        return collect_entries(path)
    listed_at = time.time_ns()
    stamps = []
    settled = True

    def walk():
        nonlocal settled
        for e in _files.walk(path, folders=True):
            if e.kind == "folder":          # (stamped before it is listed)
                ident, st = _stamp(str(e.path))
                settled = settled and st is not None and _files._settled(st, listed_at)
                stamps.append((str(e.path), ident))
            else:
                yield e
    entries = _without_archive_parts(path, list(walk()))
    if settled and len(entries) <= _KEPT_ENTRIES:
        while len(_KEPT) >= _KEPT_FOLDERS:
            _KEPT.pop(next(iter(_KEPT), None), None)
        _KEPT[key] = (tuple(stamps), tuple(entries))
    return entries


def _stamp(folder: str) -> tuple:
    """(identity, stat result) of `folder` for :func:`_kept_entries` (device, inode, times in ns,
    mode), links not followed; (None, None) when it cannot be read."""
    try:
        st = os.stat(folder, follow_symlinks=False)
    except OSError:
        return None, None
    return (st.st_dev, st.st_ino, st.st_mtime_ns, st.st_ctime_ns, st.st_mode), st


def _file_size(path) -> int:
    """The size of the regular file `path` (links not followed), else -1."""
    try:
        st = os.lstat(path)
    except OSError:
        return -1
    return st.st_size if stat.S_ISREG(st.st_mode) else -1


def collect_files(path: Path) -> list[Path]:
    """KRL files (.src, .dat, .sub in any case) of a file or folder, in walk order (regular
    files only; see :func:`collect_entries` for the rest)."""
    return [e.path for e in collect_entries(path) if e.kind == "file"]
