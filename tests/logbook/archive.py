"""A small controller archive as KUKA writes it (the layout of ../shared/event-logs/README.md),
built in a test's temporary folder: am.ini, ArchiveInfo.xml, KRC/R1 (cell.src, Program, System,
Mada), KRC/STEU, C/KRC/Roboter/Config, Log Files. Its KRL is written here by hand, each line
whose number a test expects marked in :data:`LINES`; its event logs are copies of the shared
archive's logs (read in place from ../shared/event-logs, copied only into the temporary folder)."""

from __future__ import annotations

import shutil
import zipfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]

CONFIG_DAT = """DEFDAT $CONFIG
; the cell's counters, global: the cell program and B1 use them
DECL GLOBAL INT b1_parcasirasi=1
DECL GLOBAL INT b1_parcakatsayisi=1
ENDDAT
"""
CELL_SRC = """DEF CELL()
  B1_Parca_Birakma()
  B3_Parca_Birakma()
END
"""
B1_SRC = """DEF B1_Parca_Birakma()
  b1_parcasirasi = b1_parcasirasi + 1
END
"""
B3_SRC = """DEF B3_Parca_Birakma()
  DECL REAL parcagenislik
  parcagenislik = 12.5
  b3_parcasirasi = b3_parcasirasi + b3_parcakatsayisi
END
"""
B3_DAT = """DEFDAT B3_Parca_Birakma
; the part counters the operator sets from the pendant
DECL INT b3_parcasirasi=1
DECL INT b3_parcakatsayisi=1
ENDDAT
"""

#: where each variable is declared, by hand from the texts above: (file in the archive, line)
CONFIG = "KRC/R1/System/$config.dat"
B3_DAT_PATH = "KRC/R1/Program/Parca_Birakma/B3_Parca_Birakma.dat"
B3_SRC_PATH = "KRC/R1/Program/Parca_Birakma/B3_Parca_Birakma.src"
B1_SRC_PATH = "KRC/R1/Program/Parca_Birakma/B1_Parca_Birakma.src"
CELL_PATH = "KRC/R1/cell.src"
LINES = {"b1_parcasirasi": (CONFIG, 3), "b1_parcakatsayisi": (CONFIG, 4),
         "b3_parcasirasi": (B3_DAT_PATH, 3), "b3_parcakatsayisi": (B3_DAT_PATH, 4),
         "parcagenislik": (B3_SRC_PATH, 2)}
#: the modules the archive holds: upper-case name -> code file
MODULES = {"CELL": CELL_PATH, "B1_PARCA_BIRAKMA": B1_SRC_PATH, "B3_PARCA_BIRAKMA": B3_SRC_PATH}

AM_INI = """[Archive]
ID=00000000-0000-0000-0000-000000000075
Date=2026-11-27_01-00-00
[Roboter]
RobName=Test_Cell_75
IRSerialNr=750075
[Version]
Version=V8.7.8
[TechPacks]
TechPacks=KUKA.PROFINET MS|KUKA.UpdateService|
KUKA.PROFINET MS=6.0.8
KUKA.UpdateService=1.1.24
"""
ARCHIVE_INFO = """<ArchiveInformation xmlns="KUKARoboter.Contracts.Archive">
  <Archive><Date>2026-11-27T01:00:00+00:00</Date><Id>00000000-0000-0000-0000-000000000075</Id>
    <Configuration><LogConfig><ProtokollNames><string>KrcLogB</string><string>KrcLogI</string>
    </ProtokollNames></LogConfig></Configuration></Archive>
  <Roboter><Name>Test_Cell_75</Name><Serialnumber>750075</Serialnumber><Type>#KR180R3200PA C4 FLR</Type></Roboter>
  <System><Version>V8.7.8</Version><Build>671</Build></System>
  <Options><OptionData Name="KUKA.PROFINET MS"><Version Build="8" Major="6" Minor="0" Revision="45" /></OptionData></Options>
</ArchiveInformation>
"""


def write_files(root: Path, files) -> Path:
    """Each (path relative to `root`, text) of `files` written under `root` as the controller
    writes its files (UTF-8, CRLF line ends), folders made as needed; `root` returned."""
    for rel, text in files:
        p = root / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(text, encoding="utf-8", newline="\r\n")
    return root


def build_archive(root: Path, logs_from: Path | None, logs: tuple[str, ...] = ()) -> Path:
    """The archive folder `root` (created): the files above, the robot's machine data (the
    project's KR 180 R3200 PA, robot/data) in KRC/R1/Mada, and the `logs` of `logs_from` copied
    into ``Log Files``."""
    write_files(root, ((CONFIG, CONFIG_DAT), (CELL_PATH, CELL_SRC), (B1_SRC_PATH, B1_SRC), (B3_SRC_PATH, B3_SRC),
                       (B3_DAT_PATH, B3_DAT), ("am.ini", AM_INI), ("ArchiveInfo.xml", ARCHIVE_INFO),
                       ("KRC/STEU/$config.dat", "DEFDAT $CONFIG\nENDDAT\n"),
                       ("C/KRC/Roboter/Config/User/Common/readme.txt", "WorkVisual's configuration\n"),
                       ("Archive.log", "archived\n")))
    mada = root / "KRC" / "R1" / "Mada"
    mada.mkdir(parents=True)
    shutil.copyfile(REPO / "robot" / "data" / "kr180_r3200_pa.dat", mada / "$machine.dat")
    folder = root / "Log Files"
    folder.mkdir()
    for name in logs:
        shutil.copyfile(logs_from / name, folder / name)
    return root


def zip_folder(folder: Path, archive: Path) -> Path:
    """`folder` zipped as the controller's archive.zip (entries relative to the folder)."""
    with zipfile.ZipFile(archive, "w", zipfile.ZIP_DEFLATED) as zf:
        for p in sorted(folder.rglob("*")):
            if p.is_file():
                zf.write(p, p.relative_to(folder).as_posix())
    return archive


#: KUKA's program templates as KSS 8 keeps them in ``C/KRC/Roboter/Template`` (issue 85 item 3:
#: the archive's ``C`` folder holds them; the controller offers them when a module is created,
#: it never runs them): written here by hand, shaped as KUKA's module templates are
TEMPLATES = (("C/KRC/Roboter/Template/vorgabe.src", "DEF vorgabe()\n  INI\n  PTP HOME\nEND\n"),
             ("C/KRC/Roboter/Template/vorgabe.dat", "DEFDAT vorgabe\nENDDAT\n"),
             ("C/KRC/Roboter/Template/FUNCTION.src", "DEFFCT INT function()\n  RETURN 0\nENDFCT\n"),
             ("C/KRC/Roboter/Template/cell.src", "DEF CELL()\n  LOOP\n  ENDLOOP\nEND\n"))
#: a binary file of the controller's PROFINET configuration under ``C`` (issue 85 item 3: "a binary
#: PROFINET file under C/"; its real name is not known here: a KRL suffix, as the one that made
#: `krl check` fail must have had, since only KRL files are checked)
PROFINET = "C/KRC/Roboter/Config/User/Common/Profinet/PNIO_DEV.dat"
PROFINET_BYTES = bytes(range(256)) * 4


def build_kss_archive(root: Path, logs_from: Path | None, logs: tuple[str, ...] = ("KrcLogI.evt",)) -> Path:
    """The archive of :func:`build_archive` with what a KSS 8.7.8 archive's ``C`` folder holds
    besides (../shared/event-logs/README.md): KUKA's templates (:data:`TEMPLATES`) and a binary
    PROFINET file (:data:`PROFINET`); `root` returned."""
    build_archive(root, logs_from, logs)
    write_files(root, TEMPLATES)
    (root / PROFINET).parent.mkdir(parents=True, exist_ok=True)
    (root / PROFINET).write_bytes(PROFINET_BYTES)
    return root


def build_fleet(folder: Path, logs_from: Path | None, names=("cell_a", "cell_b")) -> Path:
    """`folder` (created) holding one zipped archive of :func:`build_kss_archive` per name
    (``cell_a.zip``, ``cell_b.zip``): controller archives as they are kept."""
    folder.mkdir(parents=True, exist_ok=True)
    for name in names:
        made = build_kss_archive(folder.parent / f"{folder.name}-{name}", logs_from)
        zip_folder(made, folder / f"{name}.zip")
        shutil.rmtree(made)
    return folder
