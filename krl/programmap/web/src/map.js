// The interactive program map of `krl graph --format html` (krl/programmap/templates/graph.html.j2).
//
// The page carries the map as JSON in <script type="application/json" id="map-data"> (written by
// Jinja's tojson: no markup can close it). Everything from the backup reaches the page as text:
// node labels are drawn by cytoscape on a canvas, and the panels are built with textContent, never
// innerHTML. Links to a routine's file:line use the href the Python side built (file: or vscode:
// scheme, or none).
//
// Views: the overview (the backup's modules grouped by folder, each folder one node; KUKA's system
// software folded into one node), a folder opened to its modules, a module opened to its routines,
// "Expand all" (every folder and module of the backup's own open; KUKA's software stays folded
// unless "KUKA's system software" is ticked), and the neighbourhood of one routine (its callers and
// callees to a chosen depth). Layout: elkjs -- the overview's nodes and a module's routines with the
// layered algorithm (left to right), open folders and the top level around them packed into rows
// of the map's aspect ratio (rectpacking), so a whole backup fits the window; positions handed to
// cytoscape as a preset layout. Zoom and pan are cytoscape's (wheel, drag, the +/- and fit buttons).

import cytoscape from 'cytoscape';
import ELK from 'elkjs/lib/elk.bundled.js';

const KUKA = 'group:KUKA';
const EDGE_COLOURS = { call: '#555', interrupt: '#aa1111', trigger: '#176b2c', run: '#224466', eki: '#777' };

function $(id) {
  return document.getElementById(id);
}

function el(tag, text, attrs) {
  const e = document.createElement(tag);
  if (text !== undefined && text !== null) e.textContent = String(text);
  for (const [k, v] of Object.entries(attrs || {})) e.setAttribute(k, v);
  return e;
}

const data = JSON.parse($('map-data').textContent);
const nodes = new Map(data.nodes.map((n) => [n.id, n]));
const out = new Map();
const inc = new Map();
for (const e of data.edges) {
  if (!out.has(e.source)) out.set(e.source, []);
  if (!inc.has(e.target)) inc.set(e.target, []);
  out.get(e.source).push(e);
  inc.get(e.target).push(e);
}
const moduleOf = (n) => 'module:' + (n.system ? 'K:' : 'U:') + n.module.toUpperCase();
// what the controller starts stays in view even when it is KUKA's file (sps.sub in System/)
const KEEP = new Set(['cell', 'plc', 'submit', 'selected']);
const modules = new Map();
for (const n of data.nodes) {
  const m = moduleOf(n);
  if (!modules.has(m)) {
    modules.set(m, { id: m, name: n.kind === 'channel' ? 'EKI channels' : n.module, system: n.system, routines: [],
      folder: n.kind === 'channel' ? '' : String(n.file || '').split('/').slice(0, -1).join('/'), keep: false });
  }
  modules.get(m).routines.push(n.id);
  if (KEEP.has(n.entry_kind)) modules.get(m).keep = true;
}
const folded = (m) => m.system && !m.keep;
// folders of the backup's own holding two or more modules are one group each
const folders = new Map();
for (const m of modules.values()) {
  if (folded(m) || !m.folder) continue;
  const id = 'folder:' + m.folder;
  if (!folders.has(id)) folders.set(id, { id, name: m.folder, modules: [] });
  folders.get(id).modules.push(m.id);
}
for (const [id, f] of [...folders]) if (f.modules.length < 2) folders.delete(id);
// folder labels without the part every folder shares (R1/Program/)
{
  const paths = [...folders.values()].map((f) => f.name.split('/'));
  let common = 0;
  while (paths.length > 1 && paths.every((p) => p.length > common + 1 && p[common] === paths[0][common])) common += 1;
  for (const f of folders.values()) f.label = f.name.split('/').slice(common).join('/');
}
const folderOf = (m) => (!folded(m) && m.folder && folders.has('folder:' + m.folder) ? 'folder:' + m.folder : null);
const kukaCount = data.nodes.filter((x) => x.system && folded(modules.get(moduleOf(x)))).length;

const state = { expanded: new Set(), focus: null, depth: 1, selected: null, kuka: false };

const measure = document.createElement('canvas').getContext('2d');
measure.font = '12px sans-serif';
function width(label) {
  return Math.max(...String(label).split('\n').map((l) => measure.measureText(l).width)) + 16;
}
function height(label) {
  return 10 + 15 * String(label).split('\n').length;
}

// ---------------------------------------------------------------- what is shown

function visibleOf(id) {
  const n = nodes.get(id);
  if (state.focus !== null) return id;
  const m = modules.get(moduleOf(n));
  if (folded(m) && !state.kuka) return KUKA;
  const f = folderOf(m);
  if (f && !state.expanded.has(f)) return f;
  return state.expanded.has(m.id) ? id : m.id;
}

// a module of one routine named as the module, open: the routine alone stands for it
const bare = (m) => m.routines.length === 1 && nodes.get(m.routines[0]).name.toUpperCase() === m.name.toUpperCase();

function neighbourhood(id, depth) {
  const seen = new Set([id]);
  let frontier = [id];
  for (let d = 0; d < depth; d++) {
    const next = [];
    for (const x of frontier) {
      for (const e of out.get(x) || []) if (!seen.has(e.target)) { seen.add(e.target); next.push(e.target); }
      for (const e of inc.get(x) || []) if (!seen.has(e.source)) { seen.add(e.source); next.push(e.source); }
    }
    frontier = next;
  }
  return seen;
}

function plural(n, word) {
  return `${n} ${word}${n === 1 ? '' : 's'}`;
}

function view() {
  const shown = state.focus !== null ? neighbourhood(state.focus, state.depth) : new Set(nodes.keys());
  const vnodes = new Map();
  // the container of a visible module or folder, created open with its own container
  const container = (id) => {
    if (id === null || vnodes.has(id)) return id;
    if (id === KUKA) {
      vnodes.set(id, { id, label: "KUKA's system software", type: 'group', parent: null, expanded: true, system: true });
    } else if (folders.has(id)) {
      vnodes.set(id, { id, label: folders.get(id).label, type: 'folder', parent: null, expanded: true });
    } else {
      const m = modules.get(id);
      const parent = state.focus !== null ? null : folded(m) ? KUKA : folderOf(m);
      container(parent);
      vnodes.set(id, { id, label: m.name, type: 'module', parent, expanded: true, system: m.system });
    }
    return id;
  };
  const summary = (ids) => {
    const rs = ids.map((r) => nodes.get(r)).filter((r) => r.kind === 'routine');
    // what the controller starts is an entry; a group nothing the controller starts reaches, but
    // operator selection does, is operator-only
    return { entry: rs.some((r) => KEEP.has(r.entry_kind)), dead: rs.length > 0 && rs.every((r) => r.unreachable),
      operator: rs.some((r) => r.reach === 'operator') && !rs.some((r) => r.reach === 'controller'),
      logbook: rs.some((r) => r.logbook) };
  };
  for (const id of shown) {
    const v = visibleOf(id);
    const n = nodes.get(id);
    if (v === id) {
      const m = modules.get(moduleOf(n));
      let parent = m.id;
      if (bare(m) && state.focus === null) {
        parent = folded(m) ? KUKA : folderOf(m);
        container(parent);
      } else container(m.id);
      vnodes.set(id, { id, label: n.kind === 'channel' ? 'EKI ' + n.name : n.name, type: n.kind, parent, node: n });
    } else if (!vnodes.has(v)) {
      if (v === KUKA) {
        vnodes.set(v, { id: v, label: `KUKA's system software\n${plural(kukaCount, 'routine')}`, type: 'group',
          parent: null, expanded: false, system: true });
      } else if (folders.has(v)) {
        const f = folders.get(v);
        const ids = f.modules.flatMap((m) => modules.get(m).routines);
        vnodes.set(v, { id: v, label: `${f.label}\n${plural(f.modules.length, 'module')} · ${plural(ids.length, 'routine')}`,
          type: 'folder', parent: null, expanded: false, ...summary(ids) });
      } else {
        const m = modules.get(v);
        const parent = folded(m) ? KUKA : folderOf(m);
        container(parent);
        vnodes.set(v, { id: v, label: `${m.name}\n${plural(m.routines.length, 'routine')}`, type: 'module',
          parent, expanded: false, system: m.system, ...summary(m.routines) });
      }
    }
  }
  const vedges = new Map();
  for (const e of data.edges) {
    if (!shown.has(e.source) || !shown.has(e.target)) continue;
    const s = visibleOf(e.source);
    const t = visibleOf(e.target);
    if (s === t && s !== e.source) continue;       // inside one collapsed module or folder
    const key = `${s}->${t}:${e.kind}`;
    if (!vedges.has(key)) vedges.set(key, { id: 'e' + vedges.size, source: s, target: t, kind: e.kind, count: 0 });
    vedges.get(key).count += 1;
  }
  return { nodes: [...vnodes.values()], edges: [...vedges.values()] };
}

// ---------------------------------------------------------------- layout and drawing

const elk = new ELK();

async function layout(v) {
  const elkNode = new Map();
  for (const n of v.nodes) {
    const lines = String(n.label).split('\n').length;
    elkNode.set(n.id, n.expanded ? { id: n.id, children: [], edges: [], layoutOptions: {} }
      : { id: n.id, width: width(n.label), height: height(n.label) });
  }
  const root = { id: 'root', children: [], edges: [] };
  const parentOf = new Map();
  for (const n of v.nodes) {
    const e = elkNode.get(n.id);
    const p = n.parent && elkNode.has(n.parent) ? elkNode.get(n.parent) : root;
    p.children.push(e);
    parentOf.set(n.id, p);
  }
  // an open container that has nothing in view keeps a size
  for (const e of elkNode.values()) if (e.children && e.children.length === 0) { delete e.children; e.width = 120; e.height = 30; }
  const box = $('map').getBoundingClientRect();
  const aspect = String(Math.max(0.5, Math.min(3, (box.width || 1200) / (box.height || 700))));
  const layered = { 'elk.algorithm': 'layered', 'elk.direction': 'RIGHT', 'elk.aspectRatio': aspect,
    'elk.layered.spacing.nodeNodeBetweenLayers': '50', 'elk.spacing.nodeNode': '16',
    'elk.spacing.componentComponent': '30', 'elk.edgeRouting': 'POLYLINE' };
  const packed = { 'elk.algorithm': 'rectpacking', 'elk.aspectRatio': aspect, 'elk.spacing.nodeNode': '10',
    'elk.padding': '[top=24,left=8,bottom=8,right=8]' };
  const open = v.nodes.some((n) => n.expanded);
  const edges = v.edges.filter((e) => e.source !== e.target);
  if (state.focus !== null || !open) {
    // the neighbourhood of a routine, or the overview of closed nodes: one layered graph
    Object.assign(root, { layoutOptions: { ...layered, 'elk.hierarchyHandling': 'INCLUDE_CHILDREN' },
      edges: edges.map((e) => ({ id: e.id, sources: [e.source], targets: [e.target] })) });
    for (const e of elkNode.values()) if (e.children) e.layoutOptions = { 'elk.padding': '[top=30,left=12,bottom=12,right=12]' };
  } else {
    // open folders and modules: each container is laid out on its own (a module's routines
    // layered along its own calls, a folder's modules and the top level packed into rows)
    root.layoutOptions = { ...packed, 'elk.padding': '[top=12,left=12,bottom=12,right=12]' };
    for (const n of v.nodes) {
      const e = elkNode.get(n.id);
      if (e.children) {
        e.layoutOptions = n.type === 'module' ? { ...layered, 'elk.padding': '[top=24,left=8,bottom=8,right=8]',
          'elk.layered.spacing.nodeNodeBetweenLayers': '30', 'elk.spacing.nodeNode': '8' } : packed;
      }
    }
    for (const e of edges) {
      const p = parentOf.get(e.source);
      if (p && p === parentOf.get(e.target) && p !== root) p.edges.push({ id: e.id, sources: [e.source], targets: [e.target] });
    }
  }
  const res = await elk.layout(root);
  const pos = {};
  const walk = (n, ox, oy) => {
    for (const c of n.children || []) {
      const x = ox + c.x;
      const y = oy + c.y;
      if (!c.children || c.children.length === 0) pos[c.id] = { x: x + c.width / 2, y: y + c.height / 2 };
      walk(c, x, y);
    }
  };
  walk(res, 0, 0);
  return pos;
}

const cy = cytoscape({
  container: $('map'),
  minZoom: 0.05,
  maxZoom: 4,
  style: [
    { selector: 'node', style: {
      label: 'data(label)', 'text-wrap': 'wrap', 'text-valign': 'center', 'text-halign': 'center', 'font-size': 12,
      shape: 'round-rectangle', width: 'data(w)', height: 'data(h)', 'background-color': '#fff',
      'border-width': 1, 'border-color': '#8895a7' } },
    { selector: 'node.entry', style: { 'border-width': 3, 'border-color': '#224466', 'border-style': 'double' } },
    { selector: 'node.operator', style: { 'border-color': '#b36b00', 'border-style': 'dashed', 'border-width': 2 } },
    { selector: 'node.unknown', style: { 'border-style': 'dotted', 'border-width': 2 } },
    { selector: 'node.unreachable', style: { 'background-color': '#eeeeee', color: '#666', 'border-style': 'dashed' } },
    { selector: 'node.collapsed', style: { 'background-color': '#eaf0f8', 'font-weight': 'bold' } },
    { selector: 'node.folder.collapsed', style: { shape: 'cut-rectangle', 'background-color': '#e3ecf7' } },
    { selector: 'node.entry.operator', style: { 'border-width': 3, 'border-color': '#b36b00', 'border-style': 'double' } },
    { selector: 'node.system', style: { 'background-color': '#fff3e0' } },
    { selector: 'node.channel', style: { shape: 'tag', 'background-color': '#f4f4f4' } },
    { selector: ':parent', style: {
      'text-valign': 'top', 'text-halign': 'center', 'background-color': '#f6f8fb', 'background-opacity': 0.6,
      'border-color': '#b8c2d0', 'font-weight': 'bold', padding: 6 } },
    { selector: ':parent.system', style: { 'background-color': '#fff8ee' } },
    { selector: 'node.logbook', style: { 'underlay-color': '#c0392b', 'underlay-opacity': 0.25, 'underlay-padding': 5 } },
    { selector: 'node.match', style: { 'overlay-color': '#ffd000', 'overlay-opacity': 0.35, 'overlay-padding': 4 } },
    { selector: 'node:selected', style: { 'border-width': 3, 'border-color': '#e36209' } },
    { selector: 'node.focus', style: { 'border-width': 4, 'border-color': '#e36209' } },
    { selector: 'edge', style: {
      width: 1.2, 'curve-style': 'bezier', 'target-arrow-shape': 'triangle', 'arrow-scale': 0.9,
      'line-color': 'data(colour)', 'target-arrow-color': 'data(colour)', label: 'data(label)', 'font-size': 9,
      'text-background-color': '#fff', 'text-background-opacity': 0.8, 'text-background-padding': 1 } },
    { selector: 'edge.interrupt, edge.trigger', style: { 'line-style': 'dashed' } },
    { selector: 'edge.eki', style: { 'line-style': 'dotted' } },
    { selector: 'edge.run', style: { width: 2.5 } },
    { selector: 'edge.to-system', style: { opacity: 0.3 } },
    // many edges (folders and modules open): faint, those of the selected node drawn in full
    { selector: 'edge.faint', style: { opacity: 0.18, label: '' } },
    { selector: 'edge.hl', style: { opacity: 1, width: 2, 'z-index': 10, label: 'data(label)' } },
  ],
});

// below this zoom (12 px labels drawn under 6 px) a fitted view is zoomed in on what matters
const READABLE_ZOOM = 0.5;

cy.on('select', 'node', (evt) => evt.target.connectedEdges().addClass('hl'));
cy.on('unselect', 'node', (evt) => evt.target.connectedEdges().removeClass('hl'));

let rendering = Promise.resolve();

function render() {
  rendering = rendering.then(async () => {
    document.body.dataset.ready = '0';
    const v = view();
    const pos = await layout(v);
    const els = [];
    for (const n of v.nodes) {
      const classes = [n.type === 'routine' ? 'routine' : n.type];
      const info = n.node || {};
      if (!n.expanded && (n.type === 'module' || n.type === 'group' || n.type === 'folder')) classes.push('collapsed');
      if (n.system || info.system || n.type === 'group') classes.push('system');
      if ((info.entry && info.entry_kind !== 'system') || n.entry) classes.push('entry');
      if (info.unreachable || n.dead) classes.push('unreachable');
      else if ((info.reach === 'operator' && !info.system) || n.operator) classes.push('operator');
      else if (info.reach === 'unknown') classes.push('unknown');
      if (info.logbook || n.logbook) classes.push('logbook');
      if (n.id === state.focus) classes.push('focus');
      els.push({ group: 'nodes', data: { id: n.id, label: n.label, parent: n.parent || undefined,
        w: width(n.label), h: height(n.label) }, classes: classes.join(' ') });
    }
    const faint = v.edges.length > 60 && v.nodes.some((n) => n.expanded) && state.focus === null;
    for (const e of v.edges) {
      const label = (e.kind !== 'call' ? e.kind : '') + (e.count > 1 ? (e.kind !== 'call' ? ' ' : '') + '×' + e.count : '');
      els.push({ group: 'edges', data: { id: e.id, source: e.source, target: e.target, label,
        colour: EDGE_COLOURS[e.kind] || '#555' },
      classes: e.kind + (e.target === KUKA ? ' to-system' : '') + (faint ? ' faint' : '') });
    }
    cy.startBatch();
    cy.elements().remove();
    cy.add(els);
    cy.endBatch();
    cy.layout({ name: 'preset', positions: (n) => pos[n.id()] || { x: 0, y: 0 }, fit: true, padding: 20 }).run();
    if (cy.zoom() < READABLE_ZOOM) {
      // readable labels first: zoom in on the routine in focus, else the first entry point
      const first = data.nodes.find((n) => n.entry_kind === 'cell') || data.nodes.find((n) => n.entry);
      const anchor = state.focus !== null ? cy.getElementById(state.focus)
        : first ? cy.getElementById(visibleOf(first.id)) : cy.nodes();
      cy.zoom(0.7);
      cy.center(anchor.length ? anchor : cy.nodes());
    }
    $('map-view').textContent = state.focus !== null
      ? `Neighbourhood of ${nodes.get(state.focus).name} (${nodes.get(state.focus).module}), depth ${state.depth}: ${cy.nodes().filter((n) => !n.isParent()).length} nodes`
      : `Overview: ${cy.nodes().filter((n) => !n.isParent()).length} nodes (click a folder or module to open it)`;
    document.body.dataset.view = state.focus !== null ? 'neighbourhood' : 'overview';
    document.body.dataset.ready = '1';
  }).catch((err) => {
    $('map-view').textContent = 'The layout failed: ' + err;
    document.body.dataset.ready = 'error';
  });
  return rendering;
}

// ---------------------------------------------------------------- panels

function routineButton(id, text) {
  const b = el('button', text, { type: 'button', class: 'routine-link', 'data-id': id });
  b.addEventListener('click', () => focus(id));
  return b;
}

function sourceLink(n, id) {
  // the routine's file:line, opening its source in the page (its own lines travel in the JSON)
  const where = `${n.file}:${n.line}`;
  if (!n.source || !n.source.length) return n.href ? el('a', where, { href: n.href }) : el('code', where);
  const attrs = { href: '#source=' + encodeURIComponent(n.id), class: 'source-link' };
  if (id) attrs.id = id;
  return el('a', where, attrs);
}

function showSource(id) {
  const n = nodes.get(id);
  const box = $('source');
  box.replaceChildren();
  if (!n) { box.hidden = true; return; }
  const head = el('p');
  head.append(el('strong', n.name));
  head.append(document.createTextNode(` ${n.module} `));
  head.append(el('code', `${n.file}:${n.line}`, { id: 'source-where' }));
  if (n.href) {
    head.append(document.createTextNode(' '));
    head.append(el('a', data.links === 'vscode' ? 'open in VS Code' : 'open the file', { href: n.href, id: 'source-file' }));
  }
  const close = el('button', 'Close', { type: 'button' });
  close.addEventListener('click', () => { box.hidden = true; history.replaceState(null, '', '#'); });
  head.append(document.createTextNode(' '));
  head.append(close);
  box.append(head);
  const pre = el('pre', null, { id: 'source-text' });
  n.source.forEach((text, i) => {
    const line = el('span', null, { class: 'src-line' + (i === 0 ? ' src-def' : ''), 'data-line': String(n.line + i) });
    line.append(el('span', String(n.line + i).padStart(5, ' ') + '  ', { class: 'src-no' }));
    line.append(document.createTextNode(text + '\n'));
    pre.append(line);
  });
  box.append(pre);
  box.hidden = false;
  box.scrollIntoView({ block: 'nearest' });
}

function onHash() {
  const m = /^#source=(.*)$/.exec(location.hash);
  if (m) showSource(decodeURIComponent(m[1]));
}
window.addEventListener('hashchange', onHash);

function showDetails(id) {
  const box = $('details');
  box.replaceChildren();
  state.selected = id;
  if (nodes.has(id)) {
    const n = nodes.get(id);
    box.append(el('h2', n.kind === 'channel' ? 'EKI channel ' + n.name : n.name));
    if (n.kind === 'routine') {
      box.append(el('p', `module ${n.module}${n.system ? " (KUKA's system software)" : ''}`));
      const p = el('p');
      p.append(sourceLink(n, 'source-link'));
      box.append(p);
      if (n.entry) box.append(el('p', 'entry point: ' + n.entry, { class: 'entry-why' }));
      if (n.unreachable) box.append(el('p', 'unreachable: no entry point starts it', { class: 'bad' }));
      if (n.logbook) box.append(el('p', 'logbook: ' + n.logbook, { class: 'logbook-why' }));
    }
    const nb = el('button', 'Show its neighbourhood', { type: 'button', id: 'show-neighbourhood' });
    nb.addEventListener('click', () => focus(id));
    box.append(nb);
    for (const [title, list, end] of [['called by', inc.get(id) || [], 'source'], ['calls', out.get(id) || [], 'target']]) {
      const seen = new Set();
      const distinct = list.filter((e) => !seen.has(e[end] + ' ' + e.kind) && seen.add(e[end] + ' ' + e.kind));
      box.append(el('h3', `${title} (${distinct.length})`));
      const ul = el('ul', null, { class: title.replace(' ', '-') });
      for (const e of distinct) {
        const other = e[end];
        const li = el('li');
        const o = nodes.get(other);
        li.append(routineButton(other, o.name));
        li.append(document.createTextNode(` ${o.module}${e.kind !== 'call' ? ' (' + e.kind + ')' : ''} `));
        li.append(el('code', `${e.file}:${e.line}`));
        ul.append(li);
      }
      box.append(ul);
    }
  } else if (folders.has(id)) {
    const f = folders.get(id);
    box.append(el('h2', f.name));
    const b = el('button', state.expanded.has(id) ? 'Collapse' : 'Expand', { type: 'button', id: 'toggle-module' });
    b.addEventListener('click', () => toggle(id));
    box.append(b);
    const ul = el('ul');
    for (const mid of f.modules) {
      const m = modules.get(mid);
      const li = el('li', `${m.name} (${plural(m.routines.length, 'routine')})`);
      ul.append(li);
    }
    box.append(ul);
  } else if (modules.has(id) || id === KUKA) {
    const m = modules.get(id);
    box.append(el('h2', m ? m.name : "KUKA's system software"));
    const open = id === KUKA ? state.kuka : state.expanded.has(id);
    const b = el('button', open ? 'Collapse' : 'Expand', { type: 'button', id: 'toggle-module' });
    b.addEventListener('click', () => toggle(id));
    box.append(b);
    if (m) {
      const ul = el('ul');
      for (const r of m.routines) {
        const li = el('li');
        li.append(routineButton(r, nodes.get(r).name));
        li.append(document.createTextNode(' '));
        li.append(sourceLink(nodes.get(r)));
        ul.append(li);
      }
      box.append(ul);
    }
  }
}

function toggle(id) {
  if (id === KUKA) {
    state.kuka = !state.kuka;
    $('map-show-kuka').checked = state.kuka;
  } else if (state.expanded.has(id)) state.expanded.delete(id);
  else state.expanded.add(id);
  state.focus = null;
  showDetails(id);
  return render();
}

function focus(id) {
  state.focus = id;
  showDetails(id);
  return render().then(() => { const n = cy.getElementById(id); n.select(); });
}

function overview() {
  state.focus = null;
  return render();
}

cy.on('tap', 'node', (evt) => {
  const id = evt.target.id();
  if (nodes.has(id)) {
    showDetails(id);
  } else if (!state.expanded.has(id) || state.focus === null) {
    if (evt.target.hasClass('collapsed')) toggle(id);
    else showDetails(id);
  }
});
cy.on('dbltap', 'node', (evt) => {
  const id = evt.target.id();
  if (nodes.has(id)) focus(id);
  else toggle(id);
});

// ---------------------------------------------------------------- search

function matches(q) {
  const s = q.trim().toUpperCase();
  if (!s) return [];
  const hits = [];
  for (const n of data.nodes) {
    const full = (n.module + ':' + n.name).toUpperCase();
    if (n.name.toUpperCase().includes(s) || full.includes(s)) hits.push(n);
  }
  hits.sort((a, b) => (b.name.toUpperCase() === s) - (a.name.toUpperCase() === s)
    || (b.name.toUpperCase().startsWith(s)) - (a.name.toUpperCase().startsWith(s)) || a.name.localeCompare(b.name));
  return hits;
}

function showMatches() {
  const q = $('map-search').value;
  const hits = matches(q);
  const ul = $('search-results');
  ul.replaceChildren();
  for (const n of hits.slice(0, 30)) {
    const li = el('li');
    li.append(routineButton(n.id, n.name));
    li.append(document.createTextNode(` ${n.module} `));
    li.append(el('code', `${n.file}:${n.line}`));
    ul.append(li);
  }
  if (hits.length > 30) ul.append(el('li', `… ${hits.length - 30} more`));
  if (q.trim() && !hits.length) ul.append(el('li', 'no routine matches'));
  cy.nodes().removeClass('match');
  const ids = new Set(hits.map((n) => visibleOf(n.id)));
  cy.nodes().filter((n) => ids.has(n.id())).addClass('match');
}

$('map-search').addEventListener('input', showMatches);
$('map-search').addEventListener('keydown', (evt) => {
  if (evt.key === 'Enter') {
    const hits = matches($('map-search').value);
    if (hits.length) focus(hits[0].id);
  }
});
$('map-overview').addEventListener('click', () => overview());
$('map-depth').addEventListener('change', () => {
  state.depth = Number($('map-depth').value) || 1;
  if (state.focus !== null) render();
});
$('map-fit').addEventListener('click', () => cy.fit(undefined, 20));
$('map-zoom-in').addEventListener('click', () => cy.zoom({ level: cy.zoom() * 1.25, renderedPosition: { x: cy.width() / 2, y: cy.height() / 2 } }));
$('map-zoom-out').addEventListener('click', () => cy.zoom({ level: cy.zoom() / 1.25, renderedPosition: { x: cy.width() / 2, y: cy.height() / 2 } }));
$('map-expand-all').addEventListener('click', () => {
  // every folder and module of the backup's own; KUKA's software as the check box says
  for (const f of folders.keys()) state.expanded.add(f);
  for (const m of modules.values()) if (!folded(m) || state.kuka) state.expanded.add(m.id);
  return overview();
});
$('map-collapse-all').addEventListener('click', () => { state.expanded.clear(); return overview(); });
$('map-show-kuka').addEventListener('change', () => {
  state.kuka = $('map-show-kuka').checked;
  return overview();
});

window.krlMap = { cy, state, focus, overview, toggle, render, showSource };
render().then(onHash);
