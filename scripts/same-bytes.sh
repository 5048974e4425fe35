#!/usr/bin/env bash
# Renders the same cases with two qsgi binaries and compares what they wrote, byte for byte: the
# check that a refactoring changed no output. Every file of each output folder is compared with
# cmp (PLY, EXR, PNG, asset.glb, asset.usda), except timing.json, whose times differ from run to
# run: of it the inputs' fingerprint (config.inputs_fingerprint, and the parts under "inputs") and
# every recorded option, the scene's figures, and each frame's files (name, size, XXH3), its
# from-scratch decision and its counts must be equal; times (`*_s`) and memory figures (`*bytes`)
# are left out, and a field only one side has is named but not counted as a difference (a field
# renamed on purpose).
#
# The cases: data/cornell frames 0:3, 2:3, and 0:1 resumed to 0:3 (--resume); data/walker's glTF
# animation 0:2 with --gltf-out --usd-out, and 0:1 with --subdivide 0.25 --exr-half; data/cornell
# 0:1 with --vertex-fit least-squares and with --refine-contacts 0.05. Each with --png (and EXR,
# on by default) so that the images are compared too, at 64 x 48 pixels and 20000 photons so that
# the whole comparison takes a few minutes.
#
# Usage: scripts/same-bytes.sh OLD_QSGI NEW_QSGI [WORKDIR]
#   WORKDIR (default: a new temporary folder) receives OLD/ and NEW/, one folder per case; it is
#   kept, so that a difference can be looked at. SAME_BYTES_THREADS sets --threads (default 1:
#   any count gives the same bytes); SAME_BYTES_CASES, a list of case names, runs only those.
# Prints one line per case and exits 0 when every case is identical, 1 when any differs or a
# render fails, 2 on a usage error.
set -uo pipefail

if [[ $# -lt 2 || $# -gt 3 || "$1" == -h || "$1" == --help ]]; then
    sed -n '2,/^set -uo/p' "$0" | sed '$d; s/^# \{0,1\}//'
    exit 2
fi
old=$1 new=$2
for bin in "$old" "$new"; do
    if [[ ! -x "$bin" ]]; then echo "same-bytes.sh: $bin is not an executable" >&2; exit 2; fi
done
work=${3:-$(mktemp -d "${TMPDIR:-/tmp}/qsgi-same-bytes.XXXXXX")}
mkdir -p "$work" || exit 2
root=$(cd "$(dirname "$0")/.." && pwd)
cornell="$root/data/cornell/cornell.gltf --animation $root/data/cornell/animation.json"
walker="$root/data/walker/walker.gltf --animation gltf"
common="--photons 20000 --width 64 --height 48 --png --quiet --threads ${SAME_BYTES_THREADS:-1}"

# name|arguments, and for a resumed case the first run's arguments after a second |.
cases=(
    "cornell-0-3|$cornell --frames 0:3"
    "cornell-2-3|$cornell --frames 2:3"
    "cornell-resumed-0-1-to-0-3|$cornell --frames 0:3 --resume|$cornell --frames 0:1"
    "walker-gltf-usd-0-2|$walker --frames 0:2 --gltf-out --usd-out"
    "walker-subdivide-exr-half-0-1|$walker --frames 0:1 --subdivide 0.25 --exr-half"
    "cornell-vertex-fit-0-1|$cornell --frames 0:1 --vertex-fit least-squares"
    "cornell-refine-contacts-0-1|$cornell --frames 0:1 --refine-contacts 0.05"
)

# render BINARY OUT ARGUMENTS: one run; its output goes to OUT.log.
render() {
    local bin=$1 out=$2
    shift 2
    # shellcheck disable=SC2086  # the arguments are words by design
    "$bin" render $* $common --out "$out" >>"$out.log" 2>&1
}

# The timing.json comparison: prints what differs, one item a line; exit 1 if anything does.
compare_timing() {
    python3 - "$1" "$2" <<'PY'
import json, sys

a, b = (json.load(open(p)) for p in sys.argv[1:3])
differs, notes = [], []

def volatile(key):
    return key.endswith("_s") or key.endswith("bytes")

def walk(x, y, where):
    if isinstance(x, dict) and isinstance(y, dict):
        for key in sorted(set(x) | set(y)):
            place = f"{where}.{key}" if where else key
            if volatile(key) or key == "files":  # files: compared whole above
                continue
            if key not in x or key not in y:
                notes.append(f"{place} only in {'new' if key not in x else 'old'}")
                continue
            walk(x[key], y[key], place)
    elif isinstance(x, list) and isinstance(y, list):
        if len(x) != len(y):
            differs.append(f"{where}: {len(x)} entries against {len(y)}")
        for i, (u, v) in enumerate(zip(x, y)):
            walk(u, v, f"{where}[{i}]")
    elif x != y:
        differs.append(f"{where}: {json.dumps(x)[:40]} against {json.dumps(y)[:40]}")

# The files each frame records are compared whole (their sizes too): they are what --resume checks.
for fa, fb in zip(a.get("frames", []), b.get("frames", [])):
    if fa.get("files") != fb.get("files"):
        differs.append(f"frames[frame {fa.get('frame')}].files (sizes or checksums)")
walk(a, b, "")
differs.sort(key=lambda d: not d.startswith("config.inputs_fingerprint"))  # the fingerprint first
fingerprint = (a.get("config") or {}).get("inputs_fingerprint")
for line in differs:
    print("timing.json " + line)
for line in notes:
    print("note: timing.json " + line)
print(f"fingerprint {fingerprint}")
sys.exit(1 if differs else 0)
PY
}

status=0 ran=0
for spec in "${cases[@]}"; do
    IFS='|' read -r name arguments before <<<"$spec"
    if [[ -n "${SAME_BYTES_CASES:-}" && " $SAME_BYTES_CASES " != *" $name "* ]]; then continue; fi
    ran=$((ran + 1))
    ok=1
    for side in OLD NEW; do
        bin=$old
        [[ $side == NEW ]] && bin=$new
        out="$work/$side/$name"
        rm -rf "$out" "$out.log"
        mkdir -p "$work/$side"
        if [[ -n "$before" ]] && ! render "$bin" "$out" "$before"; then
            echo "$name: FAILED: $side's first run exited non-zero (see $out.log)"
            ok=0
            continue
        fi
        if ! render "$bin" "$out" "$arguments"; then
            echo "$name: FAILED: $side exited non-zero (see $out.log)"
            ok=0
        fi
    done
    if [[ $ok == 0 ]]; then
        status=1
        continue
    fi
    a="$work/OLD/$name" b="$work/NEW/$name"
    problems=()
    # Every file either side wrote (not the lock, which names its holder).
    mapfile -t files < <( (cd "$a" && find . -type f ! -name '.*'; cd "$b" && find . -type f ! -name '.*') | sort -u)
    compared=0
    for f in "${files[@]}"; do
        f=${f#./}
        if [[ ! -f "$a/$f" || ! -f "$b/$f" ]]; then
            problems+=("$f only in $([[ -f "$a/$f" ]] && echo OLD || echo NEW)")
            continue
        fi
        [[ $f == timing.json ]] && continue
        compared=$((compared + 1))
        if ! diff_at=$(cmp "$a/$f" "$b/$f" 2>&1); then diff_at=${diff_at##* differ: }; problems+=("$f: ${diff_at%%, line *}"); fi
    done
    timing="" timing_status=0
    if [[ -f "$a/timing.json" && -f "$b/timing.json" ]]; then
        timing=$(compare_timing "$a/timing.json" "$b/timing.json" 2>&1)
        timing_status=$?
    fi
    fingerprint=$(grep '^fingerprint ' <<<"$timing" | cut -d' ' -f2)
    notes=$(grep '^note: ' <<<"$timing" | sed 's/^note: //' | paste -sd ';' -)
    if [[ $timing_status != 0 ]]; then
        mapfile -t lines < <(grep -v '^fingerprint \|^note: ' <<<"$timing")
        problems=("${lines[@]}" "${problems[@]}")
    fi
    if [[ ${#problems[@]} == 0 ]]; then
        echo "$name: identical ($compared files byte for byte; timing.json: inputs_fingerprint $fingerprint, every count equal${notes:+; $notes})"
    else
        status=1
        # The first few on the line, and how many more (the folders are kept for the rest).
        summary=$(printf '%s; ' "${problems[@]:0:10}")
        more=$((${#problems[@]} - 10))
        echo "$name: DIFFERS (${#problems[@]}): ${summary%; }$([[ $more -gt 0 ]] && echo "; and $more more")"
    fi
done
if [[ $ran == 0 ]]; then
    echo "same-bytes.sh: no case is named '${SAME_BYTES_CASES:-}'; the cases: $(printf '%s ' "${cases[@]%%|*}")" >&2
    exit 2
fi
echo "outputs in $work"
exit $status
