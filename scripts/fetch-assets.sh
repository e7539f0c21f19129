#!/usr/bin/env bash
# Test assets that cannot live in this repository (their licences differ from umbrage's):
# buildings.obj (the OpenFOAM "windAroundBuildings" city block, 400k triangles in 26 parts with
# a few non-manifold and misoriented edges; GPL-3+) from Debian's openfoam-examples package,
# extracted into target/assets/. Best effort on a developer's machine: without network or apt the
# tests that use it say so and run their synthetic stand-ins. Under CI (CI set) it is required:
# a failed download fails the run, and so does a test that finds the asset missing.
set -euo pipefail
cd "$(dirname "$0")/.."
out=target/assets/buildings.obj
[ -f "$out" ] && exit 0
mkdir -p target/assets
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
if (cd "$tmp" && apt-get download openfoam-examples >/dev/null 2>&1); then
  dpkg -x "$tmp"/openfoam-examples_*.deb "$tmp/x"
  gz=$(find "$tmp/x" -name buildings.obj.gz | head -1)
  gunzip -c "$gz" > "$out"
  echo "fetch-assets: $out ($(wc -c < "$out") bytes, openfoam-examples, GPL-3+)"
else
  echo "fetch-assets: could not download openfoam-examples (no network or apt); skipping" >&2
  [ -z "${CI:-}" ] || { echo "fetch-assets: required under CI" >&2; exit 1; }
fi
