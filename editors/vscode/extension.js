// The KRL extension's client: starts the project's language server (`krl lsp`, stdio) for the
// `krl` language, and the project's debug adapter (`krl debug`, stdio) for launch configurations
// of type "krl", and the pendant (`krl pendant`, a local web page) in a webview panel (pendant.js).
// All of them come from the setting `krl.server.path` (default: `krl` on PATH).
'use strict';

const vscode = require('vscode');
const { LanguageClient, TransportKind } = require('vscode-languageclient/node');
const { openPendant } = require('./pendant');

/** @type {LanguageClient | undefined} */
let client;

/** The command and arguments of the language server, from the settings. */
function serverCommand() {
  const config = vscode.workspace.getConfiguration('krl');
  const command = config.get('server.path') || 'krl';
  const args = config.get('server.args') || ['lsp'];
  return { command, args };
}

async function startClient(context) {
  const { command, args } = serverCommand();
  const executable = { command, args, transport: TransportKind.stdio };
  client = new LanguageClient(
    'krl',
    'KRL Language Server',
    { run: executable, debug: executable },
    {
      documentSelector: [{ language: 'krl' }],
      synchronize: {
        fileEvents: vscode.workspace.createFileSystemWatcher('**/*.{src,dat,sub,SRC,DAT,SUB}'),
      },
    },
  );
  try {
    await client.start();
  } catch (err) {
    const message = err instanceof Error ? err.message : String(err);
    vscode.window.showErrorMessage(
      `KRL: the language server \`${command} ${args.join(' ')}\` did not start (${message}). ` +
        'Set "krl.server.path" to the krl command (after `make`: the repository\'s .venv/bin/krl).',
    );
  }
}

/** Starts `krl debug` (a Debug Adapter Protocol server on stdio) for each KRL debug session. */
class DebugAdapterFactory {
  createDebugAdapterDescriptor() {
    const { command } = serverCommand();
    return new vscode.DebugAdapterExecutable(command, ['debug']);
  }
}

/** Fills a launch configuration when there is no launch.json: the open KRL file. */
class DebugConfigurationProvider {
  resolveDebugConfiguration(folder, config) {
    if (!config.type && !config.request && !config.name) {
      const editor = vscode.window.activeTextEditor;
      if (editor && editor.document.languageId === 'krl') {
        config.type = 'krl';
        config.name = 'KRL: run the current file';
        config.request = 'launch';
        config.program = '${file}';
        config.stopOnEntry = true;
      }
    }
    if (!config.program) {
      return vscode.window.showInformationMessage('KRL: no program to run (open a .src file).').then(() => undefined);
    }
    if (!config.workspace && folder) {
      config.workspace = folder.uri.fsPath;
    }
    return config;
  }
}

async function activate(context) {
  context.subscriptions.push(
    vscode.debug.registerDebugAdapterDescriptorFactory('krl', new DebugAdapterFactory()),
    vscode.debug.registerDebugConfigurationProvider('krl', new DebugConfigurationProvider()),
    vscode.commands.registerCommand('krl.restartServer', async () => {
      if (client) {
        await client.stop();
      }
      await startClient(context);
    }),
    vscode.commands.registerCommand('krl.openPendant', () => openPendant(serverCommand().command)),
    vscode.workspace.onDidChangeConfiguration(async (event) => {
      if (event.affectsConfiguration('krl.server')) {
        await vscode.commands.executeCommand('krl.restartServer');
      }
    }),
  );
  await startClient(context);
}

async function deactivate() {
  if (client) {
    await client.stop();
  }
}

module.exports = { activate, deactivate, serverCommand };
