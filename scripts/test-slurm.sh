#!/usr/bin/env bash
# The Slurm job arrays tested for real on a single-node cluster started here
# (scripts/slurm/local-cluster.sh; needs root or sudo):
#   1. a render split into 4 frame chunks writes every PLY, EXR and PNG byte for byte as one
#      sequential run, and the merged timing.json lists every frame once, in order; --gltf-out's
#      asset.glb and --usd-out's asset.usda, made after the merge from all the frames, are the
#      sequential run's too, and no
#      chunk (run with --frames-only) writes one of its own;
#   2. an array task killed mid-chunk (scancel) leaves the merge undone; submitting the same
#      command again runs only that chunk (resumed from its last complete frame) and the merge,
#      and the result is again byte-identical;
#   3. a sweep submitted as a job array (tests/data/sweep-tiny.json) ends with the same sweep.csv
#      rows as computed locally, and resubmitting submits no point.
# Uses build/cli/qsgi (scripts/test.sh builds it; QSGI=path overrides). About 2 minutes on 2 cores.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
qsgi=${QSGI:-$root/build/cli/qsgi}
[ -x "$qsgi" ] || { echo "test-slurm: no $qsgi; build first (scripts/test.sh)" >&2; exit 1; }

scripts/slurm/local-cluster.sh start
export SLURM_CONF=${QSGI_SLURM_DIR:-/tmp/qsgi-slurm}/slurm.conf
work=$(mktemp -d /tmp/qsgi-slurm-test.XXXXXX)
cleanup() { scancel --user="$(id -un)" 2>/dev/null || true; scripts/slurm/local-cluster.sh stop; rm -rf "$work"; }
trap cleanup EXIT

fail() { echo "test-slurm: FAILED: $*" >&2; exit 1; }

wait_for_queue() {  # until no job of ours can still run (at most 10 minutes); a merge whose
  # dependency failed waits forever (DependencyNeverSatisfied) until a resubmission replaces it
  for _ in $(seq 600); do
    [ -z "$(squeue -h -u "$(id -un)" -o '%r' | grep -v DependencyNeverSatisfied)" ] && return 0
    sleep 1
  done
  squeue >&2
  fail "jobs still queued after 10 minutes"
}

same_frames() {  # every frame file of $1 is in $2 with the same bytes, and nothing more
  local a=$1 b=$2 n=0
  for f in "$a"/frame_*; do
    cmp -s "$f" "$b/$(basename "$f")" || fail "$(basename "$f") differs between $a and $b"
    n=$((n + 1))
  done
  [ "$n" -eq "$(ls "$b"/frame_* | wc -l)" ] || fail "$b holds other frame files than $a"
  echo "test-slurm: $n frame files of $b equal $a byte for byte"
}

logged_frames() { /usr/bin/python3 -c "import json,sys; print(' '.join(str(f['frame']) for f in json.load(open(sys.argv[1]))['frames']))" "$1"; }

# Absolute paths: the EXR metadata records the scene path as given, and render.py makes it absolute.
scene=("$root/data/cornell/cornell.gltf" --animation "$root/data/cornell/animation.json" --width 64 --height 48 --png --quiet)

echo "== 1. chunked render == sequential render"
"$qsgi" render "${scene[@]}" --photons 100000 --frames 0:11 --gltf-out --usd-out --out "$work/sequential"
scripts/slurm/render.py --out "$work/chunked" --frames 0:11 --chunks 4 --qsgi "$qsgi" -- "${scene[@]}" --photons 100000 --gltf-out --usd-out
wait_for_queue
[ "$(logged_frames "$work/chunked/timing.json")" = "$(seq -s ' ' 0 11)" ] || fail "merged timing.json lists other frames"
same_frames "$work/sequential" "$work/chunked"
# The one-file animation (--gltf-out) is made after the merge from all the frames: the sequential run's bytes.
for asset in asset.glb asset.usda; do
  cmp -s "$work/sequential/$asset" "$work/chunked/$asset" || fail "the merged folder's $asset differs from the sequential run's"
  echo "test-slurm: the merged folder's $asset equals the sequential run's"
done
# Chunks run --frames-only: none writes an asset of its part of the animation.
chunk_assets=$(find "$work/chunked" -mindepth 2 -name 'asset.*')
[ -z "$chunk_assets" ] || fail "a chunk wrote an asset of its own: $chunk_assets"
[ -d "$work/chunked/chunks" ] || fail "no chunks folder in $work/chunked: the check above looked at nothing"
echo "test-slurm: no chunk wrote an asset.glb or asset.usda"

echo "== 2. a killed array task, resubmitted"
"$qsgi" render "${scene[@]}" --photons 400000 --frames 0:17 --out "$work/sequential-big"
killed=(scripts/slurm/render.py --out "$work/killed" --frames 0:17 --chunks 3 --qsgi "$qsgi" -- "${scene[@]}" --photons 400000)
submitted=$("${killed[@]}")
echo "$submitted"
array=$(echo "$submitted" | sed -n 's/.*(array \([0-9]*\)).*/\1/p')
[ -n "$array" ] || fail "no array job id in: $submitted"
# Kill task 1 (frames 6..11) once it has written its first frame, five frames before its last.
for _ in $(seq 3000); do
  [ -e "$work/killed/chunks/001/frame_0006.ply" ] && break
  sleep 0.1
done
[ -e "$work/killed/chunks/001/frame_0006.ply" ] || fail "task 1 never wrote its first frame"
scancel --signal=KILL "${array}_1"
wait_for_queue
[ ! -e "$work/killed/frame_0000.ply" ] || fail "the merge ran although task 1 was killed"
done_before=$(logged_frames "$work/killed/chunks/001/timing.json")
echo "test-slurm: task 1 killed after frames [$done_before] of 6..11"
[ "$done_before" != "6 7 8 9 10 11" ] || fail "task 1 finished before the kill landed; nothing was tested"
resubmitted=$("${killed[@]}")
echo "$resubmitted"
echo "$resubmitted" | grep -q "submitted 1 of 3 chunks" || fail "the resubmission should run chunk 1 alone"
wait_for_queue
[ -z "$(squeue -h -u "$(id -un)")" ] || fail "the first merge job was not replaced: $(squeue -h)"
same_frames "$work/sequential-big" "$work/killed"

echo "== 3. a sweep as a job array"
/usr/bin/python3 scripts/sweep.py tests/data/sweep-tiny.json --out "$work/sweep-local" --qsgi "$qsgi" >/dev/null
/usr/bin/python3 scripts/sweep.py tests/data/sweep-tiny.json --out "$work/sweep-slurm" --qsgi "$qsgi" --slurm
wait_for_queue
[ -s "$work/sweep-slurm/sweep.csv" ] || fail "the merge job wrote no sweep.csv (see $work/sweep-slurm/slurm/)"
# The errors and counts are the same; the timings are the machine's of the moment.
columns='estimator,photons,radius_fraction,family,rms_all,bias_all,rms_near_edge,noise,nan_count,inf_count,segments'
project() { /usr/bin/python3 -c "import csv,sys; [print(*[r[c] for c in sys.argv[2].split(',')]) for r in csv.DictReader(open(sys.argv[1]))]" "$1" "$columns"; }
diff <(project "$work/sweep-local/sweep.csv") <(project "$work/sweep-slurm/sweep.csv") || fail "Slurm sweep rows differ"
again=$(/usr/bin/python3 scripts/sweep.py tests/data/sweep-tiny.json --out "$work/sweep-slurm" --qsgi "$qsgi" --slurm)
echo "$again"
echo "$again" | grep -q "submitted 0 of 11 points" || fail "resubmitting a finished sweep submitted points"
wait_for_queue
echo "test-slurm: all passed"
