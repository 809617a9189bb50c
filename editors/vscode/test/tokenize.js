// Tokenizes KRL lines with VS Code's own TextMate engine (vscode-textmate + vscode-oniguruma, the
// engine vscode-tmgrammar-test uses) and the extension's grammar (or the grammar file given as the
// first argument); prints one JSON array per run: for each input line, its tokens as
// {text, scopes}. Input: a JSON array of lines on stdin.
// Used by tests/editors/test_vscode_grammar.py (every lexer keyword gets a keyword scope).
'use strict';

const fs = require('fs');
const path = require('path');
const textmate = require('vscode-textmate');
const oniguruma = require('vscode-oniguruma');

async function main() {
  const wasm = fs.readFileSync(require.resolve('vscode-oniguruma/release/onig.wasm'));
  await oniguruma.loadWASM(wasm.buffer.slice(wasm.byteOffset, wasm.byteOffset + wasm.byteLength));
  const registry = new textmate.Registry({
    onigLib: Promise.resolve({
      createOnigScanner: (sources) => new oniguruma.OnigScanner(sources),
      createOnigString: (text) => new oniguruma.OnigString(text),
    }),
    loadGrammar: async (scopeName) => {
      if (scopeName !== 'source.krl') return null;
      const file = process.argv[2] || path.join(__dirname, '..', 'syntaxes', 'krl.tmLanguage.json');
      return textmate.parseRawGrammar(fs.readFileSync(file, 'utf8'), file);
    },
  });
  const grammar = await registry.loadGrammar('source.krl');
  const lines = JSON.parse(fs.readFileSync(0, 'utf8'));
  let state = textmate.INITIAL;
  const out = lines.map((line) => {
    const result = grammar.tokenizeLine(line, state);
    state = result.ruleStack;
    return result.tokens.map((t) => ({ text: line.slice(t.startIndex, t.endIndex), scopes: t.scopes }));
  });
  process.stdout.write(JSON.stringify(out));
}

main().catch((err) => {
  process.stderr.write(String(err && err.stack ? err.stack : err) + '\n');
  process.exit(1);
});
