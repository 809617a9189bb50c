// A DAP client krl-tools did not write (@vscode/debugadapter-testsupport's DebugClient, the
// test support of VS Code's debug adapters) drives `krl debug` on a cell of two robots
// (tests/debug/test_dap_cell_thirdparty.py writes the cell and reads this script's verdict).
// Usage: node cell.js KRL_COMMAND FOLDER INTERP. Exit 0 and "ok" when every check holds.
'use strict';
const assert = require('assert');
const path = require('path');
const { DebugClient } = require('@vscode/debugadapter-testsupport');

async function main() {
  const [krl, dir, interp] = process.argv.slice(2);
  const cell = path.join(dir, 'cell.yaml');
  const pal = path.join(dir, 'pal.src');
  const handler = path.join(dir, 'handler.src');
  const dc = new DebugClient(krl, 'debug', 'krl', { cwd: dir, env: process.env });
  dc.defaultTimeout = 90000;
  await dc.start();
  try {
    // R2's breakpoint: the stop names R2's thread, whose stack DebugClient reads by that id
    await dc.hitBreakpoint({ program: cell, interp }, { path: pal, line: 3 });
    const threads = (await dc.threadsRequest()).body.threads.map(t => [t.id, t.name]);
    assert.deepStrictEqual(threads, [[1, 'R1: robot program handler'], [10001, 'R2: robot program pal']]);
    const r1 = (await dc.stackTraceRequest({ threadId: 1 })).body.stackFrames;
    assert.deepStrictEqual(r1.map(f => [f.source.path, f.line]), [[handler, 5]]);
    const ev = async (expr, frame) => (await dc.evaluateRequest({ expression: expr, frameId: frame, context: 'watch' })).body.result;
    const r2 = (await dc.stackTraceRequest({ threadId: 10001 })).body.stackFrames;
    assert.strictEqual(await ev('$OUT[10]', r1[0].id), 'TRUE');
    assert.strictEqual(await ev('$IN[10]', r2[0].id), 'TRUE');
    assert.strictEqual(await ev('$OUT[11]', r2[0].id), 'FALSE');
    // a step in R2's thread
    await Promise.all([dc.nextRequest({ threadId: 10001 }), dc.assertStoppedLocation('step', { path: pal, line: 4 })]);
    const exited = dc.waitForEvent('exited');
    await Promise.all([dc.continueRequest({ threadId: 10001 }), dc.waitForEvent('terminated')]);
    assert.strictEqual((await exited).body.exitCode, 0);
  } finally {
    await dc.stop();
  }
  console.log('ok');
}

main().catch(err => { console.error(err && err.stack ? err.stack : String(err)); process.exit(1); });
