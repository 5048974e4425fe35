#!/usr/bin/env python3
"""Checks that every reference in the code's comments and the docs resolves (issue 22, item 6).

  - a path inside the repository (`lib/trace/ray_cache.h`, `tests/data/bad/found.tsv`,
    `scripts/run.sh`) names a file or folder that exists;
  - a source file named alone in a comment (`gltf_loader.cpp`, `ray_cache.h`) exists somewhere in
    the repository;
  - `DESIGN §N` names a section of ../shared/DESIGN.md, and `§N.M` an item M of that section
    (checked only where ../shared is beside the repository, as it is in CI).

Prints one line per broken reference (file:line: what) and exits 1 if there is any.
Usage: scripts/check_references.py [REPOSITORY]
"""
import os
import re
import sys

ROOT = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), ".."))
SOURCE_FOLDERS = ["lib", "cli", "tests", "bench", "fuzz", "scripts"]
SOURCE_SUFFIXES = (".h", ".cpp", ".py", ".sh", ".txt")
TOP_FOLDERS = "lib|cli|tests|bench|fuzz|scripts|docs|data|configs|\\.ci"
PATH = re.compile(r"(?<![\w./-])((?:%s)/[A-Za-z0-9_./*-]*[A-Za-z0-9_*])" % TOP_FOLDERS)
FILE_NAME = re.compile(r"(?<![\w./<>-])([a-z0-9][a-z0-9_]*\.(?:cpp|h))\b")
DESIGN_REF = re.compile(r"DESIGN\s+§\s?(\d+)(?:\.(\d+))?")
# Paths a comment may name that the repository does not hold: made at run time or by a build.
MADE_LATER = re.compile(r"^(build|out)/|/(out|corpus|artifacts|seeds)/|^tests/golden/.*\.(exr|png)$")


def comment_lines(path):
    """(line number, text) of the comments of a source file, or of every line of other files."""
    with open(path, encoding="utf-8", errors="replace") as f:
        lines = f.read().split("\n")
    if path.endswith((".h", ".cpp")):
        for i, line in enumerate(lines, 1):
            at = line.find("//")
            if at >= 0:
                yield i, line[at:]
    elif path.endswith((".py", ".sh", ".txt")) or os.path.basename(path) in ("CMakeLists.txt", "run"):
        for i, line in enumerate(lines, 1):
            at = line.find("#")
            if at >= 0:
                yield i, line[at:]
    else:  # Markdown: all of it
        yield from enumerate(lines, 1)


def design_sections():
    design = os.path.join(ROOT, "..", "shared", "DESIGN.md")
    if not os.path.exists(design):
        return None
    sections, current = {}, None
    for line in open(design, encoding="utf-8"):
        m = re.match(r"## (\d+)\.", line)
        if m:
            current = int(m.group(1))
            sections[current] = set()
            continue
        m = re.match(r"(\d+)\. ", line)
        if m and current is not None:
            sections[current].add(int(m.group(1)))
    return sections


def files_to_check():
    for folder in SOURCE_FOLDERS:
        for base, dirs, files in os.walk(os.path.join(ROOT, folder)):
            dirs[:] = [d for d in dirs if d not in ("node_modules", "data", "golden", "__pycache__")]
            for name in files:
                if name.endswith(SOURCE_SUFFIXES) or name == "CMakeLists.txt":
                    yield os.path.join(base, name)
    for name in ["README.md", "ARCHITECTURE.md", "CMakeLists.txt", ".ci/run"]:
        if os.path.exists(os.path.join(ROOT, name)):
            yield os.path.join(ROOT, name)
    for name in sorted(os.listdir(os.path.join(ROOT, "docs"))):
        if name.endswith(".md"):
            yield os.path.join(ROOT, "docs", name)


def main():
    names = set()
    for base, dirs, files in os.walk(ROOT):
        dirs[:] = [d for d in dirs if not d.startswith((".git", "build")) and d != "node_modules"]
        names.update(files)
    sections = design_sections()
    broken = []
    for path in files_to_check():
        rel = os.path.relpath(path, ROOT)
        for number, text in comment_lines(path):
            for ref in PATH.findall(text):
                ref = ref.rstrip(".")
                if MADE_LATER.search(ref) or "*" in ref or "NNNN" in ref:
                    continue
                if not os.path.exists(os.path.join(ROOT, ref)):
                    broken.append(f"{rel}:{number}: {ref} does not exist")
            for name in FILE_NAME.findall(text):
                if name not in names:
                    broken.append(f"{rel}:{number}: no file {name} in the repository")
            if sections is not None:
                for section, item in DESIGN_REF.findall(text):
                    if int(section) not in sections:
                        broken.append(f"{rel}:{number}: DESIGN §{section} does not exist")
                    elif item and int(item) not in sections[int(section)]:
                        broken.append(f"{rel}:{number}: DESIGN §{section}.{item}: section {section} has no item {item}")
    for line in broken:
        print(line)
    if sections is None:
        print("check_references: ../shared/DESIGN.md is absent; DESIGN sections were not checked")
    print(f"check_references: {len(broken)} broken reference(s)")
    return 1 if broken else 0


if __name__ == "__main__":
    sys.exit(main())
