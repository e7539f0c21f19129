#!/usr/bin/env bash
# VK-GL-CTS's own `testlog-to-xml` (executor/tools/xeBatchResultToXml.cpp) against the QPA log of
# `umbrage conform`'s dEQP-compatible mode (docs/conform/driver-ci.md, "The QPA log"):
#
#   scripts/testlog-to-xml.sh [--cts DIR] check          build the tool if needed, write a QPA with
#                                                        failures (the seam UMBRAGE_CONFORM_MISMATCH),
#                                                        convert it, compare the XML with the log; and
#                                                        the failure record deqp-runner extracts, when
#                                                        deqp-runner is installed ($DEQP_RUNNER, or
#                                                        scripts/deqp-ci.sh's in .tools/)
#   scripts/testlog-to-xml.sh [--cts DIR] build          only build the tool
#   scripts/testlog-to-xml.sh [--cts DIR] convert LOG.qpa OUT.xml
#
# The tool is built with cmake from four directories of VK-GL-CTS at the pinned commit $CTS_COMMIT
# (executor/, execserver/, framework/delibs/, framework/xexml/: no external dependency, about
# 30 s on 2 cores) into $UMBRAGE_TOOLS_DIR (default .tools/)/testlog-to-xml-<commit>/, skipped when
# present. The source: --cts DIR (or $VK_GL_CTS_DIR), a VK-GL-CTS checkout or a git clone of it
# (bare or not) that has the commit; without either, a sparse clone from GitHub. Needs git, cmake
# and a C/C++ compiler. Not part of `make test` (it needs VK-GL-CTS's source, which CI cannot fetch).
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$REPO"
CTS_COMMIT=c57d29f97dbd51e6ff57e9eb1a98808e66afa0d3
CTS_URL=https://github.com/KhronosGroup/VK-GL-CTS
PARTS=(executor execserver framework/delibs framework/xexml)
TOOLS="${UMBRAGE_TOOLS_DIR:-$REPO/.tools}"
case "$TOOLS" in /*) ;; *) TOOLS="$PWD/$TOOLS" ;; esac
HOME_DIR="$TOOLS/testlog-to-xml-${CTS_COMMIT:0:12}"
TOOL="$HOME_DIR/bin/testlog-to-xml"
CTS="${VK_GL_CTS_DIR:-}"
fail() { echo "testlog-to-xml: FAIL: $*" >&2; exit 1; }
usage() { sed -n '2,/^set -e/p' "$0" | sed '$d;s/^# \{0,1\}//'; }

while [ $# -gt 0 ]; do
  case "$1" in
    --cts) CTS="$2"; shift ;;
    -h|--help) usage; exit 0 ;;
    *) break ;;
  esac
  shift
done
[ $# -gt 0 ] || { usage >&2; exit 2; }

# The four directories, at $CTS_COMMIT, into $1.
fetch_source() {
  local dest="$1"
  mkdir -p "$dest"
  if [ -n "$CTS" ] && git -C "$CTS" cat-file -e "$CTS_COMMIT^{commit}" 2>/dev/null; then
    git -C "$CTS" archive "$CTS_COMMIT" "${PARTS[@]}" | tar -x -C "$dest"
  elif [ -n "$CTS" ] && [ -f "$CTS/executor/CMakeLists.txt" ]; then
    echo "testlog-to-xml: $CTS is not a git clone with $CTS_COMMIT: building from its files as they are" >&2
    for p in "${PARTS[@]}"; do mkdir -p "$dest/$(dirname "$p")" && cp -R "$CTS/$p" "$dest/$p"; done
  elif [ -n "$CTS" ]; then
    fail "$CTS is neither a VK-GL-CTS checkout nor a git clone with commit $CTS_COMMIT"
  else
    echo "testlog-to-xml: fetching ${PARTS[*]} of VK-GL-CTS $CTS_COMMIT from $CTS_URL (sparse)"
    local clone="$dest.git"
    rm -rf "$clone"
    git clone --quiet --filter=blob:none --no-checkout "$CTS_URL" "$clone" ||
      fail "cannot clone $CTS_URL: pass --cts DIR (a VK-GL-CTS clone with $CTS_COMMIT)"
    git -C "$clone" sparse-checkout set "${PARTS[@]}"
    git -C "$clone" checkout --quiet "$CTS_COMMIT"
    for p in "${PARTS[@]}"; do mkdir -p "$dest/$(dirname "$p")" && cp -R "$clone/$p" "$dest/$p"; done
    rm -rf "$clone"
  fi
}

# The project that builds only the tool: delibs' own cmake definitions, the libraries the
# executor links (debase, depool, dethread, destream, deutil, decpp, xexml, xscore) and
# the executor's targets, of which only testlog-to-xml is built.
write_project() {
  cat > "$1/CMakeLists.txt" <<'EOF'
cmake_minimum_required(VERSION 3.13)
project(umbrage-testlog-to-xml C CXX)
set(CTS "${CMAKE_CURRENT_SOURCE_DIR}/src")
include(${CTS}/framework/delibs/cmake/Defs.cmake NO_POLICY_SCOPE)
include(${CTS}/framework/delibs/cmake/CFlags.cmake)
add_definitions(-DDE_ASSERT_FAILURE_CALLBACK)
# The CTS top level's precompiled-header helper is for MSVC only: nothing to do here.
macro (PCH SRCS PCHCPP)
endmacro ()
set(DELIBS debase depool dethread destream deutil decpp)
foreach (lib ${DELIBS})
	include_directories(${CTS}/framework/delibs/${lib})
endforeach ()
foreach (lib ${DELIBS})
	add_subdirectory(${CTS}/framework/delibs/${lib} ${lib})
endforeach ()
add_subdirectory(${CTS}/framework/xexml xexml)
add_subdirectory(${CTS}/execserver execserver)
add_subdirectory(${CTS}/executor executor)
EOF
}

build() {
  [ -x "$TOOL" ] && return 0
  command -v cmake >/dev/null || fail "cmake not found (apt-get install cmake)"
  local stage="$HOME_DIR.tmp"
  rm -rf "$stage"
  fetch_source "$stage/src"
  write_project "$stage"
  cmake -S "$stage" -B "$stage/build" -DCMAKE_BUILD_TYPE=Release >"$stage/cmake.log" 2>&1 ||
    { tail -20 "$stage/cmake.log" >&2; fail "cmake configure (log: $stage/cmake.log)"; }
  cmake --build "$stage/build" --target testlog-to-xml -j "$(nproc)" >"$stage/build.log" 2>&1 ||
    { tail -20 "$stage/build.log" >&2; fail "build (log: $stage/build.log)"; }
  mkdir -p "$stage/bin"
  cp "$stage/build/executor/testlog-to-xml" "$stage/bin/"
  rm -rf "$stage/build" "$stage/src" "$HOME_DIR"
  mv "$stage" "$HOME_DIR"
  echo "testlog-to-xml: built $TOOL"
}

# `grep -c` that prints 0 (and succeeds) when nothing matches.
count() { grep -c -- "$1" "$2" || true; }

check() {
  build
  local out="${TESTLOG_OUT:-$REPO/target/testlog-to-xml}"
  rm -rf "$out" && mkdir -p "$out"
  local umbrage
  umbrage=$("$REPO/scripts/umbrage-bin.sh")
  # Two failures with images (a drawn case failing on depth alone, the float count), a pass.
  local depth=umbrage.depth.d32s8.dynamic_rendering.static_state.infinity.forward.dir_0.comp_less
  local cases="$depth,umbrage.legacy.deep_wrap_float_count,umbrage.legacy.depth_clamp"
  (cd "$out" && UMBRAGE_VALIDATION="${UMBRAGE_VALIDATION-1}" \
    UMBRAGE_CONFORM_MISMATCH="${depth#umbrage.},deep_wrap_float_count" \
    "$umbrage" conform --deqp-case="$cases" --deqp-log-filename="$out/run.qpa" >"$out/run.log")
  "$TOOL" "$out/run.qpa" "$out/run.xml" >"$out/convert.log" 2>&1 ||
    { cat "$out/convert.log" >&2; fail "testlog-to-xml rejected $out/run.qpa"; }
  local qpa_cases xml_cases qpa_images xml_images
  qpa_cases=$(count '^#beginTestCaseResult ' "$out/run.qpa")
  xml_cases=$(count '<TestCaseResult ' "$out/run.xml")
  qpa_images=$(count '<Image ' "$out/run.qpa")
  xml_images=$(count '<Image ' "$out/run.xml")
  [ "$qpa_cases" = 3 ] || fail "the log holds $qpa_cases records, not 3"
  [ "$xml_cases" = "$qpa_cases" ] || fail "$xml_cases of the log's $qpa_cases cases converted"
  [ "$qpa_images" -ge 12 ] || fail "the log's failures hold $qpa_images images (at least 12 expected)"
  [ "$xml_images" = "$qpa_images" ] || fail "$xml_images of the log's $qpa_images images converted"
  grep -q '<ResultTotals Pass="1" Fail="2" ' "$out/run.xml" || fail "the totals are not 1 Pass, 2 Fail: $(grep ResultTotals "$out/run.xml")"
  grep -q "CasePath=\"$depth\"" "$out/run.xml" || fail "no CasePath $depth"
  grep -q '<Image Name="diff_depth" ' "$out/run.xml" || fail "the depth failure's diff_depth image is missing"
  echo "testlog-to-xml: $qpa_cases cases (1 Pass, 2 Fail) and $xml_images failure images of umbrage's QPA converted ($out/run.xml)"
  # The record deqp-runner extracts for a failure (NAME.qpa in its output), when it is installed
  # (scripts/deqp-ci.sh --install-only).
  local runner="${DEQP_RUNNER:-$TOOLS/deqp-runner-${DEQP_RUNNER_VERSION:-0.20.3}/bin/deqp-runner}"
  if [ ! -x "$runner" ]; then
    echo "testlog-to-xml: no deqp-runner at $runner: its extracted failure record not converted"
    return 0
  fi
  local float=umbrage.legacy.deep_wrap_float_count
  printf '%s\n' "$float" umbrage.legacy.depth_clamp > "$out/list.txt"
  (UMBRAGE_VALIDATION="${UMBRAGE_VALIDATION-1}" UMBRAGE_CONFORM_MISMATCH=deep_wrap_float_count PATH="$REPO/target/debug:$PATH" \
    "$runner" run --deqp /usr/bin/env --caselist "$out/list.txt" --output "$out/runner" -- umbrage conform) >"$out/runner.log" 2>&1 &&
    fail "deqp-runner passed a run with a forced failure"
  [ "$(cat "$out/runner/failures.csv")" = "$float,Fail" ] || fail "deqp-runner's failures.csv: $(head -3 "$out/runner/failures.csv")"
  "$TOOL" "$out/runner/$float.qpa" "$out/runner.xml" >"$out/convert.log" 2>&1 ||
    { cat "$out/convert.log" >&2; fail "testlog-to-xml rejected deqp-runner's $float.qpa"; }
  grep -q '<ResultTotals Pass="0" Fail="1" ' "$out/runner.xml" || fail "deqp-runner's record: not 1 Fail"
  xml_images=$(count '<Image ' "$out/runner.xml")
  [ "$xml_images" = "$(count '<Image ' "$out/runner/$float.qpa")" ] && [ "$xml_images" -gt 0 ] ||
    fail "deqp-runner's record: $xml_images images converted"
  echo "testlog-to-xml: deqp-runner's extracted $float.qpa converted (1 Fail, $xml_images images)"
}

case "$1" in
  build) build ;;
  check) check ;;
  convert)
    [ $# = 3 ] || { usage >&2; exit 2; }
    build
    "$TOOL" "$2" "$3" ;;
  *) usage >&2; exit 2 ;;
esac
