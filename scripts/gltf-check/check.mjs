// Checks a .glb with tools independent of qsgi: the Khronos glTF-Validator and glTF Transform's
// reader. See `help` below for what it prints and its exit codes.
import { readFile } from 'node:fs/promises';
import { dirname, resolve } from 'node:path';
import { parseArgs } from 'node:util';
import validator from 'gltf-validator';
import { Accessor, Logger, NodeIO, Primitive } from '@gltf-transform/core';

// Enough lines to see what kind of trouble a file has, few enough to stay on a screen.
const summaryLines = 20;

const usageLine = 'usage: node scripts/gltf-check/check.mjs [--json | --frames] FILE.glb|FILE.gltf   (--help says more)';
const help = `usage: node scripts/gltf-check/check.mjs [--json | --frames] FILE.glb
  (after scripts/setup.sh --test, which runs npm ci in scripts/gltf-check)

Validates FILE.glb (or FILE.gltf, its files beside it) with the Khronos glTF-Validator and reads it with glTF Transform.

By default prints a short summary: the validator's error, warning, info and hint counts, its
first ${summaryLines} errors and warnings, the root node's translation, and each mesh primitive's
attributes with their accessor counts (the vertex count) and types.

  --json      print instead one JSON object (4 MB for a frame of data/cornell), for tests:
                validator: the validator's counts and its first 100 messages;
                extensionsUsed, extras (the first mesh's), indices (its first primitive's count);
                translation: the root node's; position, normal, color, radiance, irradiance:
                the first primitive's POSITION, NORMAL, COLOR_0, _RADIANCE and _IRRADIANCE as
                flat float arrays (null when absent).
  --frames    print instead one JSON object with the morphed per-vertex attributes at every key
              time, computed by the glTF 2.0 rules from what glTF Transform reads, for tests:
                {"animations": [{"index", "name", "times": [t...], "nodes": [{"node", "name",
                 "mesh", "primitives": [{"primitive", "targets", "attributes":
                 {SEMANTIC: [[flat floats at times[0]], [... at times[1]], ...]}}]}]}]}
              One entry per animation, in file order; its times are the sorted union of the key
              times of its "weights" channels (none: []). A file with no "weights" channel at all
              gets the one entry {"index": -1, "name": "", "times": [0]} with rest weights.
              Nodes: those with a mesh in the default scene (else the first), depth first;
              "node" and "mesh" are file indices. A node's weights at time t come from the
              animation's "weights" channel for it (STEP, LINEAR or CUBICSPLINE; the first
              key's value before it, the last's after it), else the node's weights, else the
              mesh's, else zeros. Attributes: each whose semantic starts with "_" or "COLOR_",
              as base + sum of weight x the target's same attribute (absent: 0), in doubles,
              normalized integers decoded. Not with --json.
  -h, --help  print this help.

Exit status: 0 when both tools read the file, whatever the validator reports (read its counts);
1 when the file cannot be read, glTF Transform cannot parse it, or it has no scene node or no
mesh primitive, or (--frames) its morph targets or "weights" animations are inconsistent (the
message says how); 2 on a wrong command line.`;

function parseCommandLine() {
  try {
    const { values, positionals } = parseArgs({
      options: { json: { type: 'boolean' }, frames: { type: 'boolean' }, help: { type: 'boolean', short: 'h' } },
      allowPositionals: true,
    });
    if (values.help) {
      console.log(help);
      process.exit(0);
    }
    if (values.json && values.frames) console.error('check.mjs: --json and --frames are exclusive');
    else if (positionals.length === 1) return { file: positionals[0], json: values.json === true, frames: values.frames === true };
    else console.error(positionals.length === 0 ? 'check.mjs: no FILE.glb given' : 'check.mjs: one FILE.glb at a time');
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

// --frames: the glTF 2.0 rules for morph targets and their "weights" animations, applied to what
// glTF Transform reads, with no knowledge of how qsgi writes them.

// An accessor's values as doubles; normalized integers decoded as glTF 2.0 says (so does
// Accessor.getElement). getArray() is dense: glTF Transform has applied sparse values, and an
// accessor with no bufferView reads as zeros.
function valuesOf(accessor) {
  const array = accessor.getArray();
  if (!accessor.getNormalized()) return Float64Array.from(array);
  const scale = { 5120: 127, 5121: 255, 5122: 32767, 5123: 65535 }[accessor.getComponentType()];
  if (!scale) return Float64Array.from(array);
  return Float64Array.from(array, (c) => Math.max(c / scale, -1));
}

// The weights (n of them) of a "weights" sampler at time t.
function sampleWeights(sampler, t, n) {
  const times = valuesOf(sampler.getInput());
  const output = valuesOf(sampler.getOutput());
  const cubic = sampler.getInterpolation() === 'CUBICSPLINE';
  // Per key, CUBICSPLINE stores n in-tangents, n values and n out-tangents.
  const stride = cubic ? 3 * n : n;
  const value = (k) => output.subarray(k * stride + (cubic ? n : 0), k * stride + (cubic ? n : 0) + n);
  let k = -1; // the last key at or before t
  while (k + 1 < times.length && times[k + 1] <= t) k++;
  if (k < 0) return Array.from(value(0));
  const s = k + 1 < times.length ? (t - times[k]) / (times[k + 1] - times[k]) : 0;
  if (s === 0 || sampler.getInterpolation() === 'STEP') return Array.from(value(k));
  const v0 = value(k);
  const v1 = value(k + 1);
  if (!cubic) return Array.from(v0, (v, i) => (1 - s) * v + s * v1[i]);
  const dt = times[k + 1] - times[k];
  const out0 = output.subarray(k * stride + 2 * n); // out-tangents of key k
  const in1 = output.subarray((k + 1) * stride); // in-tangents of key k + 1
  const s2 = s * s;
  const s3 = s2 * s;
  return Array.from(
    v0,
    (v, i) => (2 * s3 - 3 * s2 + 1) * v + (s3 - 2 * s2 + s) * dt * out0[i] + (-2 * s3 + 3 * s2) * v1[i] + (s3 - s2) * dt * in1[i],
  );
}

// A "weights" sampler's number of weights per key, checked against the mesh's targets.
function checkWeightsSampler(sampler, where, targets) {
  const keys = sampler.getInput()?.getCount() ?? 0;
  const values = sampler.getOutput()?.getArray()?.length ?? 0;
  const perKey = sampler.getInterpolation() === 'CUBICSPLINE' ? 3 * targets : targets;
  if (keys === 0 || values !== keys * perKey) {
    throw new Error(`${where}: ${keys} keys and ${values} output values, but the mesh has ${plural(targets, 'morph target')}` +
      (sampler.getInterpolation() === 'CUBICSPLINE' ? ' (CUBICSPLINE: 3 per target and key)' : ''));
  }
}

function printFrames(root) {
  const nodeIndex = new Map(root.listNodes().map((n, i) => [n, i]));
  const meshIndex = new Map(root.listMeshes().map((m, i) => [m, i]));
  const scene = root.getDefaultScene() ?? root.listScenes()[0];
  const meshNodes = [];
  const visit = (node) => {
    if (node.getMesh()) meshNodes.push(node);
    node.listChildren().forEach(visit);
  };
  scene?.listChildren().forEach(visit);

  const isWeights = (channel) => channel.getTargetPath() === 'weights';
  let animations = root.listAnimations().map((animation, index) => {
    const channels = animation.listChannels().filter(isWeights);
    const times = [...new Set(channels.flatMap((c) => Array.from(valuesOf(c.getSampler().getInput()))))].sort((a, b) => a - b);
    const byNode = new Map();
    for (const channel of channels) {
      const node = channel.getTargetNode();
      if (!node) continue;
      if (byNode.has(node)) throw new Error(`animation ${index}: two "weights" channels for node ${nodeIndex.get(node)}`);
      byNode.set(node, channel.getSampler());
    }
    return { index, name: animation.getName(), times, byNode, drivesWeights: channels.length > 0 };
  });
  if (!animations.some((a) => a.drivesWeights)) animations = [{ index: -1, name: '', times: [0], byNode: new Map() }];

  const entries = animations.map(({ index, name, times, byNode }) => ({
    index,
    name,
    times,
    nodes: meshNodes.map((node) => {
      const mesh = node.getMesh();
      const sampler = byNode.get(node);
      const rest = node.getWeights().length ? node.getWeights() : mesh.getWeights();
      return {
        node: nodeIndex.get(node),
        name: node.getName(),
        mesh: meshIndex.get(mesh),
        primitives: mesh.listPrimitives().map((primitive, p) => {
          const targets = primitive.listTargets();
          const where = `animation ${index}, node ${nodeIndex.get(node)}, mesh ${meshIndex.get(mesh)}, primitive ${p}`;
          if (sampler) checkWeightsSampler(sampler, where, targets.length);
          const weights = times.map((t) => {
            const w = sampler ? sampleWeights(sampler, t, targets.length) : rest;
            return targets.map((_, i) => w[i] ?? 0);
          });
          const attributes = {};
          for (const semantic of primitive.listSemantics().filter((s) => s.startsWith('_') || s.startsWith('COLOR_'))) {
            const base = valuesOf(primitive.getAttribute(semantic));
            const deltas = targets.map((target, i) => {
              const a = target.getAttribute(semantic);
              if (a && a.getArray().length !== base.length) {
                throw new Error(`${where}: morph target ${i} has ${a.getArray().length} ${semantic} values, the primitive ${base.length}`);
              }
              return a ? valuesOf(a) : null;
            });
            attributes[semantic] = weights.map((w) => {
              const v = Float64Array.from(base);
              deltas.forEach((d, i) => {
                if (!d || w[i] === 0) return;
                for (let j = 0; j < v.length; j++) v[j] += w[i] * d[j];
              });
              return v;
            });
          }
          return { primitive: p, targets: targets.length, attributes };
        }),
      };
    }),
  }));
  writeJson({ animations: entries });
}

// Writes value to stdout as JSON (a Float64Array as an array), piece by piece: the whole text can be
// longer than the longest string V8 makes (about 512 MB).
function writeJson(value) {
  let pending = '';
  const write = (text) => {
    pending += text;
    if (pending.length > 1 << 20) {
      process.stdout.write(pending);
      pending = '';
    }
  };
  const visit = (v) => {
    if (v instanceof Float64Array) write(JSON.stringify(Array.from(v)));
    else if (Array.isArray(v)) {
      write('[');
      v.forEach((item, i) => {
        if (i) write(',');
        visit(item);
      });
      write(']');
    } else if (v !== null && typeof v === 'object') {
      write('{');
      Object.entries(v).forEach(([key, item], i) => {
        write(`${i ? ',' : ''}${JSON.stringify(key)}:`);
        visit(item);
      });
      write('}');
    } else write(JSON.stringify(v));
  };
  visit(value);
  process.stdout.write(`${pending}\n`);
}

const { file, json, frames } = parseCommandLine();
try {
  const bytes = new Uint8Array(await readFile(file));
  // A .gltf's buffers and images are files beside it (the tests compare an asset with its input).
  const external = (uri) => readFile(resolve(dirname(file), decodeURIComponent(uri))).then((b) => new Uint8Array(b));
  const report = await validator.validateBytes(bytes, { maxIssues: 100, externalResourceFunction: external });
  // Before glTF Transform reads the file, so that a file it rejects still shows the validator's why.
  if (!json && !frames) printValidatorSummary(file, bytes, report);

  // Custom attributes such as _IRRADIANCE are kept by the reader. The unlit extension is unknown to
  // the bare reader, which would say so on stdout: the validator has judged the file already.
  const io = new NodeIO().setLogger(new Logger(Logger.Verbosity.SILENT));
  const jsonDoc = file.toLowerCase().endsWith('.gltf') ? await io.readAsJSON(file) : await io.binaryToJSON(bytes);
  // glTF Transform 4.5.1 reads sparse indices and values at the accessor's own byteOffset when they
  // give none: make the default (0) explicit, as readBinary would otherwise misread valid files.
  for (const accessor of jsonDoc.json.accessors ?? []) {
    for (const part of [accessor.sparse?.indices, accessor.sparse?.values]) if (part && part.byteOffset === undefined) part.byteOffset = 0;
  }
  const root = (await io.readJSON(jsonDoc)).getRoot();
  // The JSON describes the first primitive and the root node; all modes require them, so that the
  // exit status does not depend on --json or --frames.
  const primitive = root.listMeshes()[0]?.listPrimitives()[0];
  const node = root.listScenes()[0]?.listChildren()[0];
  if (!primitive) throw new Error('no mesh primitive');
  if (!node) throw new Error('no node in the first scene');
  if (frames) printFrames(root);
  else if (json) printJson(report, root, primitive, node);
  else printMeshSummary(root, node);
} catch (e) {
  console.error(`check.mjs: ${file}: ${e.message}`);
  process.exitCode = 1;
}
