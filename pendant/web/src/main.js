// The page of `krl pendant` (pendant/server.py): the program view, the keys, the message
// window, I/O, watch list, position and the 3D view of the backup's own robot.
// Every text that comes from KRL or the workspace is written with textContent, never as markup.
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { STLLoader } from 'three/examples/jsm/loaders/STLLoader.js';
import URDFLoader from 'urdf-loader';

const $ = (id) => document.getElementById(id);
const el = (tag, props = {}, ...children) => {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(props)) {
    if (k === 'text') e.textContent = v;
    else if (k === 'class') e.className = v;
    else if (k.startsWith('on')) e.addEventListener(k.slice(2), v);
    else e.setAttribute(k, v);
  }
  for (const c of children) e.append(c);
  return e;
};

// ------------------------------------------------------------------ connection
const params = new URLSearchParams(location.search);
const token = params.get('token');
const wsUrl = `${location.protocol === 'https:' ? 'wss' : 'ws'}://${location.host}/ws` + (token ? `?token=${encodeURIComponent(token)}` : '');
let ws = null;
let nextId = 1;
const waiting = new Map();

function connect() {
  ws = new WebSocket(wsUrl);
  ws.onopen = () => send('hello').catch(showError);
  ws.onmessage = (ev) => onMessage(JSON.parse(ev.data));
  ws.onclose = () => { setState({ state: 'disconnected' }); };
}

function send(op, args = {}) {
  const id = nextId++;
  ws.send(JSON.stringify({ op, id, ...args }));
  return new Promise((resolve, reject) => waiting.set(id, { resolve, reject, t0: performance.now() }));
}

function act(op, args) {
  showError('');
  return send(op, args).catch(showError);
}

function showError(e) {
  $('errorbar').textContent = e ? String(e.message || e) : '';
}

const P = window.pendant = { state: null, module: null, robot: null, frames: 0, live: null, lastChange: 0, events: [] };
P.send = send;

function onMessage(m) {
  switch (m.type) {
    case 'init': onInit(m); break;
    case 'module': onModule(m); break;
    case 'logbook': onLogbook(m); break;
    case 'state': onState(m); break;
    case 'live': onLive(m); break;
    case 'event': P.events.push(m); if (P.events.length > 200) P.events.shift(); break;
    case 'done': { P.lastDone = performance.now(); P.lastServerMs = m.ms; const w = waiting.get(m.id); if (w) { waiting.delete(m.id); w.resolve(m); } break; }
    case 'error': {
      const w = waiting.get(m.id);
      if (w) { waiting.delete(m.id); w.reject(new Error(m.text)); } else showError(m.text);
      break;
    }
  }
}

// ------------------------------------------------------------------ init, programs, keys
function fillSelect(sel, values, current) {
  sel.replaceChildren(...values.map((v) => el('option', { text: v, value: v })));
  if (current) sel.value = current;
}

function onInit(m) {
  $('workspace').textContent = m.workspace;
  const group = (label, values) => el('optgroup', { label }, ...values.map((v) => el('option', { text: v, value: v })));
  $('programs').replaceChildren(group('entry points', m.programs), group('other modules', m.modules || []));
  if (P.state && P.state.programLabel) $('programs').value = P.state.programLabel;
  fillSelect($('mode-op'), m.modes);
  fillSelect($('run-mode'), m.runModes);
  $('touchup').disabled = !!m.readonly;
  $('robot-name').textContent = m.robot.name;
  if (m.cell) {
    // a cell of several robots (pendant/cell.py): the robot chooser, every robot in the 3D view
    fillSelect($('cell-robot'), m.cell.robots.map((r) => r.robot), m.cell.chosen);
    $('cell-field').hidden = false;
    P.cell = m.cell;
    loadCellRobots(m.cell.robots);
  } else loadRobot(m.robot);
  if (!P.logbook) send('logbook').catch(showError);
}

$('cell-robot').onchange = (e) => act('chooseRobot', { robot: e.target.value });
$('select').onclick = () => act('select', { program: $('programs').value });
$('ack-all').onclick = () => act('ackAll');
$('cancel').onclick = () => act('cancel');
$('reset').onclick = () => act('reset');
$('start').onclick = () => act('start');
$('stop').onclick = () => act('stop');
$('backward').onclick = () => act('backward');
$('mode-op').onchange = (e) => act('modeOp', { value: e.target.value });
$('run-mode').onchange = (e) => act('runMode', { value: e.target.value });
$('drives').onclick = () => act('drives', { on: $('drives').getAttribute('aria-pressed') !== 'true' });
$('override').oninput = (e) => { $('override-value').textContent = e.target.value; };
$('override').onchange = (e) => act('override', { value: parseInt(e.target.value, 10) });
for (const b of document.querySelectorAll('#tabs button')) {
  b.onclick = () => {
    for (const x of document.querySelectorAll('#tabs button, .tab')) x.classList.remove('active');
    b.classList.add('active');
    $('tab-' + b.dataset.tab).classList.add('active');
  };
}

function buildJogKeys() {
  const system = $('jog-system').value;
  // the robot's axes and its external axes (the robot view's keys: A1..An, E1..Em); E<n> is axis 6 + n
  const names = system === 'AXIS' ? (P.jogKeys || ['A1', 'A2', 'A3', 'A4', 'A5', 'A6']) : ['X', 'Y', 'Z', 'A', 'B', 'C'];
  const box = $('jog-keys');
  box.replaceChildren();
  names.forEach((n) => {
    const axis = system === 'AXIS' ? (n[0] === 'E' ? 6 : 0) + parseInt(n.slice(1), 10) : n;
    const jog = (sign) => act('jog', { system, axis, step: sign * parseFloat($('jog-step').value) });
    box.append(el('span', { text: n }),
      el('button', { text: '\u2212', 'data-jog': `${n}-`, onclick: () => jog(-1) }),
      el('button', { text: '+', 'data-jog': `${n}+`, onclick: () => jog(1) }));
  });
}
$('jog-system').onchange = buildJogKeys;
buildJogKeys();
$('touchup').onclick = () => {
  if (!P.module || !P.module.dat) { showError('touch-up: the module has no data list'); return; }
  act('touchup', { path: P.module.dat, name: $('touchup-name').value.trim() });
};

let watchList = [];
$('watch-add').onclick = () => {
  const e = $('watch-expr').value.trim();
  if (!e) return;
  watchList = [...watchList, e];
  $('watch-expr').value = '';
  act('watch', { exprs: watchList });
};

// ------------------------------------------------------------------ program view
const moduleCache = new Map();   // path -> the module message: following the advance run costs no round trip
function onModule(m) {
  moduleCache.set(m.path, m);
  if (moduleCache.size > 64) moduleCache.delete(moduleCache.keys().next().value);
  showModule(m);
}

function showModule(m) {
  P.module = m;
  $('module-label').textContent = m.label;
  const box = $('program-view');
  const rows = m.lines.map((text, i) => {
    const no = el('span', { class: 'no', text: String(i + 1), title: 'breakpoint' });
    no.onclick = () => act('breakpoint', { path: m.path, line: i + 1, on: !row.classList.contains('bp') });
    const row = el('div', { class: 'ln', role: 'listitem', 'data-line': String(i + 1) }, el('span', { class: 'ptr' }), no, el('span', { class: 'tx', text }));
    return row;
  });
  box.replaceChildren(...rows);
  showPoints(m.points || []);
  drawPoints(m.points || []);
  if (P.state) drawPointers(P.state.pointers || {}, P.state.breakpoints || {});
  markLogged();
}

function samePath(a, b) { return a && b && a === b; }

function drawPointers(ptr, bps) {
  const m = P.module;
  if (!m) return;
  const box = $('program-view');
  for (const r of box.querySelectorAll('.main, .advance, .bp')) r.classList.remove('main', 'advance', 'bp');
  const mark = (p, cls) => {
    if (p && samePath(p.path, m.path)) {
      const r = box.querySelector(`[data-line="${p.line}"]`);
      if (r) { r.classList.add(cls); return r; }
    }
    return null;
  };
  const adv = mark(ptr.advanceRun, 'advance');
  const main = mark(ptr.mainRun, 'main');
  for (const line of (bps[m.path] || [])) {
    const r = box.querySelector(`[data-line="${line}"]`);
    if (r) r.classList.add('bp');
  }
  const target = main || adv;
  if (target && P.scrollTo !== target) { P.scrollTo = target; target.scrollIntoView({ block: 'center' }); }
  // follow the advance run into another module, as the smartPAD does
  const want = (ptr.advanceRun && ptr.advanceRun.path) || null;
  if (want && !samePath(want, m.path)) {
    const cached = moduleCache.get(want);
    if (cached) showModule(cached);
    else if (P.opening !== want) { P.opening = want; send('open', { path: want }).catch(() => {}); }
  }
}

// ------------------------------------------------------------------ the logbook (pendant/logbook.py)
// the controller archive's logbook beside the program: stepping through its records moves the
// program view to the file and line a record names (a variable set from the pendant: its
// declaration; a program: its first line)
function onLogbook(m) {
  P.logbook = m;
  P.logIndex = -1;
  $('log-count').textContent = m.records.length ? `(${m.records.length})` : '';
  const notes = [...m.errors];
  if (m.omitted) notes.push(`${m.omitted} older records not shown`);
  if (!m.records.length && !m.errors.length) notes.push('no logbook: the workspace is no controller archive with event logs');
  $('log-note').textContent = notes.join('; ');
  $('logbook').replaceChildren(...m.records.map((r, i) => el('li', { 'data-index': String(i), 'data-linked': r.path ? 'true' : 'false', onclick: () => stepLog(i) },
    el('span', { class: 'time', text: r.time.replace('T', ' ').replace('Z', '') }),
    el('span', { class: 'origin', text: r.module }),
    el('span', { class: 'number', text: r.number === null ? '' : String(r.number) }),
    el('span', { class: 'text', text: [r.key, ...r.params].filter((x) => x).join('  ') }),
    el('span', { class: 'src', text: r.path ? `${r.path.split('/').slice(-1)[0]}${r.line ? ` line ${r.line}` : ''}` : '' }))));
}

function stepLog(i) {
  const recs = P.logbook ? P.logbook.records : [];
  if (!recs.length) return;
  P.logIndex = Math.max(0, Math.min(recs.length - 1, i));
  for (const li of $('logbook').querySelectorAll('li.current')) li.classList.remove('current');
  const li = $('logbook').querySelector(`li[data-index="${P.logIndex}"]`);
  li.classList.add('current');
  li.scrollIntoView({ block: 'nearest' });
  const r = recs[P.logIndex];
  $('log-pos').textContent = `${P.logIndex + 1} / ${recs.length}`;
  if (!r.path) return;
  P.logTarget = { path: r.path, line: r.line || 1 };
  if (P.module && samePath(P.module.path, r.path)) markLogged();
  else if (moduleCache.get(r.path)) showModule(moduleCache.get(r.path));
  else send('open', { path: r.path }).catch(showError);
}

// the line the current record names, marked in the program view when it shows that file
function markLogged() {
  const box = $('program-view');
  for (const r of box.querySelectorAll('.logged')) r.classList.remove('logged');
  const t = P.logTarget;
  if (!t || !P.module || !samePath(P.module.path, t.path)) return;
  const row = box.querySelector(`[data-line="${t.line}"]`);
  if (row) { row.classList.add('logged'); row.scrollIntoView({ block: 'center' }); }
}
$('log-prev').onclick = () => stepLog(P.logIndex - 1);
$('log-next').onclick = () => stepLog(P.logIndex + 1);

// ------------------------------------------------------------------ state
const fmt = (v, d = 3) => (typeof v === 'number' ? v.toFixed(d) : '—');

// the server sends the whole state first, then what changed (a key gone is null): the page keeps
// the state and redraws only the parts that changed
function onState(m) {
  const s = m.full || !P.state ? {} : { ...P.state };
  for (const [k, v] of Object.entries(m)) {
    if (k === 'type' || k === 'full') continue;
    if (v === null) delete s[k]; else s[k] = v;
  }
  setState(s, m.full ? null : new Set(Object.keys(m)));
}

function setState(s, changed = null) {
  const has = (k) => !changed || changed.has(k);
  P.state = s;
  P.lastChange = performance.now();
  const st = s.state || 'none';
  $('st-state').dataset.state = st;
  $('st-state').dataset.outcome = (st === 'ended' && s.outcome && s.outcome.reason) || '';
  $('st-state').textContent = statusText(s);
  $('st-program').textContent = s.program ? s.program.split('/').slice(-1)[0] : 'no program';
  // the programs list shows the selected program (after a reload, in a second browser)
  if (has('programLabel') && s.programLabel && [...$('programs').options].some((o) => o.value === s.programLabel)) {
    $('programs').value = s.programLabel;
  }
  if (s.modeOp) $('mode-op').value = s.modeOp;
  if (s.runMode) $('run-mode').value = s.runMode;
  $('drives').setAttribute('aria-pressed', s.drives ? 'true' : 'false');
  $('drives').textContent = s.drives ? 'drives on' : 'drives off';
  if (typeof s.override === 'number' && document.activeElement !== $('override')) {
    $('override').value = s.override; $('override-value').textContent = String(s.override);
  }
  if (typeof s.time === 'number') $('st-time').textContent = `t = ${s.time.toFixed(3)} s`;
  if (has('pointers') || has('breakpoints')) drawPointers(s.pointers || {}, s.breakpoints || {});
  if (has('messages')) drawMessages(s.messages || []);
  if (has('notes')) $('notes').replaceChildren(...(s.notes || []).slice().reverse().map((n) => el('li', { text: `t=${fmt(n.time)} s  ${n.text}` })));
  if (has('io')) drawIo(s.io);
  if (has('watch')) drawWatch(s.watch || []);
  if (has('threads')) drawThreads(s.threads || []);
  if (has('position') && s.position) { drawPosition(s.position); setAxes(s.position.axes, s.position.tool, s.position.base); }
}

// the status line: the state, why the program stands (a run-time error: its number, text and
// statement) or how the run ended
const PLACE = (o) => (o && o.module && o.line ? ` \u2014 ${o.module} line ${o.line}` : '');
function statusText(s) {
  const st = s.state || 'none';
  if (st === 'stopped' && s.stop) {
    const d = s.stop.description ? `: ${s.stop.description}` : '';
    return `stopped${d}${s.stop.text && s.stop.text !== s.stop.description ? `: ${s.stop.text}` : ''}${PLACE(s.stop)}`;
  }
  if (st === 'ended' && s.outcome) {
    const o = s.outcome;
    const module = o.path ? o.path.split('/').slice(-1)[0] : '';
    if (o.reason === 'completed') return 'ended';
    return `ended: ${o.reason === 'error' ? 'run-time error' : o.reason}${o.number ? ` ${o.number}` : ''}${o.text ? `: ${o.text}` : ''}${PLACE({ module, line: o.line })}`;
  }
  return st;
}

// the message window as the smartHMI shows it: type, time, originator (a program's own messages
// in angle brackets), number, text, module and line; OK on notification and acknowledgement
// messages, a dialog's softkeys
function drawMessages(list) {
  $('msg-count').textContent = list.length ? `(${list.length})` : '';
  $('messages').replaceChildren(...list.map((m) => {
    const buttons = [];
    if (m.kind === 'QUIT' || m.kind === 'NOTIFY') buttons.push(el('button', { text: 'OK', 'data-ack': String(m.handle), onclick: () => act('ack', { handle: m.handle }) }));
    if (m.kind === 'DIALOG') m.softkeys.forEach((k, i) => { if (k.trim()) buttons.push(el('button', { text: k, 'data-answer': String(i + 1), onclick: () => act('answer', { handle: m.handle, key: i + 1 }) })); });
    const origin = m.krl ? `<${m.origin || ''}>` : (m.origin || '');
    return el('li', { 'data-kind': m.kind, 'data-handle': String(m.handle), 'data-type': m.type || '' },
      el('span', { class: 'kind', text: m.type || m.kind }),
      el('span', { class: 'time', text: `t=${fmt(m.time)} s` }),
      el('span', { class: 'origin', text: origin }),
      el('span', { class: 'number', text: m.number || m.number === 0 ? String(m.number) : '' }),
      el('span', { class: 'text', text: m.text }),
      el('span', { class: 'src', text: m.line ? `${m.module} line ${m.line}` : (m.krl ? '' : m.module || '') }), ...buttons);
  }));
}

function drawIo(io) {
  if (!io) return;
  const table = (rows, arr, toggle) => [el('tr', {}, el('th', { text: arr }), el('th', { text: 'name' }), el('th', { text: 'long text' }), el('th', { text: 'value' })),
    ...rows.map((r) => {
      const v = el('span', { class: r.value ? 'io-on' : 'io-off', text: r.value ? 'TRUE' : 'FALSE' });
      const cell = toggle ? el('button', { 'data-input': String(r.index), onclick: () => act('input', { index: r.index, value: !r.value }) }, v) : v;
      return el('tr', { 'data-io': `${arr}[${r.index}]` }, el('td', { text: String(r.index) }), el('td', { text: r.names.join(', ') }), el('td', { text: r.text }), el('td', {}, cell));
    })];
  $('inputs').replaceChildren(...table(io.$IN || [], '$IN', true));
  $('outputs').replaceChildren(...table(io.$OUT || [], '$OUT', false));
}

function drawWatch(list) {
  $('watch').replaceChildren(...list.map((w) => {
    const input = el('input', { value: w.value !== undefined ? w.value : '', 'aria-label': `value of ${w.expr}` });
    input.onkeydown = (e) => { if (e.key === 'Enter') act('setWatch', { expr: w.expr, value: input.value }); };
    return el('tr', { 'data-watch': w.expr }, el('td', { text: w.expr }), el('td', {}, w.error !== undefined ? el('span', { class: 'io-off', text: w.error }) : input));
  }));
}

// the module's taught points (pendant/view.py taught_points): name, line, base, X..C in that base
// (an axis point: A1..A6) and the external axes' values, one column per E the robot has and per E
// any point holds other than 0 (a point taught with E1 on another robot still shows it)
function drawPoints(points) {
  const ext = new Set((P.jogKeys || []).filter((k) => /^E[1-6]$/.test(k)));
  for (const p of points) for (const [k, v] of Object.entries(p.ext || {})) if (v !== 0) ext.add(k);
  const es = [...ext].sort();
  const keys = ['X', 'Y', 'Z', 'A', 'B', 'C'];
  const values = (p) => (p.frame ? p.frame.map((v, i) => `${keys[i]} ${fmt(v, 1)}`) : p.axes.map((v, i) => `A${i + 1} ${fmt(v, 1)}`)).join(' ');
  $('points-count').textContent = points.length ? `(${points.length})` : '';
  $('points').replaceChildren(el('tr', {}, el('th', { text: 'point' }), el('th', { text: 'line' }), el('th', { text: 'base' }),
    el('th', { text: 'position' }), ...es.map((e) => el('th', { text: e }))),
  ...points.map((p) => el('tr', { 'data-point': p.name }, el('td', { text: p.name }), el('td', { text: String(p.line) }),
    el('td', { text: p.frame ? (p.base ? `BASE_DATA[${p.base}]` : '$WORLD') : 'axes' }), el('td', { text: values(p) }),
    ...es.map((e) => el('td', { 'data-ext': e, text: p.ext && e in p.ext ? fmt(p.ext[e], 3) : '—' })))));
}

function drawThreads(list) {
  $('threads').replaceChildren(el('tr', {}, el('th', { text: 'thread' }), el('th', { text: 'routine' }), el('th', { text: 'line' })),
    ...list.map((t) => el('tr', {}, el('td', { text: t.name }), el('td', { text: t.routine || '' }), el('td', { text: t.line ? String(t.line) : '' }))));
}

function drawPosition(p) {
  const rows = [];
  const keys = ['X', 'Y', 'Z', 'A', 'B', 'C'];
  for (let i = 0; i < 6; i++) {
    rows.push(el('tr', {}, el('th', { text: `A${i + 1}` }), el('td', { 'data-axis': String(i + 1), text: fmt(p.axes[i], 3) }),
      el('th', { text: keys[i] }), el('td', { 'data-pos': keys[i], text: p.pos ? fmt(p.pos[keys[i]], 2) : '—' })));
  }
  if (p.pos) rows.push(el('tr', {}, el('th', { text: 'S' }), el('td', { text: String(p.pos.S) }), el('th', { text: 'T' }), el('td', { text: String(p.pos.T) })));
  // the external axes E1..Em: KRL's E6AXIS after A6 (the axes' values), as $POS_ACT carries them
  for (let k = 0; 6 + k < p.axes.length; k++) {
    rows.push(el('tr', {}, el('th', { text: `E${k + 1}` }), el('td', { 'data-axis': `E${k + 1}`, text: fmt(p.axes[6 + k], 3) }),
      el('th', { text: '' }), el('td', { text: '' })));
  }
  const frame = (f) => (f ? keys.map((k) => fmt(f[k], 1)).join(' ') : '—');
  rows.push(el('tr', {}, el('th', { text: '$BASE' }), el('td', { colspan: '3', text: frame(p.base) })));
  rows.push(el('tr', {}, el('th', { text: '$TOOL' }), el('td', { colspan: '3', text: frame(p.tool) })));
  $('position').replaceChildren(...rows);
}

// ------------------------------------------------------------------ 3D view
const scene = new THREE.Scene();
scene.background = new THREE.Color(0x0f1215);
const world = new THREE.Group();            // KUKA $WORLD: Z up, metres
world.rotation.x = -Math.PI / 2;
scene.add(world);
scene.add(new THREE.HemisphereLight(0xffffff, 0x334455, 2.2));
const sun = new THREE.DirectionalLight(0xffffff, 1.6);
sun.position.set(3, 6, 4);
scene.add(sun);
const grid = new THREE.GridHelper(6, 30, 0x44505c, 0x2a3138);
scene.add(grid);
world.add(new THREE.AxesHelper(0.4));
const camera = new THREE.PerspectiveCamera(45, 1, 0.01, 100);
camera.position.set(3.2, 2.6, 3.6);
// WebGL drawn by the CPU (no GPU, or Chromium started with --disable-gpu: SwiftShader; Mesa's
// llvmpipe) draws without multisampling: 4x MSAA multiplies the fragments a frame costs on the CPU
// the simulation shares (docs/pendant.md, "The 3D view without a GPU"); a GPU draws with it
function rendererName() {
  const gl = document.createElement('canvas').getContext('webgl');
  if (!gl) return '';
  const info = gl.getExtension('WEBGL_debug_renderer_info');
  const name = String(gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER));
  const lose = gl.getExtension('WEBGL_lose_context');
  if (lose) lose.loseContext();
  return name;
}
const glName = rendererName();
const softwareGL = /SwiftShader|llvmpipe|softpipe|Software Rasterizer/i.test(glName);
const renderer = new THREE.WebGLRenderer({ antialias: !softwareGL, preserveDrawingBuffer: true });
P.gl = { renderer: glName, software: softwareGL, antialias: renderer.getContext().getContextAttributes().antialias };
renderer.setPixelRatio(Math.min(2, window.devicePixelRatio || 1));
$('view3d').append(renderer.domElement);
const controls = new OrbitControls(camera, renderer.domElement);
controls.target.set(0, 1.0, 0);
controls.update();
P.view = { camera, controls, scene };

function kukaMatrix(f) {           // X,Y,Z mm and A,B,C deg -> Matrix4 (m): Rz(A) Ry(B) Rx(C)
  const m = new THREE.Matrix4();
  const d = Math.PI / 180;
  m.makeRotationFromEuler(new THREE.Euler(f[5] * d, f[4] * d, f[3] * d, 'ZYX'));
  m.setPosition(f[0] / 1000, f[1] / 1000, f[2] / 1000);
  return m;
}
const frameArr = (f) => (f ? ['X', 'Y', 'Z', 'A', 'B', 'C'].map((k) => f[k] || 0) : null);

const robotRoot = new THREE.Group();
world.add(robotRoot);
const baseFrame = new THREE.AxesHelper(0.25);
world.add(baseFrame);
const toolFrame = new THREE.AxesHelper(0.15);
let tool0 = null;
let jointNames = [];
const linkMaterial = new THREE.MeshStandardMaterial({ color: 0xff5800, metalness: 0.2, roughness: 0.6 });
const jointMaterial = new THREE.MeshStandardMaterial({ color: 0x30353b, metalness: 0.3, roughness: 0.5 });

// a capsule from one point to another in a link's frame (a sphere where they meet): the body the
// collision check gives the link (robot/mjcf.py, its radius robot/capsules.py's)
function limb(from, to, radius, material = linkMaterial) {
  const a = new THREE.Vector3(...from);
  const b = new THREE.Vector3(...to);
  const len = a.distanceTo(b);
  if (len < 1e-4) { const m = new THREE.Mesh(new THREE.SphereGeometry(radius, 20, 12), material); m.position.copy(a); return m; }
  const g = new THREE.CapsuleGeometry(radius, len, 8, 20);
  const mesh = new THREE.Mesh(g, material);
  mesh.position.copy(a).add(b).multiplyScalar(0.5);
  mesh.quaternion.setFromUnitVectors(new THREE.Vector3(0, 1, 0), b.clone().sub(a).normalize());
  return mesh;
}

// the cell file's bodies (robot/collision.py; pendant/view.py cell_view): boxes, cylinders, STL meshes
// in $WORLD, the tool on the flange, the floor
const cellGroup = new THREE.Group();
world.add(cellGroup);
const cellMaterial = new THREE.MeshStandardMaterial({ color: 0x5f8f63, metalness: 0.1, roughness: 0.8, transparent: true, opacity: 0.75 });
const toolMaterial = new THREE.MeshStandardMaterial({ color: 0xc8b43c, metalness: 0.3, roughness: 0.5 });
let toolMesh = null;

function bodyMesh(b, material) {
  let g;
  if (b.shape === 'box') g = new THREE.BoxGeometry(b.size[0] / 1000, b.size[1] / 1000, b.size[2] / 1000);
  else if (b.shape === 'cylinder') {
    g = new THREE.CylinderGeometry(b.size[0] / 1000, b.size[0] / 1000, b.size[1] / 1000, 32);
    g.rotateX(Math.PI / 2);        // three's cylinder stands on Y; the cell's on its frame's Z
  } else {
    const bytes = Uint8Array.from(atob(b.stl), (c) => c.charCodeAt(0));
    g = new STLLoader().parse(bytes.buffer);
    g.scale(0.001, 0.001, 0.001);  // the STL in mm
  }
  const m = new THREE.Mesh(g, material);
  m.matrixAutoUpdate = false;
  m.matrix.copy(kukaMatrix(b.frame));
  m.name = b.name;
  return m;
}

function drawCell(cell) {
  cellGroup.clear();
  P.cellBodies = 0;
  if (!cell) return;
  for (const b of cell.bodies) { cellGroup.add(bodyMesh(b, cellMaterial)); P.cellBodies++; }
  if (typeof cell.floor === 'number') {
    const floor = new THREE.Mesh(new THREE.PlaneGeometry(6, 6), new THREE.MeshStandardMaterial({ color: 0x3b4650, transparent: true, opacity: 0.35, side: THREE.DoubleSide }));
    floor.position.set(0, 0, cell.floor / 1000);
    cellGroup.add(floor);
  }
  if (cell.tool && tool0) { toolMesh = bodyMesh(cell.tool, toolMaterial); tool0.add(toolMesh); P.cellBodies++; }
}

// the robot of the URDF (robot view r: pendant/view.py robot_view) with its links drawn: the
// description's meshes, else the capsules the collision check gives them
function buildRobot(r) {
  const loader = new URDFLoader();
  loader.parseVisual = false;
  const robot = loader.parse(r.urdf);
  const names = r.joints;
  // the URDF has no meshes (machine data hold none): each link drawn as the capsule the collision
  // check gives it, from its joint to the next joint (the last link a sphere), the radii of the
  // robot view's capsules (m: base column, A1..A3, A4..A6; robot/capsules.py)
  let reach = 0;
  for (const name of names) if (!name.startsWith('joint_e')) reach += robot.joints[name].position.length();
  const caps = r.capsules;
  // a description's meshes (robot/description.py), in the links' frames, metres; the links without
  // one are drawn as limbs
  const meshes = r.meshes || {};
  let meshLinks = 0;
  for (const [link, b64] of Object.entries(meshes)) {
    const target = robot.links[link];
    if (!target) continue;
    const bytes = Uint8Array.from(atob(b64), (c) => c.charCodeAt(0));
    target.add(new THREE.Mesh(new STLLoader().parse(bytes.buffer), link === 'base_link' ? jointMaterial : linkMaterial));
    meshLinks++;
  }
  names.forEach((name, i) => {
    const j = robot.joints[name];
    j.ignoreLimits = true;
    if (name.startsWith('joint_e')) return;
    const child = j.children.find((c) => c.isURDFLink);
    const next = child && child.children.find((c) => c.isURDFJoint && !c.name.startsWith('joint_e'));
    if (!child || meshes[child.name]) return;
    // the flange's joint (tool0) is no axis: the last link is a sphere at its origin, as in robot/mjcf.py
    const to = next && next.name !== 'tool0_joint' && next.jointType !== 'fixed' ? next.position.toArray() : [0, 0, 0];
    child.add(limb([0, 0, 0], to, i < 3 ? caps.arm : caps.wrist));
  });
  const first = robot.joints[names[0]];
  const base = meshes.base_link ? null : limb([0, 0, 0], first.position.toArray(), caps.base, jointMaterial);
  // on the link A1 turns on (base_link, which a track carries), not at the URDF's root
  if (base) (first.parent || robot).add(base);
  return { robot, reach, meshLinks };
}

// the axis map of a robot view: each joint's index in KRL's order and its unit (deg -> rad, mm -> m)
function axisMap(r) {
  return { joints: r.joints, index: r.axis_index || r.joints.map((_, i) => i),
    scale: (r.units || r.joints.map(() => 'deg')).map((u) => (u === 'mm' ? 0.001 : Math.PI / 180)) };
}

function loadRobot(r) {
  const built = buildRobot(r);
  const robot = built.robot;
  const reach = built.reach;
  jointNames = r.joints;
  const map = axisMap(r);
  P.axisIndex = map.index;
  P.axisScale = map.scale;
  P.jogKeys = r.keys;
  buildJogKeys();
  if (P.module) drawPoints(P.module.points || []);   // the robot's external axes are the list's columns
  robotRoot.clear();
  robotRoot.matrixAutoUpdate = false;
  robotRoot.matrix.copy(kukaMatrix(r.robroot));
  robotRoot.add(robot);
  P.meshLinks = built.meshLinks;
  tool0 = robot.links.tool0 || null;
  if (tool0) tool0.add(toolFrame);
  P.robot = robot;
  drawCell(r.cell);
  requestRender();
  const span = Math.max(1.2, reach * 1.05);
  camera.position.set(span * 1.1, span * 0.9, span * 1.2);
  controls.target.set(0, reach * 0.45, 0);
  if (P.cellBodies) {
    // the cell's bodies in view too: aim at the middle of the robot's base and the bodies
    world.updateMatrixWorld(true);
    const box = new THREE.Box3().setFromObject(cellGroup.children.length ? cellGroup : robotRoot);
    box.expandByPoint(new THREE.Vector3(0, reach * 0.45, 0));
    aim(box, span);
  }
  controls.update();
}

function aim(box, span) {
  const c = box.getCenter(new THREE.Vector3());
  const s = Math.max(span, box.getSize(new THREE.Vector3()).length() * 0.6);
  controls.target.copy(c);
  camera.position.set(c.x + s * 1.1, c.y + s * 0.9, c.z + s * 1.2);
}

// a cell of several robots (pendant/cell.py): every robot at its base in the cell's world (its
// $WORLD there: its $ROBROOT and its own cell file's bodies), each moved by its own live axes
const cellRobots = new THREE.Group();
world.add(cellRobots);
function loadCellRobots(list) {
  cellRobots.clear();
  robotRoot.clear();
  cellGroup.clear();
  P.robot = null;
  P.cellRobots = {};
  P.cellBodies = 0;
  let span = 1.2;
  for (const r of list) {
    const placed = new THREE.Group();
    placed.matrixAutoUpdate = false;
    placed.matrix.copy(kukaMatrix(r.base));
    const root = new THREE.Group();
    root.matrixAutoUpdate = false;
    root.matrix.copy(kukaMatrix(r.robroot));
    const built = buildRobot(r);
    root.add(built.robot);
    placed.add(root);
    if (r.cell) for (const b of r.cell.bodies) { placed.add(bodyMesh(b, cellMaterial)); P.cellBodies++; }
    const robotTrail = newTrail();     // its TCP path, in its $WORLD (addPath)
    placed.add(robotTrail.line);
    cellRobots.add(placed);
    P.cellRobots[r.robot] = { robot: built.robot, placed, trail: robotTrail, ...axisMap(r) };
    span = Math.max(span, built.reach * 1.05);
  }
  // each where its run starts (pendant/view.py start_position) until the cell's live poses come
  setCellAxes(Object.fromEntries(list.filter((r) => r.start).map((r) => [r.robot, { axes: r.start.axes }])));
  P.robot = list.length ? P.cellRobots[list[0].robot].robot : null;   // drawn: the page is ready
  world.updateMatrixWorld(true);
  aim(new THREE.Box3().setFromObject(cellRobots), span);
  controls.update();
  requestRender();
}

// a frame only when a joint moved (urdf-loader's setJointValue: true when the value changed): the
// live pose comes at 30 Hz while the program runs, also while it waits and no axis moves
function setCellAxes(robots) {
  let moved = false;
  for (const [name, live] of Object.entries(robots || {})) {
    const c = P.cellRobots && P.cellRobots[name];
    if (!c || !live.axes) continue;
    c.joints.forEach((n, i) => { const v = live.axes[c.index[i]]; if (v !== undefined && c.robot.setJointValue(n, v * c.scale[i])) moved = true; });
  }
  if (moved) requestRender();
}

// a cell robot's rendered joint values (deg, KRL's order), read back from the drawn robot
P.renderedAxesOf = (name) => {
  const c = P.cellRobots && P.cellRobots[name];
  if (!c) return null;
  const out = [];
  c.joints.forEach((n, i) => { out[c.index[i]] = c.robot.joints[n].angle / c.scale[i]; });
  for (let i = 0; i < out.length; i++) if (out[i] === undefined) out[i] = 0;
  return out;
};

function setAxes(axes, tool, base) {
  if (!P.robot || !axes) return;
  // each joint's value from KRL's order (A1..A6, E1..Em: the robot view's axis_index), deg -> rad, mm -> m
  // a frame when a joint moved (setCellAxes) or with the state's $TOOL and $BASE
  let moved = !!(tool || base);
  jointNames.forEach((n, i) => { const v = axes[P.axisIndex[i]]; if (v !== undefined && P.robot.setJointValue(n, v * P.axisScale[i])) moved = true; });
  if (tool) { const f = frameArr(tool); toolFrame.matrixAutoUpdate = false; toolFrame.matrix.copy(kukaMatrix(f)); }
  if (base) { const f = frameArr(base); baseFrame.matrixAutoUpdate = false; baseFrame.matrix.copy(kukaMatrix(f)); }
  P.axesShown = axes.slice();
  if (moved) requestRender();
}

// the rendered joint values (deg), read back from the drawn robot: what the page shows
P.renderedAxes = () => {
  if (!P.robot) return null;
  const out = [];
  jointNames.forEach((n, i) => { out[P.axisIndex[i]] = P.robot.joints[n].angle / P.axisScale[i]; });
  for (let i = 0; i < out.length; i++) if (out[i] === undefined) out[i] = 0;   // a SCARA's A5, A6
  return out;
};

// TCP path: a trail of the drawn TCP, blue on the path, orange inside an approximation; one for
// the robot, one per robot of a cell (in its placed group: its points are in its own $WORLD)
const MAX_PATH = 20000;
function newTrail() {
  const pos = new Float32Array(MAX_PATH * 3);
  const col = new Float32Array(MAX_PATH * 3);
  const geom = new THREE.BufferGeometry();
  geom.setAttribute('position', new THREE.BufferAttribute(pos, 3));
  geom.setAttribute('color', new THREE.BufferAttribute(col, 3));
  geom.setDrawRange(0, 0);
  const line = new THREE.Line(geom, new THREE.LineBasicMaterial({ vertexColors: true }));
  line.frustumCulled = false;
  return { pos, col, geom, line, n: 0 };
}
const trail = newTrail();
world.add(trail.line);
let pathRun = null;
function trailOf(point) {
  const c = point.length > 4 && P.cellRobots ? P.cellRobots[point[4]] : null;
  return c ? c.trail : trail;
}
// the controller's TCP path (pendant/engine.py: $WORLD mm, a point each 2 mm, blending flag; in a
// cell, the robot's name fifth)
function addPath(run, points) {
  const all = [trail, ...Object.values(P.cellRobots || {}).map((c) => c.trail)];
  if (run === pathRun && !points.length) return;       // nothing new to draw
  if (run !== pathRun) { pathRun = run; for (const t of all) t.n = 0; }
  for (const point of points) {
    const [x, y, z, blending] = point;
    const t = trailOf(point);
    if (t.n >= MAX_PATH) { t.pos.copyWithin(0, 3); t.col.copyWithin(0, 3); t.n = MAX_PATH - 1; }
    t.pos.set([x / 1000, y / 1000, z / 1000], t.n * 3);
    t.col.set(blending ? [1, 0.35, 0] : [0, 0.78, 1], t.n * 3);
    t.n++;
  }
  for (const t of all) {
    t.geom.setDrawRange(0, t.n);
    t.geom.attributes.position.needsUpdate = true;
    t.geom.attributes.color.needsUpdate = true;
  }
  P.pathPoints = trail.n;
  requestRender();
}
// a cell robot's drawn TCP path in the cell's world (mm): its points placed by its base
P.cellPathOf = (name) => {
  const c = P.cellRobots && P.cellRobots[name];
  if (!c) return null;
  const out = [];
  const v = new THREE.Vector3();
  for (let i = 0; i < c.trail.n; i++) {
    v.fromArray(c.trail.pos, i * 3).applyMatrix4(c.placed.matrix);
    out.push([v.x * 1000, v.y * 1000, v.z * 1000]);
  }
  return out;
};

const pointsGroup = new THREE.Group();
world.add(pointsGroup);
function showPoints(points) {
  pointsGroup.clear();
  const g = new THREE.SphereGeometry(0.012, 12, 8);
  const mat = new THREE.MeshBasicMaterial({ color: 0xf2c94c });
  for (const p of points) {
    if (!p.world) continue;
    const s = new THREE.Mesh(g, mat);
    s.position.set(p.world[0] / 1000, p.world[1] / 1000, p.world[2] / 1000);
    s.name = p.name;
    pointsGroup.add(s);
  }
  requestRender();
}

function onLive(m) {
  P.live = m;
  if (typeof m.time === 'number') $('st-time').textContent = `t = ${m.time.toFixed(3)} s`;
  if (m.robots) setCellAxes(m.robots); else setAxes(m.axes);
  if (m.path) addPath(m.run, m.path);
  // the pointers of a cycle newer than the last state (at a stop the state, taken after the
  // last cycle, is the newer one even at the same simulated time)
  if (m.pointers && P.state && typeof P.state.time === 'number' && m.time > P.state.time + 1e-9) {
    P.state.pointers = { ...P.state.pointers, ...m.pointers };
    drawPointers(P.state.pointers, P.state.breakpoints || {});
  }
}

function resize() {
  const box = $('view3d');
  const w = box.clientWidth || 1;
  const h = box.clientHeight || 1;
  renderer.setSize(w, h, false);
  camera.aspect = w / h;
  camera.updateProjectionMatrix();
}
// render on demand: a frame when the pose, the path, the frames or the camera changed (a
// software-rendered WebGL page at 60 Hz would take the CPU the simulation needs)
let framePending = false;
function requestRender() {
  if (framePending) return;
  framePending = true;
  requestAnimationFrame(() => {
    framePending = false;
    resize();
    renderer.render(scene, camera);
    P.frames++;
  });
}
P.requestRender = requestRender;
// true while a frame is asked for and not drawn yet (the tests wait for the drawn frame)
P.renderPending = () => framePending;
window.addEventListener('resize', requestRender);
controls.addEventListener('change', requestRender);
requestRender();
connect();
