"""Every size and depth limit on untrusted input, in one place (docs/security.md lists them).

Each limit is a named constant; going past one is a normal error with a message and a place
(file:line:col), never a crash. Commands and both interpreters read the limits from here, so one
number holds everywhere. Add a limit here, with its unit and the reason for its value, and a row in
docs/security.md.
"""

from __future__ import annotations

# The nesting budget, shared by every command and both interpreters: the deepest nesting of
# blocks (IF, FOR, WHILE, LOOP, REPEAT, SWITCH, SPLINE, ...) and brackets in expressions, counted
# together, in levels. Real KRL nests a few levels (the corpus's deepest file is far below this);
# C requires compilers to accept 127 nested blocks and 63 nested parentheses, which is the order
# of magnitude chosen here. Past it: "nesting too deep" at the opener that went past it.
MAX_NESTING = 100

# The deepest nesting of KRL routine calls at run time (both interpreters, interrupt routines
# included). The reference (§8.2) leaves the limit open and suggests about 100 levels; real
# programs call a few levels deep. Past it: the run-time error "stack overflow: more than 100
# nested calls" at the call (interp/runtime/core.py).
MAX_CALL_DEPTH = 100

# The largest source file read, in bytes (krl/source.py).
MAX_FILE_BYTES = 10 * 1024 * 1024

# The longest message printed, in characters: a diagnostic's message (krl parse, krl check, the
# language server), a line of the run summary (krl run), and the part of a source line shown
# around a caret. Untrusted text (a 10 MB line, a string SWRITE built) never floods a terminal or
# a report; longer text is cut by krl.terminal.clip, ending in "…".
MAX_MESSAGE_CHARS = 160

# The most operands (terms) in one statement's expressions, counted on its line: `a + b * c` has
# 3. Real KRL stays far below (long conditions have a few dozen terms); the limit keeps the parse
# tree and the AST bounded: a chain of binary operators nests one level per operator (in
# Binary.left), and every stage walks such a chain in a loop (krl.ast.nodes.left_chain: the
# builder, the checker, the printer, pickling, both interpreters), so its length costs no stack.
# Past it: error E019 "expression too long" at the statement's line (the file does not parse;
# the program does not start).
MAX_EXPRESSION_TERMS = 500

# One KRL expression given on its own, outside a program's text (krl/semantics/expression.py:
# a debugger's watch, condition or new value, the pendant's watch list): one line of at most
# this many characters and tokens (nesting and terms as in a program: MAX_NESTING,
# MAX_EXPRESSION_TERMS). A cell rule's condition has its own, smaller MAX_RULE_TOKENS. Past
# either: "not a KRL expression: ..." / "an expression is at most ... characters".
MAX_EXPRESSION_CHARS = 4096
MAX_EXPRESSION_TOKENS = 2048

# The Python stack that parsing, building and checking one file within the limits above may
# take, in frames above the caller. Only MAX_NESTING levels recurse (blocks, brackets, prefix
# operators; never the terms of a chain): measured at most 5.25 frames per level (100 nested IFs
# take 525 frames, 100 brackets around 499 terms 325), so 600 leaves a margin, and Python's
# default recursion limit of 1000 frames leaves 400 to the caller (the command line, the
# language server). tests/frontend/test_long_expressions.py checks the deepest legal files
# within it. The parser's limits keep every file below it; were it ever passed, the routine gets
# E901 "routine nested too deeply to check" (the builder E003), never a crash.
MAX_CHECK_FRAMES = 600

# The deepest folder a walk of a corpus or a KRC backup enters (krl/files.py), in folder levels
# below the root. Real backups are about 6 levels deep (KRC/R1/Program/<cell>/<folder>); the walk is
# iterative, so the limit keeps paths and report rows readable, not the stack safe. Past it: the
# folder is listed as a row / warning "too_deep" and not entered.
MAX_FOLDER_DEPTH = 100

# The time one file may take to parse (krl recover, krl parse, krl check), in seconds of wall time
# in a worker process; past it the worker is killed and the file gets a "timeout" row / error.
# The largest corpus file (about 150 KB) parses in about a second; a 9.5 MB file took over 300 s.
PARSE_TIMEOUT_S = 30

# KRC backup archives (.zip) given to `krl check`, `krl recover` and `krl run` (krl/archive.py).
# Every entry is inspected before anything is written; past a limit the archive is refused with
# an error naming it and the entry (code E004), and nothing of it is read.
# Entries (files and folders) in one archive: a KRC 4 backup holds a few thousand.
MAX_ARCHIVE_ENTRIES = 20_000
# Total uncompressed size declared by the entries, in bytes: a backup is tens of MiB; the real
# corpus of 596 files is 4.8 MB.
MAX_ARCHIVE_BYTES = 512 * 1024 * 1024
# Uncompressed / compressed size of one entry: KRL text compresses 3-67x (measured over the
# real corpus with deflate level 9; the maximum is a point list of repeated lines); a zip bomb
# expands 1000x and more. Checked for entries larger than MAX_ARCHIVE_RATIO_FLOOR bytes (a
# tiny file of blanks compresses well and can do no harm).
MAX_ARCHIVE_RATIO = 200
MAX_ARCHIVE_RATIO_FLOOR = 4096
# Levels of an entry's path, file name included (KRC/R1/Program/x.src has 4).
MAX_ARCHIVE_DEPTH = 32
# Archives (.zip) below one folder given as backups (krl/backups.py: a folder of controller
# archives, one per controller and date, issue 85): each is checked and extracted as above, and the
# bytes extracted from all of them together are at most MAX_ARCHIVE_BYTES. Past it: an error
# naming the folder, nothing extracted.
MAX_FOLDER_ARCHIVES = 1000

# The most KRL files `krl lsp` reads for one workspace (a KRC backup or a folder the editor
# opened), in files. A real backup holds a few hundred to a few thousand; an editor opened on a
# home folder must not make the server read the whole disk. Past it: the first files (sorted)
# are read, the rest are not part of the workspace (their names stay unresolved).
MAX_LSP_WORKSPACE_FILES = 5000
# The largest file of a workspace `krl lsp` reads while it is not open in the editor, in bytes:
# a larger one is not indexed (a W002 warning names it; what it declares stays unresolved in the
# other files, as for any file not read) until the editor opens it. The corpus's largest KRL file
# is 626 kB (My_Job.src); a 9.8 MB file beside the one opened made the first answer wait 96 s,
# 86 s of CPU and 2.9 GB (issue 74, case 10).
MAX_LSP_INDEX_FILE_BYTES = 2 * 1024 * 1024
# A closed file past MAX_LSP_INDEX_FILE_BYTES is indexed in the background by its outline (its
# routines' first, last and DECL lines, a data list's GLOBAL declarations: krl/lsp/index.py),
# parsed alone; the most bytes one outline may hold. Past it the file stays not indexed (W002).
# The Python engine parses about 20 us a byte: 256 KiB is about 5 s of one core, in the background.
MAX_LSP_OUTLINE_BYTES = 256 * 1024
# The most directory entries (files and folders) `krl lsp` looks at while listing one workspace
# folder, in entries: a backup has a few thousand; a home folder opened by mistake may have
# millions. Past it the listing stops there (as for MAX_LSP_WORKSPACE_FILES).
MAX_LSP_SCAN_ENTRIES = 200_000

# The most entries `krl lsp` answers with: workspace symbols for one query, completion items for
# one request. A backup declares tens of thousands of names; an editor shows a few dozen.
MAX_LSP_SYMBOLS = 500
MAX_LSP_COMPLETIONS = 1000
# The one store of parse and check results (krl/store.py, shared by krl lsp, run, debug and
# check), in bytes of entries: a 400-file workspace takes about 2.5 MB. Past it the least
# recently used quarter of the entries is deleted. An entry (one file's parse, one workspace's
# diagnostics) larger than MAX_CACHE_ENTRY_BYTES is not kept (made anew each time).
MAX_CACHE_BYTES = 512 * 1024 * 1024
MAX_CACHE_ENTRY_BYTES = 64 * 1024 * 1024

# The loaded programs a process keeps in memory (interp/runtime/program.py `checked_workspace`,
# interp/runtime/model.py `load_model`: the runs of one backup, the tests of a worker, the variants
# of a sweep share them), in estimated bytes. Each checked workspace is charged
# MODEL_BYTES_PER_SOURCE_BYTE times the bytes of its files (measured with tracemalloc: 42-57
# bytes held per byte of KRL, the palletizer backup's 367 kB 18.8 MB, ChinaMilling's 526 kB
# 21.9 MB), leaving out the BASIS files of a workspace checked on the process's one BASIS layer
# (krl/basislayer.py holds their checked parse once, whatever the number of programs on it),
# plus WORKSPACE_BASE_BYTES, plus MODEL_BASE_BYTES for each program model built on it (measured
# 2026-11-29 with tracemalloc, 23 conformance cases and 3 folders on the layer: a workspace
# 0.07-0.11 MB beyond its own 74-477 bytes of KRL, corpus/programs' 28 kB 1.68 MB; a model
# 0.33-0.35 MB, corpus/programs' 0.50 MB, ChinaMilling's 3.0 MB, within its files' charge). The
# RSS a corpus backup's model adds to a process is about its charge (2026-11-29, one process,
# the four corpus backups in turn: 26.7, 23.9, 29.5, 28.6 MB against 32.7, 23.0, 32.9, 15.3 MiB).
# Past the budget the least recently used workspace loaded only once goes first (a segmented
# LRU: interp/runtime/sizedcache.py), with the models built on it; a later run of it loads it
# again. A workspace larger than the budget is kept alone. Chosen from the requests of one
# worker of a whole make test on a fresh clone (gw1 of three: its 1,552 tests in one process,
# the 2,247 operations on this cache recorded and replayed, 2026-11-29): the corpus and history
# backups it holds at once are charged about 125 MiB (KRC4_test 32.9, ChinaMilling 32.7, the
# palletizer 23.5, kukaKRLmagic 15.3, ChinaMilling's history 14.5), more than the protected
# 80 % of 128 MiB: ChinaMilling was built twice. With these charges 160 MiB loads each backup
# once (176 MiB with each program on the layer charged its 33 kB of BASIS, 2.1 MB, as before);
# 192 MiB leaves a margin for the other workers' orders. (The earlier choice of 128 MiB, from
# tests/vm, tests/conformance and tests/debug in one process, was made before the BASIS layer,
# when each small program held a checked BASIS of its own: 256 MiB then took 413 MB more peak
# RSS, 1,147 against 734 MB.)
MODEL_CACHE_BYTES = 192 * 1024 * 1024
MODEL_BYTES_PER_SOURCE_BYTE = 64
WORKSPACE_BASE_BYTES = 128 * 1024
MODEL_BASE_BYTES = 512 * 1024

# A `krl.toml` (the diagnostic configuration of a workspace), in bytes: a few lines in practice.
# Past it: the configuration error names the file (krl check exits 2).
MAX_CONFIG_BYTES = 64 * 1024

# Stimuli files (`krl run --inputs`, robot/stimuli.py): the largest file read, in bytes (a YAML
# document; real cells script a few hundred stimuli), and the most stimuli in one file. Past
# either: an error naming the file; the run does not start.
MAX_STIMULI_BYTES = 4 * 1024 * 1024
MAX_STIMULI = 100_000

# The run's data memory, in data elements: every scalar value (INT, REAL, BOOL, CHAR, ENUM) and
# every structure value held by a declared variable counts one (an array of n elements counts n
# times its element; `DECL E6POS P[10]` is 10 x 13 = 130). Data lists (.dat, $config.dat), the
# locals of every active routine call and the copies of :IN parameters are counted together;
# a routine's share is given back when it returns. 2^20 elements is about 4 MiB of controller
# data at 4 bytes an element, far above the largest real data list (the corpus's biggest array
# has 8192 elements) and a few hundred MB of Python at most. Past it: the run-time error "data
# memory exhausted" at the DECL line, before anything is allocated (interp/runtime/memory.py).
MAX_DATA_ELEMENTS = 1 << 20

# Backward motion (interp/runtime/runmode.py): the executed motions the robot interpreter keeps
# for #BSTEP, newest last; past it the oldest is dropped (backward motion then ends there with
# "no executed motion left to retrace"). A real cycle has tens to a few hundred motions.
MAX_MOTION_HISTORY = 10_000

# The DAP server (interp/debug): the largest message body it reads (a longer Content-Length is
# a protocol error that ends the session), the breakpoints of one source file, and the
# statements a reverse step replays (stepBack re-runs the program from its start).
MAX_DAP_MESSAGE_BYTES = 1024 * 1024
MAX_DAP_BREAKPOINTS = 1000
MAX_DAP_REPLAY_STEPS = 10_000_000

# Reactive rules of a cell file (`rules:` in a stimuli file, robot/cellrules.py): the most rules
# in one file (a PLC program answering a cell has tens of handshakes, a few hundred at most) and
# the most tokens in one rule's `when` expression (one line of KRL; real conditions have under
# 20 tokens; the bound also bounds the bracket depth of the parse). Past either: an error naming
# the file:line of the rule; the run does not start.
MAX_CELL_RULES = 1000
#: The longest simulated time (s) a cell file may ask for a program's run (``sim_time``,
#: robot/stimuli.py): one hour.
MAX_CELL_SIM_TIME_S = 3600.0
MAX_RULE_TOKENS = 200

# A cell of several robots (interp/robotcell.py, docs/cells.md): the most robots in one cell file
# (a production cell has a few; a simulated one steps every robot each IPO cycle) and the most
# wires between them. Past either: an error naming the file:line; the cell does not start.
MAX_CELL_ROBOTS = 16
MAX_CELL_WIRES = 4096
#: shared zones of such a cell (interp/cellzones.py): each is checked against every pair of robots each cycle
MAX_CELL_ZONES = 64

# The backup diff (`krl diff`, krl/diff): the statement lines shown before and after for one
# changed routine (each side; the count of the rest is given), and the routines, points and
# other entries listed in one report. Past them: the report says how many were left out.
MAX_DIFF_LINES = 200
MAX_DIFF_ENTRIES = 20_000

# The program map (`krl graph`, krl/programmap): the largest map rendered through Graphviz
# (DOT/SVG) and the HTML page, in nodes. Past it: an error naming the count (JSON has no limit).
MAX_GRAPH_NODES = 5000
# The routines' source text the interactive map page carries (krl graph --format html), in
# characters in all; past it the remaining routines show their file:line without the text.
MAX_GRAPH_SOURCE_CHARS = 8_000_000
# The files the change report carries as its own views of the lines it links to (krl report
# --links source, krl/diff/sources.py), in characters in all; past it a file shows the lines
# around each line a link names.
MAX_REPORT_SOURCE_CHARS = 4_000_000

# KUKA Trace recordings (`krl trace show|compare`, robot/kukatrace): the largest KRCIpo CSV or
# PROG.TXT read, in bytes (a recording of the real-traces repository is at most 700 kB: 12 ms
# samples of 22 columns for 20 s), and the most columns of one CSV row. Past either: an error
# naming the file (exit 2); nothing is read.
MAX_RECORDING_BYTES = 64 * 1024 * 1024
MAX_RECORDING_COLUMNS = 512

# The controller's message window (interp/runtime/messages.py): the most messages shown at once
# (a real cell shows a handful; past it the oldest notify message is dropped).
MAX_KRL_MESSAGES = 100
# The same QUIT message acknowledged automatically (a run has no operator) this many times in a
# row with no motion between ends the run: the controller would wait for the operator at each
# (interp/runtime/messages.py, issue 85: a P00 fault loop wrote 27,787 messages in 30 s).
MAX_QUIT_REPEATS = 10

# `krl pendant` (pendant/, docs/security.md "The pendant's web server"): the largest websocket
# message the server reads (a larger one closes the connection with 1009), the largest HTTP
# request body, the connections served at once, the operator's messages per second on one
# connection (past it the connection is closed), the watch list's length and the length of one
# watched expression, and the largest KRL file the page shows or touch-up rewrites.
MAX_WEB_MESSAGE_BYTES = 64 * 1024
MAX_WEB_BODY_BYTES = 64 * 1024
MAX_WEB_CONNECTIONS = 8
MAX_WEB_MESSAGES_PER_S = 200
MAX_WEB_WATCHES = 64
MAX_WEB_EXPRESSION_CHARS = 200
MAX_WEB_FILE_BYTES = 4 * 1024 * 1024
# The controller on the network (net/, docs/network.md, docs/security.md "Network"). Everything
# that arrives on a socket is untrusted; every size, rate and count below ends in an EKI/RSI
# message, a closed connection or a stopped motion, never in unbounded memory or a hang.
# EthernetKRL (KUKA.EthernetKRL manual): at most 16 channels at once (the manual's limit of
# active connections); at most 512 entries buffered per element (BUFFERING Limit's system
# maximum); one message at most BUFFSIZE bytes, default 16384 and at most 65534 (the manual's
# range); a channel's XML configuration at most 256 KiB (real ones are a few KiB).
MAX_EKI_CHANNELS = 16
# A server channel takes one partner at a time. The manual monitors a connection by ALIVE's ping,
# not by its traffic (EthernetKRL 2.2, 2.2.2 "Monitoring a connection"): a partner that only
# listens is silent by design, and none is dropped for its silence alone. But a partner that
# has sent nothing for this long, in seconds of the controller's time, gives its place to a new
# one that connects (it held the only place forever, issue 61); the program sees EKI00512 as for
# any dropped connection (docs/network.md, Decisions).
MAX_EKI_IDLE_S = 30.0
MAX_EKI_BUFFERING = 512
EKI_BUFFSIZE_DEFAULT = 16384
MAX_EKI_BUFFSIZE = 65534
MAX_NET_CONFIG_BYTES = 256 * 1024
# One received XML message: the deepest element nesting and the most elements and attributes
# (real EKI and RSI messages nest 3-4 levels and carry a few dozen values). Past either: the
# message is refused as unreadable (EKI01024, RSI: a late packet).
MAX_NET_XML_DEPTH = 32
MAX_NET_XML_NODES = 4096
# Bytes read from one connection in one IPO cycle (12 ms): 256 KiB is 21 MB/s, far above any
# partner (RSI sends about 1 KiB per cycle); a flood past it waits in the kernel's buffer, so a
# partner cannot make one cycle take unbounded time or memory.
MAX_NET_BYTES_PER_CYCLE = 256 * 1024
# RSI (KUKA.RobotSensorInterface): one UDP datagram at most 8 KiB (a real answer is under 1 KiB);
# datagrams read per cycle at most 64 (the rest are dropped by the kernel).
MAX_RSI_DATAGRAM_BYTES = 8 * 1024
MAX_RSI_DATAGRAMS_PER_CYCLE = 64
# An RSI context file (.rsi.xml, .rsix): elements and attributes at most 64 Ki. WorkVisual's
# .rsix carries the editor's blueprint collection beside the objects (about 120 KB, several
# thousand nodes: kroshu's SDK, FZI's driver); a context has at most 256 objects.
MAX_RSI_CONTEXT_NODES = 65536
MAX_RSI_OBJECTS = 256
# KukaVarProxy (OpenShowVar protocol): clients at once (KukaVarProxy itself takes 10), requests
# answered per client per IPO cycle, and the longest variable name and value text (the protocol
# counts them in 16 bits; real names are under 30 characters, values under 300).
MAX_VARPROXY_CLIENTS = 10
MAX_VARPROXY_REQUESTS_PER_CYCLE = 16
MAX_VARPROXY_NAME_CHARS = 256
MAX_VARPROXY_VALUE_CHARS = 4096
# The PLC side (Modbus TCP, OPC UA): clients at once on each server.
MAX_PLC_CLIENTS = 8
# What a partner sends, shown anywhere but in the recording of the message itself (the trace's
# `data`, bounded by each protocol's own limits above so that a replay feeds it again): an error
# event's text, a controller message, a refusal, a line a protocol library logs on stderr. 200
# characters show any real name, value or IPOC whole; a 100 KB value a client wrote is cut, ending
# in "…" (issue 61: one rejected OPC UA write put a 100,158-character line on stderr).
MAX_NET_LOG_CHARS = 200
# A recorded message sequence replayed into a run (`network: {replay: trace.jsonl}`): its
# largest file, in bytes, and its most network events.
MAX_NET_REPLAY_BYTES = 64 * 1024 * 1024
MAX_NET_REPLAY_EVENTS = 1_000_000
# The wall-clock pace factor of a run with a partner attached (simulated s per wall s): 1 is
# real time; up to 10 where the protocol allows (EKI, KukaVarProxy, the PLC), never for RSI.
MAX_NET_PACE = 10.0
# The automatic cell (krl run --inputs auto, interp/runtime/autocell.py): the inputs of one
# condition it combines, and the evaluations of that condition it tries (2^8 combinations of
# one-bit inputs and a few values of each group), before it leaves the condition unanswered.
AUTO_MAX_INPUTS = 8
AUTO_MAX_TRIES = 4096
# The points of one backup the automatic cell's robot choice looks at (interp/scene.py): a
# palletizer's backup teaches about 300.
MAX_CHOICE_POINTS = 2000
# `krl run --on-halt continue:N`: the operator presses Start again at most this often.
MAX_HALT_CONTINUES = 1000
# A start position (`krl run --start`, a cell file's `start:`): characters of its text; its
# tokens are at most MAX_RULE_TOKENS.
MAX_START_CHARS = 400
# `krl audit FOLDER...` (audit/, docs/audit.md): the most backups and program folders one audit
# takes (past it: an error naming the count, nothing runs), the entry points it runs per backup
# (the first ones in walk order; the rest are listed as not run), the check findings it lists
# per backup (all are counted), the wall-clock seconds one run may take in its worker process
# (then it is killed: ends "stopped at the audit's wall-clock limit"), and the source text the
# report's evidence carries, in characters in all (past it an item keeps its file:line only).
MAX_AUDIT_BACKUPS = 1000
MAX_AUDIT_ENTRIES = 200
MAX_AUDIT_FINDINGS = 500
AUDIT_RUN_TIMEOUT_S = 900.0
MAX_AUDIT_EVIDENCE_CHARS = 4_000_000

# A controller archive as KUKA writes it (krl/kssarchive.py): its am.ini and ArchiveInfo.xml, in
# bytes (the real KSS 8.7.8 archive's are 750 and 7,010 bytes); past it the file is not read and
# the archive is described without it (a note names the file).
MAX_ARCHIVE_INFO_BYTES = 1024 * 1024
# The controller's logbook (`krl log`, krl/logbook): the largest event log read, in bytes (a KSS
# event log is 64 KiB to a few MiB: the archive's KrcLogU.evt is 1.1 MB with 1,761 records), the
# most records read from all the logs of one command (past it the rest of the logs is not read and
# a note says so), and the characters of one record's LS document (a record is a few hundred
# characters). Past the file size: an error naming the file; the other logs are still read.
# A record held takes about 1.8 KB (tracemalloc over KrcLogU.evt), so 200 000 records are about
# 360 MB; a real archive's seven logs hold tens of thousands.
MAX_LOG_BYTES = 64 * 1024 * 1024
MAX_LOG_RECORDS = 200_000
#: the logbook records `krl pendant` sends its page (pendant/logbook.py): the newest are kept,
#: the page says how many were left out (a whole archive's seven logs hold tens of thousands)
MAX_PENDANT_LOG_RECORDS = 5_000
MAX_LOG_RECORD_CHARS = 64 * 1024
