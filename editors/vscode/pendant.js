// "KRL: Open pendant": `krl pendant --no-browser` on the workspace folder (or the open .src),
// shown in a webview panel beside the editor and the debugger (docs/pendant.md). The panel holds
// the page of the local server in an iframe; the server's first line is its URL with the token.
'use strict';

const vscode = require('vscode');
const { spawn } = require('child_process');

const URL_LINE = /^http:\/\/127\.0\.0\.1:(\d{1,5})\/\?token=[A-Za-z0-9_-]{20,100}$/;

/** The webview's HTML: the pendant page of `url` (already checked against URL_LINE). */
function panelHtml(url, port) {
  const csp = `default-src 'none'; frame-src http://127.0.0.1:${port}; style-src 'unsafe-inline'`;
  return `<!DOCTYPE html><html><head><meta charset="utf-8">
<meta http-equiv="Content-Security-Policy" content="${csp}">
<style>html,body,iframe{margin:0;padding:0;border:0;width:100%;height:100%;overflow:hidden}</style>
</head><body><iframe src="${url}" title="krl pendant" allow="clipboard-read; clipboard-write"></iframe></body></html>`;
}

/** What the pendant opens: the open KRL program, else the first workspace folder. */
function target() {
  const editor = vscode.window.activeTextEditor;
  if (editor && editor.document.languageId === 'krl' && /\.src$/i.test(editor.document.fileName)) {
    return editor.document.fileName;
  }
  const folder = vscode.workspace.workspaceFolders && vscode.workspace.workspaceFolders[0];
  return folder ? folder.uri.fsPath : undefined;
}

/** Start the server and open its page in a panel beside the active editor. */
async function openPendant(command) {
  const what = target();
  if (!what) {
    vscode.window.showInformationMessage('KRL: open a folder or a .src program first.');
    return undefined;
  }
  const proc = spawn(command, ['pendant', what, '--no-browser'], { stdio: ['ignore', 'pipe', 'pipe'] });
  const url = await new Promise((resolve) => {
    let buf = '';
    proc.stdout.on('data', (chunk) => {
      buf += chunk.toString();
      const nl = buf.indexOf('\n');
      if (nl >= 0) resolve(buf.slice(0, nl).trim());
    });
    proc.on('exit', () => resolve(undefined));
    proc.on('error', () => resolve(undefined));
  });
  const m = url && URL_LINE.exec(url);
  if (!m) {
    proc.kill();
    vscode.window.showErrorMessage(`KRL: \`${command} pendant\` did not start (set "krl.server.path" to the krl command).`);
    return undefined;
  }
  const panel = vscode.window.createWebviewPanel('krlPendant', 'KRL pendant', vscode.ViewColumn.Beside,
    { enableScripts: false, retainContextWhenHidden: true });
  panel.webview.html = panelHtml(url, m[1]);
  panel.onDidDispose(() => proc.kill());
  return panel;
}

module.exports = { openPendant, panelHtml, URL_LINE };
