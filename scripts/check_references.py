#!/usr/bin/env python3
"""Checks that every reference in the code's comments and the docs resolves (issue 22, item 6;
issue 31, part 10).

  - a path inside the repository (`lib/trace/ray_cache.h`, `tests/data/bad/found.tsv`,
    `scripts/run.sh`) names a file or folder that exists;
  - a source file named alone in a comment (`gltf_loader.cpp`, `ray_cache.h`) exists somewhere in
    the repository;
  - a citation of the design, `docs/design.md` followed by a section sign and a number, names a
    section of docs/design.md: N a heading `## N.`, N.M (and "N step M") a heading `### N.M`.
    Every tracked file is searched (`git ls-files`, with the files not yet added that .gitignore
    does not exclude; every file but build and output folders where the tree is not a git
    checkout), in its code as well as its comments, also where a line break splits the citation.
    Inside docs/design.md a bare section sign and number must resolve too;
  - no citation of the specification the project was started from (the word DESIGN followed by
    a section sign) remains: that file is not in the repository, so a reader cannot follow it;
  - a Markdown link to a local file (`[Outputs](outputs.md)`, `[x](design.md#62-affected-paths)`)
    names a file that exists, and its #anchor a heading of that file.

Prints one line per broken reference (file:line: what) and exits 1 if there is any.
Usage: scripts/check_references.py [REPOSITORY]
"""
import os
import re
import subprocess
import sys

ROOT = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), ".."))
SOURCE_FOLDERS = ["lib", "cli", "tests", "bench", "fuzz", "scripts"]
SOURCE_SUFFIXES = (".h", ".cpp", ".py", ".sh", ".txt")
TOP_FOLDERS = "lib|cli|tests|bench|fuzz|scripts|docs|data|configs|\\.ci"
PATH = re.compile(r"(?<![\w./-])((?:%s)/[A-Za-z0-9_./*-]*[A-Za-z0-9_*])" % TOP_FOLDERS)
FILE_NAME = re.compile(r"(?<![\w./<>-])([a-z0-9][a-z0-9_]*\.(?:cpp|h))\b")
# Paths a comment may name that the repository does not hold: made at run time or by a build.
MADE_LATER = re.compile(r"^(build|out)/|/(out|corpus|artifacts|seeds)/|^tests/golden/.*\.(exr|png)$")

SIGN = "\u00a7"
DESIGN_DOC = "docs/design.md"
# One cited section: "§6", "§6.4", "§6 step 4", "§6 steps 2–3" (the first step is checked).
_SECTION = r"§\s?(\d+)(?:\.(\d+)|\s+steps?\s+(\d+))?"
DESIGN_CITATION = re.compile(r"docs/design\.md\s+" + _SECTION)
# Further sections cited in the same breath: "§5–§6", "§2, §7", "§5, §6 step 4", "§2 and §3".
MORE_SECTIONS = re.compile(r"\s*(?:,|–|-|and|or)\s*" + _SECTION)
# Inside docs/design.md: a section sign alone ("see §6.2").
OWN_SECTION = re.compile(r"(?<![\w/.])" + _SECTION)
# The specification outside the repository: the word, then the section sign.
BARE_DESIGN = re.compile(r"\bDESIGN\s*§\s?(\d+(?:\.\d+)?)")
MARKDOWN_LINK = re.compile(r"\]\(([^()\s]+)\)")
# The start of a comment line, stripped from the next line before it is joined to this one.
CONTINUATION = re.compile(r"^\s*(?://+!?|#+|\*+|--|<!--)?\s*")
SKIPPED_FOLDERS = ("node_modules", "__pycache__", "out")


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


def files_to_check():
    for folder in SOURCE_FOLDERS:
        for base, dirs, files in os.walk(os.path.join(ROOT, folder)):
            dirs[:] = [d for d in dirs if d not in ("node_modules", "venv", "data", "golden", "__pycache__")]
            for name in files:
                if name.endswith(SOURCE_SUFFIXES) or name == "CMakeLists.txt":
                    yield os.path.join(base, name)
    for name in ["README.md", "ARCHITECTURE.md", "CMakeLists.txt", ".ci/run"]:
        if os.path.exists(os.path.join(ROOT, name)):
            yield os.path.join(ROOT, name)
    for name in sorted(os.listdir(os.path.join(ROOT, "docs"))):
        if name.endswith(".md"):
            yield os.path.join(ROOT, "docs", name)


def tracked_files():
    """Paths (relative to ROOT) of the files git tracks, with the untracked ones .gitignore does not
    exclude; where ROOT is not a git checkout (a copy, an unpacked archive), every file outside
    build and output folders."""
    try:
        out = subprocess.run(["git", "-C", ROOT, "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
                             capture_output=True, check=True).stdout
        top = subprocess.run(["git", "-C", ROOT, "rev-parse", "--show-toplevel"], capture_output=True, check=True,
                             text=True).stdout.strip()
        if os.path.realpath(top) == os.path.realpath(ROOT):
            return sorted({p for p in out.decode("utf-8", "replace").split("\0") if p})
    except (OSError, subprocess.CalledProcessError):
        pass
    found = []
    for base, dirs, files in os.walk(ROOT):
        dirs[:] = [d for d in dirs if not d.startswith((".git", "build")) and d not in SKIPPED_FOLDERS]
        found.extend(os.path.relpath(os.path.join(base, name), ROOT) for name in files)
    return sorted(found)


def text_of(rel):
    """The file's lines, or None for a binary file or one that is gone."""
    try:
        with open(os.path.join(ROOT, rel), "rb") as f:
            data = f.read()
    except OSError:
        return None
    if b"\0" in data[:65536]:
        return None
    return data.decode("utf-8", "replace").split("\n")


def fenced(lines):
    """Per line: inside a ``` code block (the block's fence lines included)."""
    inside, out = False, []
    for line in lines:
        fence = line.lstrip().startswith("```")
        out.append(inside or fence)
        if fence:
            inside = not inside
    return out


def heading_anchor(heading):
    """The anchor GitHub gives a Markdown heading: lower case, punctuation dropped, spaces as '-'."""
    text = re.sub(r"`|\*\*|__", "", heading.strip().lower())
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def markdown_anchors(lines):
    anchors, seen = set(), {}
    for line, in_code in zip(lines, fenced(lines)):
        m = re.match(r"#{1,6}\s+(.*?)\s*#*\s*$", line)
        if m and not in_code:
            anchor = heading_anchor(m.group(1))
            count = seen.get(anchor, 0)
            seen[anchor] = count + 1
            anchors.add(anchor if count == 0 else f"{anchor}-{count}")
    return anchors


def design_sections():
    """({N}, {(N, M)}) of docs/design.md's headings, or None if the file is missing."""
    lines = text_of(DESIGN_DOC)
    if lines is None:
        return None
    sections, steps = set(), set()
    for line, in_code in zip(lines, fenced(lines)):
        if in_code:
            continue
        m = re.match(r"## (\d+)\.", line)
        if m:
            sections.add(int(m.group(1)))
        m = re.match(r"### (\d+)\.(\d+)\b", line)
        if m:
            steps.add((int(m.group(1)), int(m.group(2))))
    return sections, steps


def unresolved(design, section, item, step):
    sections, steps = design
    cited = f"{SIGN}{section}" + (f".{item}" if item else f" step {step}" if step else "")
    if int(section) not in sections:
        return f"{DESIGN_DOC} {cited}: no section '## {section}.' in {DESIGN_DOC}"
    sub = item or step
    if sub and (int(section), int(sub)) not in steps:
        return f"{DESIGN_DOC} {cited}: no heading '### {section}.{sub}' in {DESIGN_DOC}"
    return None


def joined(lines, i):
    """Line i with the next line's text after it (its comment marker stripped), so that a citation
    a line break splits is found; matches must start on line i itself."""
    nxt = CONTINUATION.sub("", lines[i + 1], count=1) if i + 1 < len(lines) else ""
    return lines[i] + " " + nxt


def check_design_citations(rel, lines, design, broken):
    own = rel == DESIGN_DOC
    code = fenced(lines) if rel.endswith(".md") else [False] * len(lines)
    for i, line in enumerate(lines):
        text = joined(lines, i)
        for m in BARE_DESIGN.finditer(text):
            if m.start() < len(line):
                broken.append(f"{rel}:{i + 1}: DESIGN {SIGN}{m.group(1)} cites a file that is not in the repository; "
                              f"cite {DESIGN_DOC} {SIGN}{m.group(1)}")
        cited = []
        for m in DESIGN_CITATION.finditer(text):
            if m.start() >= len(line):
                continue
            cited.append(m.groups())
            at = m.end()
            while True:
                more = MORE_SECTIONS.match(text, at)
                if not more:
                    break
                cited.append(more.groups())
                at = more.end()
        if own and not code[i]:
            spans = [m.span() for m in DESIGN_CITATION.finditer(text)]
            for m in OWN_SECTION.finditer(line):
                if not any(a <= m.start() < b for a, b in spans):
                    cited.append(m.groups())
        if cited and design is None:
            broken.append(f"{rel}:{i + 1}: cites {DESIGN_DOC}, which does not exist")
            continue
        for section, item, step in cited:
            problem = unresolved(design, section, item, step)
            if problem:
                broken.append(f"{rel}:{i + 1}: {problem}")


def check_markdown_links(rel, lines, anchors_of, broken):
    code = fenced(lines)
    for i, line in enumerate(lines):
        if code[i]:
            continue
        for target in MARKDOWN_LINK.findall(line):
            if re.match(r"^[a-z][a-z0-9+.-]*:", target):  # https:, mailto: …
                continue
            path, _, anchor = target.partition("#")
            dest = os.path.normpath(os.path.join(os.path.dirname(rel), path)) if path else rel
            if not os.path.exists(os.path.join(ROOT, dest)):
                broken.append(f"{rel}:{i + 1}: link to {target}: {dest} does not exist")
                continue
            if anchor and dest.endswith(".md"):
                if dest not in anchors_of:
                    anchors_of[dest] = markdown_anchors(text_of(dest) or [])
                if anchor not in anchors_of[dest]:
                    broken.append(f"{rel}:{i + 1}: link to {target}: {dest} has no heading with the anchor #{anchor}")


def main():
    names = set()
    for base, dirs, files in os.walk(ROOT):
        dirs[:] = [d for d in dirs if not d.startswith((".git", "build")) and d not in ("node_modules", "venv")]
        names.update(files)
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
    design = design_sections()
    anchors_of = {}
    for rel in tracked_files():
        if rel.startswith("scripts/gltf-check/node_modules/"):
            continue
        lines = text_of(rel)
        if lines is None:
            continue
        check_design_citations(rel, lines, design, broken)
        if rel.endswith(".md"):
            check_markdown_links(rel, lines, anchors_of, broken)
    for line in broken:
        print(line)
    print(f"check_references: {len(broken)} broken reference(s)")
    return 1 if broken else 0


if __name__ == "__main__":
    sys.exit(main())
