// Runs the Khronos glTF validator on each file named on the command line and prints one JSON
// object: for each file, its error, warning, info and hint counts and every message above info.
import { readFile } from "node:fs/promises";
import validator from "gltf-validator";

const out = {};
for (const file of process.argv.slice(2)) {
  const bytes = new Uint8Array(await readFile(file));
  const report = await validator.validateBytes(bytes, {
    maxIssues: 0,
    externalResourceFunction: (uri) =>
      readFile(new URL(uri, "file://" + file)).then((b) => new Uint8Array(b)),
  });
  const issues = report.issues;
  out[file] = {
    errors: issues.numErrors,
    warnings: issues.numWarnings,
    infos: issues.numInfos,
    hints: issues.numHints,
    messages: issues.messages.filter((m) => m.severity <= 1),
    infoCodes: [...new Set(issues.messages.filter((m) => m.severity > 1).map((m) => m.code))],
    animations: report.info ? report.info.animationCount : null,
  };
}
console.log(JSON.stringify(out, null, 1));
