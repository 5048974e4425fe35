#!/usr/bin/env bash
# Proves that scripts/run.sh works on a bare Debian 12: makes a fresh root with mmdebstrap
# (--variant=apt: apt and what it needs, nothing else), copies this checkout's tracked files into it,
# runs scripts/run.sh there on a tiny render (it installs its own packages, builds and renders) and
# checks the frames it wrote. A build or run dependency missing from scripts/setup.sh's run set makes
# it fail. .ci/run calls it before the test command.
#
# mmdebstrap mounts /dev, /proc and /sys in the root, unmounts them and removes the root itself (the
# target is /dev/null); nothing here mounts, unmounts or deletes into the root. The root gets the
# host's apt sources for Debian 12 (the host's mirror, not mmdebstrap's default) and the host's
# locally added CA certificates (for a mirror or proxy over TLS).
#
# Usage: scripts/test-fresh-root.sh
# Needs root (mmdebstrap's root mode) and installs mmdebstrap when it is missing.
set -euo pipefail
cd "$(dirname "$0")/.."

if [ "$(id -u)" -ne 0 ]; then
  echo "test-fresh-root: needs root (mmdebstrap's root mode mounts /dev and /proc in the root)" >&2
  exit 2
fi
if ! command -v mmdebstrap >/dev/null 2>&1; then
  echo "test-fresh-root: installing mmdebstrap"
  DEBIAN_FRONTEND=noninteractive apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends mmdebstrap >/dev/null
fi

# The host's enabled sources of Debian 12 itself (bookworm, -updates, -security, signed by Debian's
# keyring), each file as one mirror argument (mmdebstrap takes a file's contents, one-line or deb822).
# Third-party sources that also name bookworm (Docker's, NodeSource's) stay out: their keyrings are
# not in the root, and apt-get update there would fail on them.
sources=()
for f in /etc/apt/sources.list /etc/apt/sources.list.d/*.list /etc/apt/sources.list.d/*.sources; do
  [ -f "$f" ] || continue
  active="$(grep -v '^\s*#' "$f")"
  grep -q 'bookworm' <<<"$active" || continue
  grep -qiE '^Enabled:\s*no' <<<"$active" && continue
  grep -E '^(deb|URIs:)' <<<"$active" | grep -vE 'deb\.debian\.org|security\.debian\.org|snapshot\.debian\.org|ftp\.[a-z.]*debian\.org' | grep -q . && continue
  sources+=("$f")
done
if [ ${#sources[@]} -eq 0 ]; then
  echo "test-fresh-root: no apt source for Debian 12 (bookworm) in /etc/apt; mmdebstrap's default mirror is used" >&2
fi

# Scratch space of this script's own: the checkout's tracked files as a tarball, and the frames
# copied out of the root for checking. No mount is ever under it.
work="$(mktemp -d /tmp/qsgi-fresh-root.XXXXXX)"  # no spaces: the hooks below name it unquoted
trap 'rm -rf -- "$work"' EXIT
# The tracked files as they stand in the checkout (uncommitted edits included; a tracked file deleted
# in the work tree is left out).
git ls-files -z | tar --null --ignore-failed-read -T - -cf "$work/qsgi.tar" 2>/dev/null
mkdir "$work/ca"
cp /usr/local/share/ca-certificates/*.crt "$work/ca/" 2>/dev/null || true

# Inside the root: scripts/run.sh, as a new user would run it, on two frames of data/cornell. Its
# output (apt's and the compiler's) goes to a log that is copied out; its end is shown on failure.
render=(scripts/run.sh --frames 0:1 --photons 20000 --out /root/out)
inner="cd /root/qsgi && start=\$(date +%s) && { ${render[*]@Q} > /root/run.log 2>&1 || { tail -n 60 /root/run.log; exit 1; }; } \
  && echo \$(( \$(date +%s) - start )) > /root/run-seconds"

start=$(date +%s)
mmdebstrap --variant=apt --include=ca-certificates --quiet \
  --customize-hook='mkdir -p "$1/root/qsgi"' \
  --customize-hook="tar-in $work/qsgi.tar /root/qsgi" \
  --customize-hook="copy-in $work/ca /usr/local/share/ca-certificates" \
  --customize-hook='chroot "$1" update-ca-certificates >/dev/null 2>&1' \
  --customize-hook="chroot \"\$1\" bash -c ${inner@Q}" \
  --customize-hook="copy-out /root/out /root/run.log /root/run-seconds $work" \
  bookworm /dev/null "${sources[@]}"
seconds=$(( $(date +%s) - start ))

out="$work/out"
for f in frame_0000.ply frame_0001.ply frame_0000.exr frame_0001.exr frame_0000.png frame_0001.png timing.json; do
  if [ ! -s "$out/$f" ]; then
    echo "test-fresh-root: the render in the fresh root did not write $f" >&2
    exit 1
  fi
done
frames=$(grep -c '"frame":' "$out/timing.json" || true)
if [ "$frames" != 2 ]; then
  echo "test-fresh-root: timing.json lists $frames frames, not 2" >&2
  exit 1
fi
packages=$(grep -c '^Setting up ' "$work/run.log" || true)
echo "test-fresh-root: in a fresh Debian 12 root, scripts/run.sh installed $packages packages, built qsgi and rendered" \
     "2 frames in $(cat "$work/run-seconds") s; the whole stage (root, install, build, render) took ${seconds} s"
