#!/usr/bin/env bash
# Installs what umbrage needs to build and run on a fresh Debian/Ubuntu machine, and nothing
# that is already there: the Vulkan loader, Mesa's lavapipe (a CPU Vulkan driver), the
# Khronos validation layers and spirv-tools (spirv-val, used by the tests), and for the
# `umbrage view` tests a virtual X server (xvfb, xauth for xvfb-run) and xdotool (synthetic
# input), and the X11 libraries winit loads at run time. Rust via rustup only when cargo is
# missing.
#
#   scripts/deps.sh            what `make run` needs
#   scripts/deps.sh --tests    what `make test` needs (the same install on Debian)
#
# Off Debian (no apt-get) it installs nothing from a package manager: it checks that what is
# needed is already there (the Vulkan loader libvulkan.so.1, a driver ICD JSON, and with
# --tests the Khronos validation layer's JSON), prints what it found and exits 0, or names
# each missing piece with how to get it and exits 1. spirv-val, xvfb-run and xdotool are
# reported but optional there (the tests that use them skip loudly; with CI set they are
# required). DEPS_ASSUME_NO_APT=1 takes that path on a Debian machine too (to test it).
set -euo pipefail

tests=0
case "${1:-}" in
  --tests) tests=1 ;;
  "") ;;
  *) echo "usage: $0 [--tests]" >&2; exit 2 ;;
esac

# --- Off Debian: check, do not install ------------------------------------------------------

# The first libvulkan.so.1 the dynamic loader knows (ldconfig's cache), else in a common lib dir.
find_loader() {
  local ldc d
  ldc="$(command -v ldconfig || true)"
  [ -z "$ldc" ] && [ -x /sbin/ldconfig ] && ldc=/sbin/ldconfig
  if [ -n "$ldc" ]; then
    d="$("$ldc" -p 2>/dev/null | grep -m1 'libvulkan\.so\.1 ' | sed 's/.*=> //')" || true
    [ -n "$d" ] && { echo "$d"; return 0; }
  fi
  local IFS=:
  for d in ${LD_LIBRARY_PATH:-} /usr/lib /usr/lib64 /usr/local/lib /usr/local/lib64 /lib /lib64 \
    /usr/lib/x86_64-linux-gnu /usr/lib/aarch64-linux-gnu; do
    [ -n "$d" ] && [ -e "$d/libvulkan.so.1" ] && { echo "$d/libvulkan.so.1"; return 0; }
  done
  return 1
}

# Vulkan's search dirs for a manifest kind (icd.d, explicit_layer.d).
vk_dirs() {
  local kind=$1
  echo "/usr/share/vulkan/$kind /etc/vulkan/$kind /usr/local/share/vulkan/$kind ${HOME:-/nonexistent}/.local/share/vulkan/$kind"
}

# Driver ICDs: VK_ICD_FILENAMES / VK_DRIVER_FILES when set, else every *.json in icd.d.
find_icds() {
  local v="${VK_DRIVER_FILES:-${VK_ICD_FILENAMES:-}}"
  if [ -n "$v" ]; then echo "$v (VK_DRIVER_FILES / VK_ICD_FILENAMES)"; return 0; fi
  local d f found=1
  for d in $(vk_dirs icd.d); do
    for f in "$d"/*.json; do [ -e "$f" ] && { echo "$f"; found=0; }; done
  done
  return $found
}

# The Khronos validation layer's manifest (VK_LAYER_PATH / VK_ADD_LAYER_PATH first).
find_validation() {
  local d f IFS=' :'
  for d in ${VK_LAYER_PATH:-} ${VK_ADD_LAYER_PATH:-} $(vk_dirs explicit_layer.d); do
    for f in "$d"/VkLayer_khronos_validation.json "$d"/*validation*.json; do
      [ -e "$f" ] && { echo "$f"; return 0; }
    done
  done
  return 1
}

check_present() {
  local missing=() optional=() found
  echo "deps: no apt-get here; checking what is installed (nothing is installed by this script)"
  if found="$(find_loader)"; then echo "deps: Vulkan loader: $found"; else
    missing+=("the Vulkan loader libvulkan.so.1 (Fedora: vulkan-loader, Arch: vulkan-icd-loader, Alpine: vulkan-loader)")
  fi
  if found="$(find_icds)"; then echo "deps: Vulkan driver ICD: ${found//$'\n'/ }"; else
    missing+=("a Vulkan driver ICD (no *.json in $(vk_dirs icd.d | sed 's/ /, /g'), VK_DRIVER_FILES / VK_ICD_FILENAMES unset): your GPU's Vulkan driver, or Mesa's lavapipe on the CPU (Fedora: mesa-vulkan-drivers, Arch: vulkan-swrast, Alpine: mesa-vulkan-swrast)")
  fi
  if found="$(find_validation)"; then echo "deps: validation layer: $found"; else
    local v="the Khronos validation layer (VkLayer_khronos_validation.json in explicit_layer.d; package vulkan-validation-layers on Fedora, Arch and Alpine, or the LunarG Vulkan SDK)"
    if [ $tests = 1 ]; then missing+=("$v"); else optional+=("$v: needed by make test and UMBRAGE_VALIDATION=1"); fi
  fi
  if ! command -v cc >/dev/null 2>&1; then missing+=("a C toolchain (cc, for linking: gcc or clang)"); fi
  if ! command -v cargo >/dev/null 2>&1 && [ ! -x "${HOME:-}/.cargo/bin/cargo" ] && ! command -v curl >/dev/null 2>&1; then
    missing+=("Rust (cargo), or curl to install it with rustup")
  fi
  if [ $tests = 1 ]; then
    local t tool
    for t in spirv-val:spirv-tools xvfb-run:"Xvfb's xvfb-run" xdotool:xdotool; do
      tool=${t%%:*}
      command -v "$tool" >/dev/null 2>&1 && continue
      if [ -n "${CI:-}" ]; then missing+=("$tool (${t#*:}; required under CI)"); else
        optional+=("$tool (${t#*:}): the tests that use it are skipped")
      fi
    done
  fi
  for o in "${optional[@]+"${optional[@]}"}"; do echo "deps: optional, not found: $o"; done
  if [ ${#missing[@]} -gt 0 ]; then
    for m in "${missing[@]}"; do echo "deps: missing: $m" >&2; done
    echo "deps: install the above with your package manager, then run this again" >&2
    exit 1
  fi
  echo "deps: everything needed is present"
}

if [ "${DEPS_ASSUME_NO_APT:-}" = 1 ] || ! command -v apt-get >/dev/null 2>&1; then
  check_present
else
  # --- Debian/Ubuntu: install what is missing ----------------------------------------------
  need=()
  have_pkg() { dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q "install ok installed"; }
  for p in libvulkan1 mesa-vulkan-drivers vulkan-validationlayers spirv-tools \
    xvfb xauth xdotool libxkbcommon-x11-0 libxcursor1 libxrandr2 libxi6 libx11-xcb1; do
    have_pkg "$p" || need+=("$p")
  done
  # make test's C ABI checks: the Vulkan headers the C hosts include, clang beside gcc for the
  # header's language-standard matrix, pkg-config for the installed umbrage.pc, valgrind.
  if [ $tests = 1 ]; then
    for p in libvulkan-dev clang pkg-config valgrind; do have_pkg "$p" || need+=("$p"); done
  fi
  if ! command -v cc >/dev/null 2>&1 || ! command -v c++ >/dev/null 2>&1; then need+=(build-essential); fi  # meshopt builds C++
  if ! command -v curl >/dev/null 2>&1 && ! command -v cargo >/dev/null 2>&1; then need+=(curl ca-certificates); fi

  if [ ${#need[@]} -gt 0 ]; then
    SUDO=""
    if [ "$(id -u)" != 0 ]; then
      if command -v sudo >/dev/null 2>&1; then SUDO=sudo; else
        echo "deps: need root (or sudo) to apt-get install ${need[*]}" >&2; exit 1
      fi
    fi
    echo "deps: installing ${need[*]}"
    $SUDO env DEBIAN_FRONTEND=noninteractive apt-get update -qq
    $SUDO env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${need[@]}" >/dev/null
  fi
fi

if ! command -v cargo >/dev/null 2>&1; then
  if [ -x "$HOME/.cargo/bin/cargo" ]; then
    echo "deps: cargo is in ~/.cargo/bin; add it to PATH (source ~/.cargo/env)" >&2
  else
    echo "deps: installing Rust with rustup"
    curl --proto '=https' --tlsv1.2 -sSf https://sh.rustup.rs | sh -s -- -y --profile minimal
  fi
fi

# `make test` runs rustfmt and clippy (make lint): add them where rustup installed a minimal
# toolchain without them.
if command -v rustup >/dev/null 2>&1 || [ -x "${HOME:-}/.cargo/bin/rustup" ]; then
  rustup_bin=$(command -v rustup || echo "$HOME/.cargo/bin/rustup")
  for c in clippy rustfmt; do
    if ! "$rustup_bin" component list --installed 2>/dev/null | grep -q "^$c"; then
      echo "deps: adding the $c component"
      "$rustup_bin" component add "$c" >/dev/null
    fi
  done
fi
