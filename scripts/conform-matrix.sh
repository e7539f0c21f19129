#!/usr/bin/env bash
# The conformance driver matrix: `umbrage conform` (validation on, every unit crash-isolated in
# its own child process) on each Mesa lavapipe scripts/drivers.sh installs, and with llvmpipe
# switches that change its code paths, then `umbrage conform-matrix` side by side.
#
#   scripts/conform-matrix.sh            the full suite per column -> docs/conform/drivers.md
#   scripts/conform-matrix.sh --quick    one configuration per family on the four drivers, each
#                                        judged against docs/conform/expectations/lavapipe-V.txt
#                                        (SwiftShader: expectations/swiftshader.txt)
#                                        (Mesa CI style: a new failure, a new skip or an unexpected pass fails)
#
# Reports go to target/conform-matrix/<column>/ (conform.json, conform.md, junit.xml).
set -euo pipefail
cd "$(dirname "$0")/.."
export PATH="$HOME/.cargo/bin:$PATH"

quick=0
[ "${1:-}" = "--quick" ] && quick=1
out=target/conform-matrix
exp=docs/conform/expectations
./scripts/drivers.sh install 20.3.5 22.3.6 25.0.7 swiftshader
bin=$(./scripts/umbrage-bin.sh)
export UMBRAGE_VALIDATION=1

# The quick filter: the configuration every driver runs (Vulkan 1.0 render pass, static state),
# the Vulkan 1.3 one (dynamic rendering, dynamic state), the legacy, command and mesh-shader
# checks (skipped as unsupported without VK_EXT_mesh_shader) and the whole pipeline with
# McGuire's method on every hard scene.
QUICK='*.d24s8.render_pass.static_state.*,*.d32s8.dynamic_rendering.dynamic_state.*,legacy.*,commands.*,mesh.*,pipeline.hard_cases.*.mcguire'

# run NAME VERSION [VAR=VALUE...]: one column.
run() {
  local name=$1 version=$2
  shift 2
  local dir="$out/${name// /_}"
  dir="${dir//=/-}" # conform-matrix reads NAME=DIR: no '=' in DIR
  rm -rf "$dir"
  local args=(conform --out "$dir" --junit "$dir/junit.xml")
  local expect="$exp/lavapipe-$version.txt"
  [ "$version" != swiftshader ] || expect="$exp/swiftshader.txt"
  if [ $quick = 1 ]; then args+=(--filter "$QUICK" --expect "$expect"); fi
  echo "== $name"
  local rc=0
  (eval "$(./scripts/drivers.sh env "$version")" && env "$@" "$bin" "${args[@]}") 2>&1 |
    grep -v '^WARNING: lavapipe is not a conformant' | grep -E '^(PASS|FAIL|NEW|UNEXPECTED|expectations|llvmpipe|SwiftShader)' || true
  # The pipeline above hides the exit status; the report says what happened.
  if [ $quick = 1 ]; then
    # failures, passes and skips, each as listed (`ok` says all three)
    if ! grep -q '"ok": true' "$dir/conform-expect.json" 2>/dev/null; then
      rc=1
    fi
  fi
  columns+=(--column "$name=$dir")
  if [ $quick = 1 ]; then drive "$version" "$dir" || rc=1; fi
  return $rc
}

# drive VERSION DIR: `umbrage info` works on the driver, and `umbrage render` of the default
# scene matches the CPU reference (`umbrage check` on its dump) where the driver has Vulkan 1.3,
# or fails with an error naming what is missing where it does not.
drive() {
  local version=$1 dir=$2 log="$2/render.log"
  (eval "$(./scripts/drivers.sh env "$version")" && "$bin" info >"$dir/info.txt" 2>&1) ||
    { echo "FAIL: umbrage info on $version"; cat "$dir/info.txt"; return 1; }
  if (eval "$(./scripts/drivers.sh env "$version")" &&
    "$bin" render --size 160x120 --out "$dir/render.png" --dump "$dir/dump") >"$log" 2>&1; then
    if "$bin" check "$dir/dump" >>"$log" 2>&1; then
      echo "render on $version: matches the reference"
    else
      echo "FAIL: render on $version does not match the reference"; tail -5 "$log"; return 1
    fi
  elif grep -q 'dynamicRendering and synchronization2 (Vulkan 1.3)' "$log" && ! grep -q panicked "$log"; then
    echo "render on $version: refused with a clear error: $(grep -o 'unsupported on this device: [^;]*' "$log")"
  else
    echo "FAIL: render on $version failed without the expected error"; tail -5 "$log"; return 1
  fi
}

columns=()
status=0
run 20.3.5 20.3.5 || status=1
run 22.3.6 22.3.6 || status=1
run 25.0.7 25.0.7 || status=1
run swiftshader swiftshader || status=1
if [ $quick = 0 ]; then
  # llvmpipe's own switches (docs/conform/mesa-ci-notes.md): the JIT's SIMD width, the
  # rasteriser's debug path (read by release builds since Mesa 24), and draw's C clipper.
  run "22.3.6 LP_NATIVE_VECTOR_WIDTH=128" 22.3.6 LP_NATIVE_VECTOR_WIDTH=128 || true
  run "25.0.7 LP_NATIVE_VECTOR_WIDTH=128" 25.0.7 LP_NATIVE_VECTOR_WIDTH=128 || true
  run "25.0.7 LP_DEBUG=no_fastpath" 25.0.7 LP_DEBUG=no_fastpath || true
  run "25.0.7 DRAW_USE_LLVM=0" 25.0.7 DRAW_USE_LLVM=0 || true
  "$bin" conform-matrix "${columns[@]}" --notes docs/conform/drivers-notes.md --out docs/conform/drivers.md
  echo "wrote docs/conform/drivers.md"
else
  "$bin" conform-matrix "${columns[@]}" --out "$out/drivers-quick.md"
  [ $status = 0 ] && echo "quick matrix: every driver matched its expectations" || echo "quick matrix: FAILED (see above)"
fi
exit $status
