// The interactive program map of `krl graph --format html` (krl/programmap/templates/graph.html.j2).
//
// The page carries the map as JSON in <script type="application/json" id="map-data"> (written by
// Jinja's tojson: no markup can close it). Everything from the backup reaches the page as text:
// node labels are drawn by cytoscape on a canvas, and the panels are built with textContent, never
// innerHTML. Links to a routine's file:line use the href the Python side built (file: or vscode:
// scheme, or none).
//
// Views: the overview (modules collapsed to one node each, KUKA's system software to one node), a
// module expanded to its routines, and the neighbourhood of one routine (its callers and callees
// to a chosen depth). Layout: elkjs's layered algorithm (left to right), positions handed to
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
const modules = new Map();
for (const n of data.nodes) {
  const m = moduleOf(n);
  if (!modules.has(m)) modules.set(m, { id: m, name: n.kind === 'channel' ? 'EKI channels' : n.module, system: n.system, routines: [] });
  modules.get(m).routines.push(n.id);
}

const state = { expanded: new Set(), focus: null, depth: 1, selected: null };

const measure = document.createElement('canvas').getContext('2d');
measure.font = '12px sans-serif';
function width(label) {
  return Math.max(...String(label).split('\n').map((l) => measure.measureText(l).width)) + 24;
}

// ---------------------------------------------------------------- what is shown

function visibleOf(id) {
  const n = nodes.get(id);
  if (state.focus !== null) return id;
  if (n.system && !state.expanded.has(KUKA)) return KUKA;
  const m = moduleOf(n);
  return state.expanded.has(m) ? id : m;
}

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

function view() {
  const shown = state.focus !== null ? neighbourhood(state.focus, state.depth) : new Set(nodes.keys());
  const vnodes = new Map();
  const addParent = (id) => {
    if (vnodes.has(id)) return;
    if (id === KUKA) {
      vnodes.set(id, { id, label: "KUKA's system software", type: 'group', parent: null, expanded: true });
      return;
    }
    const m = modules.get(id);
    const parent = m.system && state.focus === null ? KUKA : null;
    if (parent) addParent(parent);
    vnodes.set(id, { id, label: m.name, type: 'module', parent, expanded: true, system: m.system });
  };
  for (const id of shown) {
    const v = visibleOf(id);
    const n = nodes.get(id);
    if (v === id) {
      const m = moduleOf(n);
      addParent(m);
      vnodes.set(id, { id, label: n.kind === 'channel' ? 'EKI ' + n.name : n.name, type: n.kind, parent: m, node: n });
    } else if (!vnodes.has(v)) {
      if (v === KUKA) {
        const count = data.nodes.filter((x) => x.system).length;
        vnodes.set(v, { id: v, label: `KUKA's system software\n${count} routines`, type: 'group', parent: null, expanded: false });
      } else {
        const m = modules.get(v);
        const parent = m.system ? KUKA : null;
        if (parent && state.expanded.has(KUKA)) addParent(parent);
        const count = m.routines.length;
        vnodes.set(v, { id: v, label: `${m.name}\n${count} routine${count === 1 ? '' : 's'}`, type: 'module',
          parent: parent && state.expanded.has(KUKA) ? parent : null, expanded: false, system: m.system,
          entry: m.routines.some((r) => nodes.get(r).entry), unreachable: m.routines.every((r) => nodes.get(r).unreachable) });
      }
    }
  }
  const vedges = new Map();
  for (const e of data.edges) {
    if (!shown.has(e.source) || !shown.has(e.target)) continue;
    const s = visibleOf(e.source);
    const t = visibleOf(e.target);
    if (s === t && s !== e.source) continue;       // inside one collapsed module
    const key = `${s}->${t}:${e.kind}`;
    if (!vedges.has(key)) vedges.set(key, { id: 'e' + vedges.size, source: s, target: t, kind: e.kind, count: 0 });
    vedges.get(key).count += 1;
  }
  return { nodes: [...vnodes.values()], edges: [...vedges.values()] };
}

// ---------------------------------------------------------------- layout and drawing

const elk = new ELK();

async function layout(v) {
  const children = new Map();
  const elkNode = new Map();
  for (const n of v.nodes) {
    const leaf = !n.expanded;
    const lines = String(n.label).split('\n').length;
    const e = leaf ? { id: n.id, width: width(n.label), height: 16 + 15 * lines }
      : { id: n.id, children: [], layoutOptions: { 'elk.padding': '[top=30,left=12,bottom=12,right=12]' } };
    elkNode.set(n.id, e);
  }
  const roots = [];
  for (const n of v.nodes) {
    const e = elkNode.get(n.id);
    if (n.parent && elkNode.has(n.parent)) elkNode.get(n.parent).children.push(e);
    else roots.push(e);
    children.set(n.id, e);
  }
  // an expanded module that has no routine in view keeps a size
  for (const e of elkNode.values()) if (e.children && e.children.length === 0) { delete e.children; e.width = 120; e.height = 30; }
  const graph = {
    id: 'root',
    layoutOptions: {
      'elk.algorithm': 'layered', 'elk.direction': 'RIGHT', 'elk.hierarchyHandling': 'INCLUDE_CHILDREN',
      'elk.layered.spacing.nodeNodeBetweenLayers': '50', 'elk.spacing.nodeNode': '16',
      'elk.spacing.componentComponent': '40', 'elk.edgeRouting': 'POLYLINE',
    },
    children: roots,
    edges: v.edges.filter((e) => e.source !== e.target).map((e) => ({ id: e.id, sources: [e.source], targets: [e.target] })),
  };
  const res = await elk.layout(graph);
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
    { selector: 'node.unreachable', style: { 'background-color': '#eeeeee', color: '#666', 'border-style': 'dashed' } },
    { selector: 'node.collapsed', style: { 'background-color': '#eaf0f8', 'font-weight': 'bold' } },
    { selector: 'node.system', style: { 'background-color': '#fff3e0' } },
    { selector: 'node.channel', style: { shape: 'tag', 'background-color': '#f4f4f4' } },
    { selector: ':parent', style: {
      'text-valign': 'top', 'text-halign': 'center', 'background-color': '#f6f8fb', 'background-opacity': 0.6,
      'border-color': '#b8c2d0', 'font-weight': 'bold', padding: 10 } },
    { selector: ':parent.system', style: { 'background-color': '#fff8ee' } },
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
  ],
});

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
      if (!n.expanded && (n.type === 'module' || n.type === 'group')) classes.push('collapsed');
      if (n.system || info.system || n.type === 'group') classes.push('system');
      if (info.entry || n.entry) classes.push('entry');
      if (info.unreachable || n.unreachable) classes.push('unreachable');
      if (n.id === state.focus) classes.push('focus');
      els.push({ group: 'nodes', data: { id: n.id, label: n.label, parent: n.parent || undefined,
        w: width(n.label), h: 16 + 15 * String(n.label).split('\n').length }, classes: classes.join(' ') });
    }
    for (const e of v.edges) {
      const label = (e.kind !== 'call' ? e.kind : '') + (e.count > 1 ? (e.kind !== 'call' ? ' ' : '') + '×' + e.count : '');
      els.push({ group: 'edges', data: { id: e.id, source: e.source, target: e.target, label,
        colour: EDGE_COLOURS[e.kind] || '#555' }, classes: e.kind + (e.target === KUKA ? ' to-system' : '') });
    }
    cy.startBatch();
    cy.elements().remove();
    cy.add(els);
    cy.endBatch();
    cy.layout({ name: 'preset', positions: (n) => pos[n.id()] || { x: 0, y: 0 }, fit: true, padding: 20 }).run();
    if (cy.zoom() < 0.7) {
      // readable labels first: zoom in on the routine in focus, else the first entry point
      const first = data.nodes.find((n) => n.entry_kind === 'cell') || data.nodes.find((n) => n.entry);
      const anchor = state.focus !== null ? cy.getElementById(state.focus)
        : first ? cy.getElementById(visibleOf(first.id)) : cy.nodes();
      cy.zoom(0.7);
      cy.center(anchor.length ? anchor : cy.nodes());
    }
    $('map-view').textContent = state.focus !== null
      ? `Neighbourhood of ${nodes.get(state.focus).name} (${nodes.get(state.focus).module}), depth ${state.depth}: ${cy.nodes().filter((n) => !n.isParent()).length} nodes`
      : `Overview: ${cy.nodes().filter((n) => !n.isParent()).length} nodes (click a module to open it)`;
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
  } else if (modules.has(id) || id === KUKA) {
    const m = modules.get(id);
    box.append(el('h2', m ? m.name : "KUKA's system software"));
    const open = state.expanded.has(id);
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
  if (state.expanded.has(id)) state.expanded.delete(id);
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
  for (const m of modules.keys()) state.expanded.add(m);
  state.expanded.add(KUKA);
  return overview();
});
$('map-collapse-all').addEventListener('click', () => { state.expanded.clear(); return overview(); });

window.krlMap = { cy, state, focus, overview, toggle, render, showSource };
render().then(onHash);
