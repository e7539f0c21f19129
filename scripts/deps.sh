#!/usr/bin/env bash
# Installs what umbrage needs to build and run on a fresh Debian/Ubuntu machine, and nothing
# that is already there: the Vulkan loader, Mesa's lavapipe (a CPU Vulkan driver), the
# Khronos validation layers and spirv-tools (spirv-val, used by the tests), and for the
# `umbrage view` tests a virtual X server (xvfb, xauth for xvfb-run) and xdotool (synthetic
# input), and the X11 libraries winit loads at run time. Rust via rustup only when cargo is
# missing.
set -euo pipefail

need=()
have_pkg() { dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q "install ok installed"; }
for p in libvulkan1 mesa-vulkan-drivers vulkan-validationlayers spirv-tools \
  xvfb xauth xdotool libxkbcommon-x11-0 libxcursor1 libxrandr2 libxi6; do
  have_pkg "$p" || need+=("$p")
done
if ! command -v cc >/dev/null 2>&1; then need+=(build-essential); fi
if ! command -v curl >/dev/null 2>&1 && ! command -v cargo >/dev/null 2>&1; then need+=(curl ca-certificates); fi

if [ ${#need[@]} -gt 0 ]; then
  if ! command -v apt-get >/dev/null 2>&1; then
    echo "deps: missing ${need[*]} and no apt-get here; install them with your package manager" >&2
    exit 1
  fi
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

if ! command -v cargo >/dev/null 2>&1; then
  if [ -x "$HOME/.cargo/bin/cargo" ]; then
    echo "deps: cargo is in ~/.cargo/bin; add it to PATH (source ~/.cargo/env)" >&2
  else
    echo "deps: installing Rust with rustup"
    curl --proto '=https' --tlsv1.2 -sSf https://sh.rustup.rs | sh -s -- -y --profile minimal
  fi
fi
