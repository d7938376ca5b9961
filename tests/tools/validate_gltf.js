// Validate a glTF/GLB file with the Khronos validator; prints {"errors": n, "warnings": n, "messages": [...]}.
// Usage: node validate_gltf.js FILE (the npm package gltf-validator must be installed: see .ci/run).
const fs = require("fs");
const validator = require("gltf-validator");
const data = new Uint8Array(fs.readFileSync(process.argv[2]));
validator
  .validateBytes(data)
  .then((r) => {
    const i = r.issues;
    const messages = i.messages.filter((m) => m.severity <= 1).map((m) => `${m.code} ${m.pointer || ""} ${m.message}`);
    console.log(JSON.stringify({ errors: i.numErrors, warnings: i.numWarnings, messages }));
  })
  .catch((e) => console.log(JSON.stringify({ errors: 1, warnings: 0, messages: [String(e)] })));
