#!/usr/bin/env python3
"""Checks that the map and the door stay true to the tree (README.md, ARCHITECTURE.md):

  - every file ARCHITECTURE.md names exists: in the stage table a name (`render_job.*`,
    `trace_settings.h`, `impact_count*.cpp`, `_estimator.cpp` for every `*_estimator.cpp`) is looked
    up in its row's folder; a path anywhere (`lib/output/frame_sink.h`, `tests/data/bad/found.tsv`)
    from the repository's root; a source file named alone elsewhere (`detp.cpp`) anywhere under
    lib/ and cli/;
  - every file under lib/ and cli/ (but CMakeLists.txt) has a line: some name in its folder's rows
    of the table matches it;
  - README.md has at most 150 lines (a door: the reference lives in docs/).

Prints one line per problem (file: what) and exits 1 if there is any. Reads files only: it takes
well under a second. Usage: scripts/check_architecture.py [REPOSITORY]
"""
import fnmatch
import os
import re
import sys

ROOT = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), ".."))
README_MOST_LINES = 150
MAPPED_FOLDERS = ("lib", "cli")
TOP_FOLDERS = ("lib", "cli", "tests", "bench", "fuzz", "scripts", "docs", "data", "configs", ".ci")
CODE = re.compile(r"`([^`]+)`")
# A file name as the table writes it: a stem with an extension, either of which may be a pattern.
FILE_NAME = re.compile(r"^[A-Za-z0-9_*][A-Za-z0-9_.*-]*\.[A-Za-z*]+$")
SOURCE_FILE = re.compile(r"^[a-z0-9][a-z0-9_]*\.(?:cpp|h)$")
# Paths that a run or a build makes, not the repository.
MADE_LATER = re.compile(r"^(build|out)/")


def mapped_files():
    """Every file under lib/ and cli/ (repository-relative), but the build's own CMakeLists.txt."""
    files = []
    for top in MAPPED_FOLDERS:
        for folder, dirs, names in os.walk(os.path.join(ROOT, top)):
            dirs[:] = [d for d in dirs if not d.startswith(".")]
            for name in names:
                if name != "CMakeLists.txt":
                    files.append(os.path.relpath(os.path.join(folder, name), ROOT))
    return sorted(files)


def pattern_of(name):
    # `_estimator.cpp` in the table means each estimator's file of that suffix.
    return "*" + name if name.startswith("_") else name


def table_rows(lines):
    """(line number, folders, names) of each row of the stage table: its folder cell's folders and
    the file names its last cell gives."""
    rows = []
    for number, line in enumerate(lines, 1):
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if not line.startswith("|") or len(cells) < 3 or set(cells[0]) <= set("-: "):
            continue
        folders = [f.rstrip("/") for f in CODE.findall(cells[1]) if f.endswith("/")]
        if not folders:
            continue  # the header row
        names = [n for n in CODE.findall(cells[-1]) if "/" not in n and FILE_NAME.match(n)]
        rows.append((number, folders, names))
    return rows


def main():
    problems = []
    files = mapped_files()
    with open(os.path.join(ROOT, "ARCHITECTURE.md"), encoding="utf-8") as f:
        text = f.read()
    lines = text.split("\n")

    # Names in the table, each in its row's folder.
    covered = set()
    for number, folders, names in table_rows(lines):
        for name in names:
            matched = [p for folder in folders for p in files if os.path.dirname(p) == folder
                       and fnmatch.fnmatchcase(os.path.basename(p), pattern_of(name))]
            if not matched and not any(os.path.exists(os.path.join(ROOT, folder, name)) for folder in folders):
                problems.append(f"ARCHITECTURE.md:{number}: `{name}` names no file in {', '.join(f + '/' for f in folders)}")
            covered.update(matched)

    # Paths from the root, anywhere in the text.
    path = re.compile(r"(?<![\w./-])((?:%s)/[A-Za-z0-9_./*-]*)" % "|".join(re.escape(t) for t in TOP_FOLDERS))
    for number, line in enumerate(lines, 1):
        for p in path.findall(line):
            p = p.rstrip(".")
            if MADE_LATER.match(p):
                continue
            pattern = p.rstrip("/")
            found = [f for f in files if fnmatch.fnmatchcase(f, pattern)] or \
                (os.path.exists(os.path.join(ROOT, pattern)) if "*" not in pattern else
                 any(fnmatch.fnmatchcase(os.path.relpath(os.path.join(d, n), ROOT), pattern)
                     for d, _, ns in os.walk(os.path.join(ROOT, pattern.split("/")[0])) for n in ns))
            if not found:
                problems.append(f"ARCHITECTURE.md:{number}: {p} does not exist")

    # A source file named alone outside the table: somewhere under lib/ or cli/.
    table_lines = {number for number, _, _ in table_rows(lines)}
    basenames = {os.path.basename(f) for f in files}
    for number, line in enumerate(lines, 1):
        if number in table_lines:
            continue
        for name in CODE.findall(line):
            if SOURCE_FILE.match(name) and name not in basenames:
                problems.append(f"ARCHITECTURE.md:{number}: `{name}` is no file under {' or '.join(MAPPED_FOLDERS)}/")

    for f in files:
        if f not in covered:
            problems.append(f"ARCHITECTURE.md: {f} has no line (name it in the row of {os.path.dirname(f)}/)")

    with open(os.path.join(ROOT, "README.md"), encoding="utf-8") as f:
        readme_lines = len(f.read().rstrip("\n").split("\n"))
    if readme_lines > README_MOST_LINES:
        problems.append(f"README.md: {readme_lines} lines, more than {README_MOST_LINES} (move the detail to docs/ and link it)")

    for p in problems:
        print(p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
