// Checks a .glb with tools independent of qsgi: the Khronos glTF-Validator and glTF Transform's
// reader. See `help` below for what it prints and its exit codes.
import { readFile } from 'node:fs/promises';
import { parseArgs } from 'node:util';
import validator from 'gltf-validator';
import { Accessor, Logger, NodeIO, Primitive } from '@gltf-transform/core';

// Enough lines to see what kind of trouble a file has, few enough to stay on a screen.
const summaryLines = 20;

const usageLine = 'usage: node scripts/gltf-check/check.mjs [--json] FILE.glb   (--help says more)';
const help = `usage: node scripts/gltf-check/check.mjs [--json] FILE.glb
  (after scripts/setup.sh --test, which runs npm ci in scripts/gltf-check)

Validates FILE.glb with the Khronos glTF-Validator and reads it with glTF Transform.

By default prints a short summary: the validator's error, warning, info and hint counts, its
first ${summaryLines} errors and warnings, the root node's translation, and each mesh primitive's
attributes with their accessor counts (the vertex count) and types.

  --json      print instead one JSON object (4 MB for a frame of data/cornell), for tests:
                validator: the validator's counts and its first 100 messages;
                extensionsUsed, extras (the first mesh's), indices (its first primitive's count);
                translation: the root node's; position, normal, color, radiance, irradiance:
                the first primitive's POSITION, NORMAL, COLOR_0, _RADIANCE and _IRRADIANCE as
                flat float arrays (null when absent).
  -h, --help  print this help.

Exit status: 0 when both tools read the file, whatever the validator reports (read its counts);
1 when the file cannot be read, glTF Transform cannot parse it, or it has no scene node or no
mesh primitive; 2 on a wrong command line.`;

function parseCommandLine() {
  try {
    const { values, positionals } = parseArgs({
      options: { json: { type: 'boolean' }, help: { type: 'boolean', short: 'h' } },
      allowPositionals: true,
    });
    if (values.help) {
      console.log(help);
      process.exit(0);
    }
    if (positionals.length === 1) return { file: positionals[0], json: values.json === true };
    console.error(positionals.length === 0 ? 'check.mjs: no FILE.glb given' : 'check.mjs: one FILE.glb at a time');
  } catch (e) {
    console.error(`check.mjs: ${e.message}`);
  }
  console.error(usageLine);
  process.exit(2);
}

const plural = (n, word) => `${n} ${word}${n === 1 ? '' : 's'}`;
// glTF stores enums as numbers; glTF Transform names them in these tables.
const nameOf = (table, value) => Object.keys(table).find((k) => table[k] === value) ?? String(value);
const severities = ['error', 'warning', 'info', 'hint'];

function printValidatorSummary(file, bytes, report) {
  const issues = report.issues;
  // From the validator: glTF Transform's bare reader lists only the extensions it implements.
  const generator = report.info?.generator;
  const extensions = report.info?.extensionsUsed ?? [];
  console.log(
    `${file}: ${bytes.length} bytes` +
      (generator ? `, generator "${generator}"` : '') +
      (extensions.length ? `, extensions used: ${extensions.join(', ')}` : ''),
  );
  console.log(
    `glTF-Validator ${report.validatorVersion}: ${plural(issues.numErrors, 'error')}, ` +
      `${plural(issues.numWarnings, 'warning')}, ${plural(issues.numInfos, 'info')}, ${plural(issues.numHints, 'hint')}` +
      (issues.truncated ? ' (it stopped at 100 issues: there may be more)' : ''),
  );
  const serious = issues.messages.filter((m) => m.severity <= 1);
  for (const m of serious.slice(0, summaryLines)) {
    // GLB-level issues have a byte offset instead of a JSON pointer.
    const where = m.pointer ?? (m.offset !== undefined ? `byte ${m.offset}` : '');
    console.log(`  ${severities[m.severity]} ${m.code} ${where}: ${m.message}`);
  }
  const more = issues.numErrors + issues.numWarnings - Math.min(serious.length, summaryLines);
  if (more > 0) console.log(`  ... and ${more} more (--json lists the first 100 messages of any severity)`);
}

function printMeshSummary(root, node) {
  // qsgi stores positions relative to this translation, so it belongs with the attribute counts.
  console.log(`root node translation: ${node.getTranslation().join(' ')}`);
  const primitives = root.listMeshes().flatMap((mesh, m) =>
    mesh.listPrimitives().map((primitive, p) => ({ label: `mesh ${m}${mesh.getName() ? ` "${mesh.getName()}"` : ''}, primitive ${p}`, primitive })),
  );
  for (const { label, primitive } of primitives.slice(0, summaryLines)) {
    const indices = primitive.getIndices();
    const indexText = indices ? `${indices.getCount()} indices (${nameOf(Accessor.ComponentType, indices.getComponentType())})` : 'no indices';
    console.log(`${label}: ${nameOf(Primitive.Mode, primitive.getMode())}, ${indexText}`);
    const names = primitive.listSemantics();
    const width = Math.max(...names.map((s) => s.length));
    for (const semantic of names) {
      const a = primitive.getAttribute(semantic);
      const type = `${a.getType()} ${nameOf(Accessor.ComponentType, a.getComponentType())}${a.getNormalized() ? ' normalized' : ''}`;
      console.log(`  ${semantic.padEnd(width)}  count ${a.getCount()}  ${type}`);
    }
  }
  if (primitives.length > summaryLines) console.log(`... and ${primitives.length - summaryLines} more primitives`);
}

function printJson(report, root, primitive, node) {
  const issues = report.issues;
  const array = (name) => {
    const a = primitive.getAttribute(name);
    return a ? Array.from(a.getArray()) : null;
  };
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
}

const { file, json } = parseCommandLine();
try {
  const bytes = new Uint8Array(await readFile(file));
  const report = await validator.validateBytes(bytes, { maxIssues: 100 });
  // Before glTF Transform reads the file, so that a file it rejects still shows the validator's why.
  if (!json) printValidatorSummary(file, bytes, report);

  // Custom attributes such as _IRRADIANCE are kept by the reader. The unlit extension is unknown to
  // the bare reader, which would say so on stdout: the validator has judged the file already.
  const io = new NodeIO().setLogger(new Logger(Logger.Verbosity.SILENT));
  const root = (await io.readBinary(bytes)).getRoot();
  // The JSON describes the first primitive and the root node; both modes require them, so that the
  // exit status does not depend on --json.
  const primitive = root.listMeshes()[0]?.listPrimitives()[0];
  const node = root.listScenes()[0]?.listChildren()[0];
  if (!primitive) throw new Error('no mesh primitive');
  if (!node) throw new Error('no node in the first scene');
  if (json) printJson(report, root, primitive, node);
  else printMeshSummary(root, node);
} catch (e) {
  console.error(`check.mjs: ${file}: ${e.message}`);
  process.exitCode = 1;
}
