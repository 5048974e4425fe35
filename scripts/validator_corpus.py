#!/usr/bin/env python3
"""Runs the Khronos glTF-Validator's own test corpus through `qsgi inspect` and reports how qsgi treats
each file, measured against the validator's verdict (the `<file>.report.json` beside each file).

Most corpus files have no scene, no light or nothing to render, so qsgi would refuse them for that
reason alone and say nothing about their real error. Each file is therefore run as two variants:

  scene  the file given a minimal scene of its own (a triangle, a node and a scene appended, nothing
         else touched; the validator then reports exactly the original errors). The triangle's
         material is emissive because qsgi refuses a scene without light. The original objects are
         not in the rendered scene, so qsgi should refuse the file when the error is in something it
         reads anyway, and at least warn about it otherwise; with --strict it should refuse (exit 2).
  all    the same, but with every original mesh and camera in the rendered scene (a new node for
         each, appended) and every original root node, so the render uses every object the errors
         can be in that a scene can reach: qsgi should refuse every invalid file (exit 2). An
         object no scene can reach (an accessor no mesh reads, a texture no material names) is
         still unread; a warning naming it as "not in the rendered scene" is then its class
         (warned-unreachable), not "accepted".

Valid files (numErrors 0) must load in both variants, with and without --strict. Their originals
are not run: almost none has a scene and a light, which qsgi needs before anything else. A
--strict run is left out where the plain run refused (it would refuse too) and counted as such.

A variant that cannot be made (the GLB container or its JSON cannot be parsed, a top-level array is
not an array, or appending would change something the validator flagged) is replaced by the
original file, run as is, and the reason is recorded.

How a run is classed, for an invalid file. qsgi "names the object" when an error pointer of the
report, turned into qsgi's form ("/accessors/0/byteOffset" -> "accessors[0]"), occurs in its error
(or warning) text; a pointer to the whole file (none, "" or "/": GLB container errors, JSON syntax
errors, a missing "asset") counts as named by any refusal, since there is no object to name.

  scene           refused-own, refused-other (refused, naming something else), warned (loaded with a
                  warning naming the object), silent (loaded without one), crash
  scene --strict  refused, accepted, crash
  all             refused-own, refused-other, warned-unreachable, accepted, crash
  valid files     loaded, refused, crash (for "scene", "scene --strict" and "all")

A crash is any exit code other than 0 and 2: 1, a signal, or no answer within 60 s.

The runs go in batches, one `qsgi inspect --scenes LIST --json` for many files (a process start
costs more than most of these files take to read): each line of its output carries the exit code
and error line the file alone would give. A batch that crashes or stops answering has its
unanswered files run alone, so a crash is charged to its file. One file in SAMPLE_EVERY is also run
alone and its answers compared with the batch's; a difference fails the script.

--expect FILE names the known gaps, {"invalid-silent-in-scene": [...], "invalid-accepted-in-all":
[...], "valid-refused": [...], "valid-refused-under-strict": [...], "crash": [...]} with
"category/file" entries; the script exits 1 when a file is worse than listed
and when a listed file is now handled, so the list only shrinks. --write-expect FILE writes the
current gaps in that form. Without --expect it exits 1 only on a crash.

Usage: scripts/validator_corpus.py --qsgi build/cli/qsgi [--corpus DIR] [--jobs N] [--json OUT]
                                   [--expect FILE] [--write-expect FILE]
"""
import argparse
import base64
import collections
import concurrent.futures
import json
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import time
from pathlib import Path

DEFAULT_CORPUS = Path(__file__).resolve().parents[1].parent / "shared/data/gltf-validator-corpus"
TIMEOUT_SECONDS = 60
SAMPLE_EVERY = 16  # of the files, one in this many is also run alone and compared with its batch answer
SKIPPED = 77  # the exit code ctest's SKIP_RETURN_CODE reports as a skipped test
EXIT_LOADED, EXIT_REFUSED = 0, 2

GLB_MAGIC = b"glTF"
GLB_HEADER = struct.Struct("<4sII")
GLB_CHUNK_HEADER = struct.Struct("<II")
GLB_JSON_CHUNK = 0x4E4F534A
UTF8_BOM = b"\xef\xbb\xbf"

# The appended triangle: (0,0,0), (1,0,0), (0,0,1), its normal along -y.
TRIANGLE = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 0.0, 1.0)]
APPENDED_NAME = "appended by validator_corpus.py"
# The top-level arrays the variants append to.
APPENDED_ARRAYS = ["buffers", "bufferViews", "accessors", "materials", "meshes", "nodes", "scenes"]


class NoVariant(Exception):
    """A variant cannot be made without changing the original; the message says why."""


# ---------------------------------------------------------------------------------------------
# The corpus and the validator's reports


def corpus_files(data_dir):
    """(category, file path, report) of every corpus file that has a report, sorted."""
    for report_path in sorted(data_dir.glob("*/*.report.json")):
        model = report_path.with_name(report_path.name[: -len(".report.json")])
        if model.suffix in (".gltf", ".glb") and model.is_file():
            with open(report_path, encoding="utf-8") as f:
                yield model.parent.name, model, json.load(f)


def report_errors(report):
    """The report's errors (severity 0) as (code, pointer); pointer None when it gives only a byte offset."""
    return [(m["code"], m.get("pointer")) for m in report["issues"]["messages"] if m.get("severity") == 0]


def is_whole_file(pointer):
    """Whether an error is about the file as a whole: no pointer (a GLB byte offset), "" or "/" (the root)."""
    return pointer in (None, "", "/")


def pointer_segments(pointer):
    """JSON pointer "/a/0/b~1c" -> ["a", "0", "b/c"]."""
    return [s.replace("~1", "/").replace("~0", "~") for s in pointer.split("/")[1:]]


def object_names(pointer):
    """The names by which qsgi would refer to the object a pointer is in, shortest first.

    "/accessors/0/byteOffset" -> ["accessors[0]"]; "/meshes/0/primitives/1/attributes/POSITION" ->
    ["meshes[0]", "meshes[0].primitives[1]"]: every prefix that ends at an array index.
    "/extensions/KHR_lights_punctual/lights/0" -> ["extensions.KHR_lights_punctual.lights[0]"].
    Without an index the object is the top-level property ("/asset/version" -> ["asset"]), or the
    extension ("/extensions/EXT_x" -> ["extensions.EXT_x"]). [] for a pointer to the whole file.
    """
    if is_whole_file(pointer):
        return []
    segments = pointer_segments(pointer)
    names, place = [], ""
    for segment in segments:
        if segment.isdigit() and place:
            place += "[%s]" % segment
            names.append(place)
        else:
            place += ("." if place else "") + segment
    if names:
        return names
    if segments[0] == "extensions" and len(segments) > 1:
        return ["extensions." + segments[1]]
    return [segments[0]]


# ---------------------------------------------------------------------------------------------
# Making the variants


def appended_scene(doc, error_pointers, with_every_mesh_and_camera):
    """doc with a lit triangle, its node and a scene appended, and that scene made the default.

    Appends only: the original objects keep their indices and contents, so the validator's
    pointers still point at the same things. Raises NoVariant if a top-level array is not one, or
    if the edit would change something the validator flags.
    """
    read_only = ["cameras"] if with_every_mesh_and_camera else []
    for name in APPENDED_ARRAYS + read_only:
        if name in doc and not isinstance(doc[name], list):
            raise NoVariant("top-level %r is not an array" % name)
    check_edit_keeps_errors(doc, APPENDED_ARRAYS, error_pointers)
    doc = dict(doc)
    for name in APPENDED_ARRAYS:
        doc[name] = list(doc.get(name, []))

    def append(name, value):
        doc[name].append(value)
        return len(doc[name]) - 1

    positions = b"".join(struct.pack("<3f", *p) for p in TRIANGLE)
    buffer = append("buffers", {
        "uri": "data:application/octet-stream;base64," + base64.b64encode(positions).decode("ascii"),
        "byteLength": len(positions), "name": APPENDED_NAME})
    view = append("bufferViews", {"buffer": buffer, "byteLength": len(positions), "target": 34962})
    accessor = append("accessors", {
        "bufferView": view, "componentType": 5126, "count": len(TRIANGLE), "type": "VEC3",
        "min": [min(p[i] for p in TRIANGLE) for i in range(3)],
        "max": [max(p[i] for p in TRIANGLE) for i in range(3)]})
    # Emissive, because qsgi refuses a scene without light.
    material = append("materials", {"emissiveFactor": [1.0, 1.0, 1.0], "name": APPENDED_NAME})
    mesh_count = len(doc["meshes"])
    mesh = append("meshes", {"primitives": [{"attributes": {"POSITION": accessor}, "material": material}],
                             "name": APPENDED_NAME})
    scene_nodes = [append("nodes", {"mesh": mesh, "name": APPENDED_NAME})]
    if with_every_mesh_and_camera:
        # The original hierarchy's roots too, so that their skins, weights and children are read.
        original_nodes = len(doc["nodes"]) - 1
        children = {c for n in doc["nodes"][:original_nodes] if isinstance(n, dict)
                    for c in (n.get("children") if isinstance(n.get("children"), list) else []) if isinstance(c, int)}
        scene_nodes += [n for n in range(original_nodes) if n not in children]
        scene_nodes += [append("nodes", {"mesh": i}) for i in range(mesh_count)]
        scene_nodes += [append("nodes", {"camera": j}) for j in range(len(doc.get("cameras", [])))]
    doc["scene"] = append("scenes", {"nodes": scene_nodes, "name": APPENDED_NAME})
    return doc


# The array a reference points into, by the key that holds it.
REFERENCE_TARGETS = {"nodes": "nodes", "children": "nodes", "joints": "nodes", "skeleton": "nodes", "node": "nodes",
                     "mesh": "meshes", "material": "materials", "buffer": "buffers", "bufferView": "bufferViews",
                     "indices": "accessors", "inverseBindMatrices": "accessors", "input": "accessors",
                     "output": "accessors", "scene": "scenes"}


def check_edit_keeps_errors(doc, arrays, error_pointers):
    """Raises NoVariant when the edit would touch a value the validator flagged.

    Appending to an array the validator calls empty ("/scenes") would remove that error, and
    replacing a flagged default scene ("/scene") would too; so would appending the very object a
    dangling reference names (a node's mesh 0 in a file without meshes: the appended mesh is mesh
    0). Such a file is run as it is.
    """
    touched = ["/scene"] + ["/" + name for name in arrays if name in doc]
    for pointer in error_pointers:
        if pointer in touched:
            raise NoVariant("the edit would change %s, which the validator flags" % pointer)
        segments = pointer_segments(pointer) if pointer else []
        keys = [k for k in segments if not k.isdigit()]
        target = REFERENCE_TARGETS.get(keys[-1]) if keys else None
        if keys and keys[-1] not in REFERENCE_TARGETS and len(segments) >= 2 and segments[-2] == "attributes":
            target = "accessors"
        value = value_at(doc, segments)
        if target in arrays and isinstance(value, int) and not isinstance(value, bool):
            existing = len(doc.get(target, [])) if isinstance(doc.get(target), list) else 0
            # Each array gains one object; nodes gain one per mesh and camera too (the "all" variant).
            gained = 1 + (len(doc.get("meshes") or []) + len(doc.get("cameras") or []) if target == "nodes" else 0)
            if existing <= value < existing + gained:
                raise NoVariant("an appended object would resolve %s, which the validator flags" % pointer)


def value_at(doc, segments):
    """The JSON value at a pointer's segments, or None."""
    at = doc
    for key in segments:
        if isinstance(at, list) and key.isdigit() and int(key) < len(at):
            at = at[int(key)]
        elif isinstance(at, dict) and key in at:
            at = at[key]
        else:
            return None
    return at


def parse_json_text(data):
    """(bom, document) of JSON bytes; a UTF-8 BOM (itself an error in the corpus) is kept aside."""
    bom = UTF8_BOM if data.startswith(UTF8_BOM) else b""

    def refuse_duplicate_keys(pairs):
        # json.loads keeps the last of duplicate keys; rewriting would silently drop the others.
        keys = [k for k, _ in pairs]
        if len(keys) != len(set(keys)):
            raise NoVariant("duplicate keys in a JSON object")
        return dict(pairs)

    try:
        doc = json.loads(data[len(bom):].decode("utf-8"), object_pairs_hook=refuse_duplicate_keys)
    except (UnicodeDecodeError, json.JSONDecodeError) as e:
        raise NoVariant("unparseable: JSON: %s" % e)
    if not isinstance(doc, dict):
        raise NoVariant("unparseable: the JSON is not an object")
    return bom, doc


def json_bytes(bom, doc):
    """The document written back as compact JSON. Values are kept, not their spelling: a number
    written 1e0 comes back as 1.0, a string's escapes may change."""
    try:
        # allow_nan=False: an infinity read from the original would not be written back as JSON.
        return bom + json.dumps(doc, allow_nan=False).encode("utf-8")
    except ValueError as e:
        raise NoVariant("cannot write the JSON back: %s" % e)


def parse_glb(data):
    """(header length field, chunks as [type, bytes], trailing bytes) of a GLB container."""
    if len(data) < GLB_HEADER.size:
        raise NoVariant("unparseable: GLB shorter than its header")
    magic, _version, declared_length = GLB_HEADER.unpack_from(data)
    if magic != GLB_MAGIC:
        raise NoVariant("unparseable: GLB magic is not 'glTF'")
    chunks, offset = [], GLB_HEADER.size
    while len(data) - offset >= GLB_CHUNK_HEADER.size:
        length, chunk_type = GLB_CHUNK_HEADER.unpack_from(data, offset)
        start = offset + GLB_CHUNK_HEADER.size
        if start + length > len(data):
            raise NoVariant("unparseable: GLB chunk at byte %d runs past the end" % offset)
        chunks.append([chunk_type, data[start:start + length]])
        offset = start + length
    return declared_length, chunks, data[offset:]


def glb_variant(data, edit):
    """The GLB with its (first) JSON chunk edited; every other byte of the container kept."""
    declared_length, chunks, trailing = parse_glb(data)
    json_chunk = next((c for c in chunks if c[0] == GLB_JSON_CHUNK), None)
    if json_chunk is None:
        raise NoVariant("unparseable: GLB has no JSON chunk")
    bom, doc = parse_json_text(json_chunk[1])
    new_json = json_bytes(bom, edit(doc))
    # Pad with spaces to the original's alignment: 4 bytes, unless the original chunk was unaligned
    # (itself a corpus error, which the variant must keep).
    new_json += b" " * ((len(json_chunk[1]) - len(new_json)) % 4)
    growth = len(new_json) - len(json_chunk[1])
    json_chunk[1] = new_json
    # The header's length grows with the file; a wrong length (a corpus error) stays as wrong.
    out = bytearray(GLB_HEADER.pack(GLB_MAGIC, struct.unpack_from("<I", data, 4)[0], declared_length + growth))
    for chunk_type, body in chunks:
        out += GLB_CHUNK_HEADER.pack(len(body), chunk_type) + body
    return bytes(out + trailing)


def make_variant(model, error_pointers, with_every_mesh_and_camera):
    """The bytes of a variant of a corpus file; raises NoVariant."""
    def edit(doc):
        return appended_scene(doc, error_pointers, with_every_mesh_and_camera)

    data = model.read_bytes()
    if model.suffix == ".glb":
        return glb_variant(data, edit)
    bom, doc = parse_json_text(data)
    return json_bytes(bom, edit(doc))


# ---------------------------------------------------------------------------------------------
# Running qsgi


def run_inspect(qsgi, path, strict):
    """{exit, crash, errors, warnings, message} of `qsgi inspect PATH [--strict] --json`.

    Warnings are read from inspect's JSON ("warnings") and from stderr; the file's path is replaced
    by "<file>" in all text, so that a file name never passes for an object name.
    """
    command = [qsgi, "inspect", str(path), "--json"] + (["--strict"] if strict else [])
    try:
        done = subprocess.run(command, capture_output=True, timeout=TIMEOUT_SECONDS)
    except subprocess.TimeoutExpired:
        return {"exit": None, "crash": "no answer in %d s" % TIMEOUT_SECONDS,
                "errors": [], "warnings": [], "message": ""}
    stderr = done.stderr.decode("utf-8", "replace").splitlines()
    report_warnings = []
    if done.returncode == EXIT_LOADED:
        try:
            report_warnings = json.loads(done.stdout).get("warnings", [])
        except (ValueError, AttributeError):
            stderr.append("(inspect --json printed no JSON object)")
    return run_of(path, done.returncode, stderr, report_warnings)


def run_of(path, exit_code, stderr_lines, report_warnings):
    """A run's record from its exit code, its stderr lines and its report's warnings."""
    def clean(text):
        return text.replace(str(path), "<file>")

    stderr = [clean(line) for line in stderr_lines]
    errors = [line for line in stderr if not line.startswith("qsgi: warning: ")]
    warnings = [line for line in stderr if line.startswith("qsgi: warning: ")]
    if exit_code == EXIT_LOADED:
        warnings += [clean(w) for w in report_warnings]
    crash = None
    if exit_code < 0:
        crash = "signal %d" % -exit_code
    elif exit_code not in (EXIT_LOADED, EXIT_REFUSED):
        crash = "exit %d" % exit_code
    message = next(iter(errors if exit_code != EXIT_LOADED else warnings), "")
    return {"exit": exit_code, "crash": crash, "errors": errors, "warnings": warnings, "message": message}


def run_batch(qsgi, paths, strict, work_dir):
    """{path: run} for every path, from one `qsgi inspect --scenes LIST --json [--strict]`.

    Each line of its output is what the scene alone gives (exit code, error line, report). Where
    the batch process itself fails (a crash, no answer) or leaves a path out, those paths are run
    alone with run_inspect, so that a crash is charged to its file as before.
    """
    fd, list_name = tempfile.mkstemp(suffix=".txt", dir=work_dir)
    with os.fdopen(fd, "w", encoding="utf-8") as f:
        f.write("".join(str(p) + "\n" for p in paths))
    command = [qsgi, "inspect", "--scenes", list_name, "--json"] + (["--strict"] if strict else [])
    runs = {}
    try:
        done = subprocess.run(command, capture_output=True, timeout=TIMEOUT_SECONDS * max(1, len(paths) // 20))
        output = done.stdout
    except subprocess.TimeoutExpired as e:
        output = e.stdout or b""
    for line in output.decode("utf-8", "replace").splitlines():
        try:
            entry = json.loads(line)
        except ValueError:
            continue
        path = entry["scene"]
        warnings = (entry.get("report") or {}).get("warnings", []) if entry["exit"] == EXIT_LOADED else []
        runs[path] = run_of(path, entry["exit"], [entry["error"]] if entry["error"] else [], warnings)
    return {p: runs.get(str(p)) or run_inspect(qsgi, p, strict) for p in paths}


def naming_line(lines, names):
    """The first line in which any of the object names occurs as a whole name, or None.

    An indexed name ("accessors[0]") counts anywhere, unless it is the tail of a longer name
    ("scenes[0].nodes[0]" does not name nodes[0]). A bare name ("asset", "scene") counts only as
    the place at the start of a message ("<file>: asset.version: ..."), since it is also a word.
    """
    for name in names:
        if "[" in name:
            pattern = r"(?<![\w.])" + re.escape(name) + r"(?![\w])"
        else:
            pattern = r"<file>: " + re.escape(name) + r"(?=[.\[:])"
        for line in lines:
            if re.search(pattern, line):
                return line
    return None


# ---------------------------------------------------------------------------------------------
# Classing the runs


def class_of_invalid(variant, run, names, whole_file):
    """The class of a run of an invalid file (see the docstring at the top).

    Where qsgi names the object, the line that names it becomes the run's message.
    """
    if run["crash"]:
        return "crash"
    if variant == "scene --strict":
        return "refused" if run["exit"] == EXIT_REFUSED else "accepted"
    if run["exit"] == EXIT_REFUSED:
        line = naming_line(run["errors"], names)
        run["message"] = line or run["message"]
        return "refused-own" if whole_file or line else "refused-other"
    if variant == "all":
        # Loaded with a warning that the flagged object is in no rendered scene: nothing the
        # variant renders reaches it (an accessor no mesh reads, a texture no material names).
        # So is a slip in the document itself (an empty top-level array, a byte-order mark).
        unread = [w for w in run["warnings"] if "not in the rendered scene" in w or "read all the same" in w]
        line = naming_line(unread, names) or (whole_file and next((w for w in unread if "read all the same" in w), None))
        if line:
            run["message"] = line
            return "warned-unreachable"
        return "accepted"
    line = naming_line(run["warnings"], names)
    if not line and whole_file:
        # A slip in the document itself (a byte-order mark, a second BIN chunk) has no object to
        # name: qsgi's warnings about the document say "(the file is read all the same)".
        line = next((w for w in run["warnings"] if "read all the same" in w), None)
    run["message"] = line or run["message"]
    return "warned" if line else "silent"


def class_of_valid(run):
    if run["crash"]:
        return "crash"
    return "loaded" if run["exit"] == EXIT_LOADED else "refused"


INVALID_RUNS = [("scene", "scene", False), ("scene --strict", "scene", True), ("all", "all", False)]
# The original of a valid file is not run: almost none has a scene and a light of its own, so it
# would only be refused for that.
VALID_RUNS = INVALID_RUNS


def prepare_file(work_dir, category, model, report):
    """The record of one corpus file, with the paths of its variants made in work_dir/category."""
    errors = report_errors(report)
    pointers = [p for _, p in errors]
    valid = report["issues"]["numErrors"] == 0
    names = sorted({n for p in pointers for n in object_names(p)})
    result = {
        "file": "%s/%s" % (category, model.name), "valid": valid,
        "numErrors": report["issues"]["numErrors"], "codes": [c for c, _ in errors],
        "pointers": pointers, "object_names": names,
        "whole_file": any(is_whole_file(p) for p in pointers),
        "variant_skipped": {}, "runs": {},
    }
    folder = work_dir / category
    paths = {"original": folder / model.name}
    for variant in ("scene", "all"):
        try:
            data = make_variant(model, pointers, variant == "all")
        except NoVariant as e:
            # The variant would not be the original plus a scene: run the file as it is instead.
            result["variant_skipped"][variant] = str(e)
            paths[variant] = paths["original"]
            continue
        paths[variant] = folder / ("%s.%s%s" % (model.stem, variant, model.suffix))
        paths[variant].write_bytes(data)
    return result, paths


def run_everything(qsgi, work_dir, files, jobs):
    """Runs every file's variants, in batches (one qsgi per batch, `jobs` at once), and classes them.

    The plain runs first; then --strict, where the plain run did not refuse (--strict refuses all
    that the plain run refuses: the same answer, without the run).
    """
    def in_batches(wanted, strict):
        paths = sorted({str(p) for p in wanted})
        size = max(1, -(-len(paths) // (4 * max(1, jobs))))
        chunks = [[Path(p) for p in paths[i:i + size]] for i in range(0, len(paths), size)]
        runs = {}
        with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
            for part in pool.map(lambda chunk: run_batch(qsgi, chunk, strict, work_dir), chunks):
                runs.update({str(p): r for p, r in part.items()})
        return runs

    def refused(run):
        return run["exit"] == EXIT_REFUSED and not run["crash"]

    plain = in_batches([paths[variant] for _, paths in files for _, variant, strict in INVALID_RUNS if not strict], False)
    strict_runs = in_batches([paths[variant] for _, paths in files for _, variant, strict in INVALID_RUNS
                              if strict and not refused(plain[str(paths[variant])])], True)
    results = []
    for result, paths in files:
        valid = result["valid"]
        for label, variant, strict in (VALID_RUNS if valid else INVALID_RUNS):
            run = dict((strict_runs if strict and str(paths[variant]) in strict_runs else plain)[str(paths[variant])])
            run["class"] = (class_of_valid(run) if valid
                            else class_of_invalid(label, run, result["object_names"], result["whole_file"]))
            result["runs"][label] = run
        results.append(result)
    return results


def batch_equals_alone(qsgi, files, every):
    """Lines naming each sampled run whose batch answer differs from the same file run alone."""
    problems = []
    for i, (result, paths) in enumerate(files):
        if i % every:
            continue
        for label, variant, strict in INVALID_RUNS:
            batch = result["runs"][label]
            if strict and batch["exit"] == EXIT_REFUSED and result["runs"][label.replace(" --strict", "")]["exit"] == EXIT_REFUSED:
                continue  # not run: the plain run's answer
            alone = run_inspect(qsgi, paths[variant], strict)
            for key in ("exit", "errors", "warnings"):
                if alone[key] != batch[key]:
                    problems.append("%s %s: --scenes gave %s %r, alone %r" % (result["file"], label, key, batch[key], alone[key]))
    return problems


def copy_corpus_folders(data_dir, work_dir):
    """Copies every category's files but the reports, so that variants find their relative uris."""
    for folder in sorted(p for p in data_dir.iterdir() if p.is_dir()):
        target = work_dir / folder.name
        target.mkdir()
        for f in folder.iterdir():
            if f.is_file() and not f.name.endswith(".report.json"):
                shutil.copy2(f, target / f.name)


# ---------------------------------------------------------------------------------------------
# Summary, known gaps


def current_gaps(results):
    def files(test):
        return sorted(r["file"] for r in results if test(r))

    return {
        "invalid-silent-in-scene": files(lambda r: not r["valid"] and r["runs"]["scene"]["class"] == "silent"),
        "invalid-accepted-in-all": files(lambda r: not r["valid"] and r["runs"]["all"]["class"] == "accepted"),
        "valid-refused": files(lambda r: r["valid"] and r["runs"]["scene"]["class"] == "refused"),
        "valid-refused-under-strict": files(lambda r: r["valid"] and r["runs"]["scene --strict"]["class"] == "refused"),
        "crash": files(lambda r: any(run["class"] == "crash" for run in r["runs"].values())),
    }


def first_line(text, width=150):
    return text if len(text) <= width else text[:width - 3] + "..."


def print_class_lists(title, results, variant, unlisted=()):
    """Every class of one run, smallest first, with each file and qsgi's first line.

    The classes in unlisted are only counted (valid files that load: nothing to say about them).
    """
    by_class = collections.defaultdict(list)
    for r in results:
        by_class[r["runs"][variant]["class"]].append(r)
    for cls, members in sorted(by_class.items(), key=lambda item: (len(item[1]), item[0])):
        print("\n%s: %s (%d)" % (title, cls, len(members)))
        if cls in unlisted:
            print("  (not listed)")
            continue
        for r in members:
            run = r["runs"][variant]
            text = run["crash"] and "CRASH (%s) %s" % (run["crash"], run["message"]) or run["message"]
            if cls in ("silent", "accepted", "warned", "refused-other"):
                text = "[%s] %s" % (" ".join(sorted(set(r["codes"]))), text or "(no message)")
            print("  %-55s %s" % (r["file"], first_line(text)))


def print_summary(results, seconds):
    invalid = [r for r in results if not r["valid"]]
    valid = [r for r in results if r["valid"]]
    substituted = [r for r in results if r["variant_skipped"]]

    crashes = [(r["file"], label, run) for r in results for label, run in r["runs"].items() if run["crash"]]
    if crashes:
        print("!!! %d CRASHES (exit other than 0 and 2) !!!" % len(crashes))
        for file, label, run in crashes:
            print("  CRASH %-50s %-15s %s  %s" % (file, label, run["crash"], first_line(run["message"], 100)))
        print()

    print("validator corpus: %d files (%d invalid, %d valid) in %.0f s" % (len(results), len(invalid), len(valid), seconds))
    print("  %d had a variant that could not be made; the file was run as it is instead (listed at the end)"
          % len(substituted))
    print("invalid files: of %d" % len(invalid))
    for label, _, _ in INVALID_RUNS:
        counts = collections.Counter(r["runs"][label]["class"] for r in invalid)
        print("  %-15s %s" % (label, ", ".join("%s %d" % (c, n) for c, n in counts.most_common())))
    print("valid files: of %d" % len(valid))
    for label, _, _ in VALID_RUNS:
        counts = collections.Counter(r["runs"][label]["class"] for r in valid)
        print("  %-15s %s" % (label, ", ".join("%s %d" % (c, n) for c, n in counts.most_common())))

    for label, _, _ in INVALID_RUNS:
        print_class_lists("invalid, " + label, invalid, label)
    for label, _, _ in VALID_RUNS:
        print_class_lists("valid, " + label, valid, label, unlisted=("loaded",))

    print_codes_let_through(invalid)

    if substituted:
        print("\nVariants not made; the file was run as it is instead:")
        for r in substituted:
            for variant, why in r["variant_skipped"].items():
                print("  %-55s %-6s %s" % (r["file"], variant, why))


def print_codes_let_through(invalid):
    """The to-do list: the report's error codes of the invalid files qsgi lets through, as files per code."""
    let_through = [("scene", "silent"), ("scene --strict", "accepted"), ("all", "accepted")]
    counts = {code: [0] * len(let_through) for r in invalid for code in r["codes"]}
    for column, (label, cls) in enumerate(let_through):
        for r in invalid:
            if r["runs"][label]["class"] == cls:
                for code in set(r["codes"]):
                    counts[code][column] += 1
    rows = sorted(((code, n) for code, n in counts.items() if any(n)), key=lambda row: (-sum(row[1]), row[0]))
    print("\nTo do: error codes of the invalid files qsgi lets through (files per code)")
    print("  %-50s %s" % ("code", "  ".join("%s %s" % lc for lc in let_through)))
    for code, n in rows:
        print("  %-50s %12d  %23d  %12d" % (code, *n))
    if not rows:
        print("  none")


def compare_with_expected(gaps, expected):
    """Lines saying where the results are worse or better than the known gaps; [] when they match."""
    problems = []
    for key, files in gaps.items():
        listed = set(expected.get(key, []))
        for f in sorted(set(files) - listed):
            problems.append("not in the list %r: %s" % (key, f))
        for f in sorted(listed - set(files)):
            problems.append("now handled, remove from the list %r: %s" % (key, f))
    for key in sorted(set(expected) - set(gaps)):
        problems.append("unknown list %r in the expectations" % key)
    return problems


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--qsgi", required=True, help="the qsgi executable")
    parser.add_argument("--corpus", type=Path, default=DEFAULT_CORPUS, help="the corpus (default: %(default)s)")
    parser.add_argument("--jobs", type=int, default=2, help="files checked at once (default: 2)")
    parser.add_argument("--json", type=Path, help="write every file's results here")
    parser.add_argument("--expect", type=Path, help="JSON file of known gaps; exit 1 when worse or better")
    parser.add_argument("--write-expect", type=Path, help="write the current gaps here, in --expect's form")
    args = parser.parse_args()

    data_dir = args.corpus / "test/base/data"
    if not data_dir.is_dir():
        print("validator corpus: skipped (%s absent)" % args.corpus)
        return SKIPPED
    if not Path(args.qsgi).is_file():
        parser.error("no qsgi executable at %s" % args.qsgi)
    qsgi = str(Path(args.qsgi).resolve())

    started = time.monotonic()
    with tempfile.TemporaryDirectory(prefix="validator_corpus.") as tmp:
        work_dir = Path(tmp)
        copy_corpus_folders(data_dir, work_dir)
        files = [prepare_file(work_dir, *item) for item in corpus_files(data_dir)]
        results = run_everything(qsgi, work_dir, files, args.jobs)
        # One file in SAMPLE_EVERY is run alone too: `--scenes` must answer as single runs do.
        batch_problems = batch_equals_alone(qsgi, files, SAMPLE_EVERY)
    seconds = time.monotonic() - started

    print_summary(results, seconds)
    gaps = current_gaps(results)
    if args.json:
        args.json.write_text(json.dumps({"seconds": round(seconds, 1), "gaps": gaps, "files": results}, indent=1) + "\n")
    if args.write_expect:
        args.write_expect.write_text(json.dumps(gaps, indent=1) + "\n")

    failed = False
    if args.expect:
        problems = compare_with_expected(gaps, json.loads(args.expect.read_text()))
        print("\nAgainst %s: %s" % (args.expect, "as expected" if not problems else "%d differences" % len(problems)))
        for line in problems:
            print("  " + line)
        failed = bool(problems)
    elif gaps["crash"]:
        failed = True
    print("\n--scenes against runs alone (every %dth file): %s" % (SAMPLE_EVERY, "the same" if not batch_problems
                                                                     else "%d differences" % len(batch_problems)))
    for line in batch_problems:
        print("  " + line)
    failed = failed or bool(batch_problems)
    if gaps["crash"]:
        print("\n%d file(s) crash qsgi: %s" % (len(gaps["crash"]), ", ".join(gaps["crash"])))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
