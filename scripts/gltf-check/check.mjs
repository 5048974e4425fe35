// Checks a .glb with tools independent of qsgi, and prints one JSON object on stdout:
//   validator: the Khronos glTF-Validator's issue counts and messages;
//   translation, position, normal, color, irradiance: what glTF Transform's reader finds in the
//   first mesh primitive (flat float arrays) and the root node's translation.
// Usage: node scripts/gltf-check/check.mjs FILE.glb   (after scripts/setup.sh, which runs npm ci here)
import { readFile } from 'node:fs/promises';
import validator from 'gltf-validator';
import { Logger, NodeIO } from '@gltf-transform/core';

const file = process.argv[2];
if (!file) {
  console.error('usage: node check.mjs FILE.glb');
  process.exit(2);
}
const bytes = new Uint8Array(await readFile(file));
const report = await validator.validateBytes(bytes, { maxIssues: 100 });
const issues = report.issues;

// Custom attributes such as _IRRADIANCE are kept by the reader. The unlit extension is unknown to
// the bare reader, which would say so on stdout: the validator has judged the file already.
const io = new NodeIO().setLogger(new Logger(Logger.Verbosity.SILENT));
const document = await io.readBinary(bytes);
const root = document.getRoot();
const primitive = root.listMeshes()[0].listPrimitives()[0];
const array = (name) => {
  const a = primitive.getAttribute(name);
  return a ? Array.from(a.getArray()) : null;
};
const node = root.listScenes()[0].listChildren()[0];
console.log(JSON.stringify({
  validator: {
    errors: issues.numErrors,
    warnings: issues.numWarnings,
    infos: issues.numInfos,
    messages: issues.messages.map((m) => `${m.severity} ${m.code} ${m.pointer ?? ''}: ${m.message}`),
  },
  extensionsUsed: root.listExtensionsUsed().map((e) => e.extensionName),
  translation: node.getTranslation(),
  position: array('POSITION'),
  normal: array('NORMAL'),
  color: array('COLOR_0'),
  radiance: array('_RADIANCE'),
  irradiance: array('_IRRADIANCE'),
  extras: root.listMeshes()[0].getExtras(),
  indices: primitive.getIndices() ? primitive.getIndices().getCount() : 0,
}));
