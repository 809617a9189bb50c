// The extension's client side, in node without VS Code: starts the language server the way
// extension.js does (the command and arguments of the settings `krl.server.path` and
// `krl.server.args`, stdio transport), initializes it on a workspace folder, opens KRL files
// and waits for their checked publishDiagnostics; then shuts the server down and prints one JSON object:
// {capabilities, diagnostics: {<file path>: [Diagnostic...]}}.
//
// usage: node diagnostics.js COMMAND ARGS_JSON WORKSPACE_DIR FILE... (ARGS_JSON "" = the default)
'use strict';

const { spawn } = require('child_process');
const fs = require('fs');
const path = require('path');
const { pathToFileURL } = require('url');
const rpc = require('vscode-languageserver-protocol/node');

const TIMEOUT_MS = 120000;

/** The defaults of the extension's settings, from its package.json. */
function defaults() {
  const pkg = JSON.parse(fs.readFileSync(path.join(__dirname, '..', '..', 'package.json'), 'utf8'));
  const props = pkg.contributes.configuration.properties;
  return { command: props['krl.server.path'].default, args: props['krl.server.args'].default };
}

async function main() {
  const [command, argsJson, workspace, ...files] = process.argv.slice(2);
  const args = argsJson ? JSON.parse(argsJson) : defaults().args;
  const server = spawn(command || defaults().command, args, { stdio: ['pipe', 'pipe', 'pipe'] });
  let stderr = '';
  server.stderr.on('data', (d) => { stderr += d; });
  const exited = new Promise((resolve) => server.on('exit', (code) => resolve(code)));
  server.on('error', (err) => { process.stderr.write(`cannot start the server: ${err.message}\n`); process.exit(2); });

  const connection = rpc.createProtocolConnection(
    new rpc.StreamMessageReader(server.stdout), new rpc.StreamMessageWriter(server.stdin));
  const uris = new Map(files.map((f) => [pathToFileURL(path.resolve(f)).toString(), path.resolve(f)]));
  const received = new Map();
  let done;
  const allReceived = new Promise((resolve) => { done = resolve; });
  connection.onNotification(rpc.PublishDiagnosticsNotification.type, (params) => {
    if (uris.has(params.uri)) {
      received.set(params.uri, params.diagnostics);     // the latest: the checked ones replace a
      if (received.size === uris.size) done();          // file's own parse diagnostics
    }
  });
  connection.onRequest(rpc.RegistrationRequest.type, () => null);
  connection.onRequest(rpc.ConfigurationRequest.type, (params) => params.items.map(() => null));
  connection.onRequest(rpc.WorkDoneProgressCreateRequest.type, () => null);
  connection.listen();

  const rootUri = pathToFileURL(path.resolve(workspace)).toString();
  const init = await connection.sendRequest(rpc.InitializeRequest.type, {
    processId: process.pid,
    rootUri,
    workspaceFolders: [{ uri: rootUri, name: path.basename(workspace) }],
    capabilities: {
      textDocument: { publishDiagnostics: { relatedInformation: true }, synchronization: { didSave: true } },
      workspace: { workspaceFolders: true, configuration: true },
    },
  });
  await connection.sendNotification(rpc.InitializedNotification.type, {});
  for (const [uri, file] of uris) {
    await connection.sendNotification(rpc.DidOpenTextDocumentNotification.type, {
      textDocument: { uri, languageId: 'krl', version: 1, text: fs.readFileSync(file, 'latin1') },
    });
  }
  const timer = setTimeout(() => {
    process.stderr.write(`no diagnostics within ${TIMEOUT_MS} ms; server stderr:\n${stderr}\n`);
    process.exit(3);
  }, TIMEOUT_MS);
  await allReceived;
  // In a workspace of 20 files or more the server first publishes each file's own parse
  // diagnostics; a documentSymbol request is answered once the analysis is done, after the
  // checked diagnostics it published.
  for (const uri of uris.keys()) {
    await connection.sendRequest(rpc.DocumentSymbolRequest.type, { textDocument: { uri } });
  }
  clearTimeout(timer);
  await connection.sendRequest(rpc.ShutdownRequest.type);
  await connection.sendNotification(rpc.ExitNotification.type);
  const code = await exited;
  const diagnostics = {};
  for (const [uri, file] of uris) diagnostics[file] = received.get(uri);
  process.stdout.write(JSON.stringify({ capabilities: init.capabilities, exitCode: code, diagnostics }));
}

main().catch((err) => {
  process.stderr.write(String(err && err.stack ? err.stack : err) + '\n');
  process.exit(1);
});
