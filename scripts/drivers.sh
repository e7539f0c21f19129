#!/usr/bin/env bash
# Extra CPU Vulkan drivers beside the system's, in a project-local cache: Mesa lavapipe versions
# and Google's SwiftShader (the recipe measured in the design notes, "Three lavapipes on one
# machine" and "SwiftShader, the fourth driver").
#
#   scripts/drivers.sh install VERSION...|all   fetch + extract into $UMBRAGE_DRIVERS_DIR/VERSION
#   scripts/drivers.sh env VERSION              export lines: eval "$(scripts/drivers.sh env 25.0.7)"
#   scripts/drivers.sh list | path VERSION | check VERSION | --help
#
# VERSION is 20.3.5 (Debian 11 bullseye, Vulkan 1.0), 22.3.6 (Debian 12 bookworm, Vulkan 1.3),
# 25.0.7 (bookworm-backports, Vulkan 1.4) or swiftshader (SwiftShader from bookworm's
# chromium-common, Vulkan 1.3; its package version moves with security updates and is recorded
# in packages.txt, which `list` prints). The packages come from the Debian mirror the machine's
# own apt sources name, through a private, throw-away apt state (its own sources list, lists and
# cache): nothing is installed system-wide and the machine's apt setup is never touched. Each
# version is staged in a temp dir and renamed into place with a stamp, so an interrupted run
# leaves no half cache and a second `install` is a no-op.
set -euo pipefail

REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
DRIVERS_DIR="${UMBRAGE_DRIVERS_DIR:-$REPO/.drivers}"
case "$DRIVERS_DIR" in /*) ;; *) DRIVERS_DIR="$PWD/$DRIVERS_DIR" ;; esac # ICD JSONs need it absolute
VERSIONS=(20.3.5 22.3.6 25.0.7 swiftshader)
STAMP=.installed # written last, inside the staging dir, before the atomic rename

usage() {
  sed -n '2,14s/^# \{0,1\}//p' "$0"
  echo "cache: $DRIVERS_DIR (set UMBRAGE_DRIVERS_DIR to move it)"
}
die() { echo "drivers: $*" >&2; exit 1; }
usage_error() { echo "drivers: $*" >&2; echo "run '$0 --help' for usage" >&2; exit 2; }

# What each version needs: the Debian suites to search, and the packages to extract beside
# mesa-vulkan-drivers (each at its newest version in those suites), and the Vulkan version its
# lavapipe reports (for `check`). Mesa itself is pinned by the upstream version prefix
# ("25.0.7-*") and the newest matching Debian revision wins.
spec() {
  case "$1" in
    20.3.5) SUITES="bullseye bullseye-updates bullseye-security"; EXTRA="libllvm11 libffi7"; API=1.0 ;;
    # libllvm15 is the system's own on bookworm; cached too so the version works without it.
    22.3.6) SUITES="bookworm bookworm-updates bookworm-security"; EXTRA="libllvm15"; API=1.3 ;;
    25.0.7) SUITES="bookworm bookworm-backports"; EXTRA="libdrm2 libdrm-amdgpu1 libllvm15"; API=1.4 ;;
    # Only libvk_swiftshader.so and its ICD JSON are kept from chromium-common (the rest of
    # Chromium is deleted after extraction); the library needs only libc, libm and libgcc_s.
    swiftshader) SUITES="bookworm bookworm-updates bookworm-security"; EXTRA=""; API=1.3 ;;
    *) usage_error "unknown version '$1' (known: ${VERSIONS[*]})" ;;
  esac
}
installed() { [ -f "$DRIVERS_DIR/$1/$STAMP" ]; }
need_installed() { spec "$1"; installed "$1" || die "$(label "$1") is not installed; run: scripts/drivers.sh install $1"; }
label() { if [ "$1" = swiftshader ]; then echo SwiftShader; else echo "lavapipe $1"; fi; }

# The Debian archive and security URIs the machine's apt sources already use (one-line .list
# and deb822 .sources files); deb.debian.org only when none can be read. UMBRAGE_DEBIAN_MIRROR /
# UMBRAGE_DEBIAN_SECURITY_MIRROR override them (e.g. archive.debian.org once bullseye moves there).
system_uris() {
  local f
  for f in /etc/apt/sources.list /etc/apt/sources.list.d/*.list; do
    [ -r "$f" ] && awk '$1 == "deb" { for (i = 2; i <= NF; i++) if ($i ~ /^[a-z+]+:\/\//) { print $i; break } }' "$f"
  done
  for f in /etc/apt/sources.list.d/*.sources; do
    [ -r "$f" ] && awk 'tolower($1) == "uris:" { for (i = 2; i <= NF; i++) print $i }' "$f"
  done
  return 0
}
pick_mirrors() {
  local uris
  uris="$(system_uris)"
  MIRROR="${UMBRAGE_DEBIAN_MIRROR:-$(awk '/\/debian\/?$/ { sub(/\/$/, ""); print; exit }' <<<"$uris")}"
  SECURITY="${UMBRAGE_DEBIAN_SECURITY_MIRROR:-$(awk '/\/debian-security\/?$/ { sub(/\/$/, ""); print; exit }' <<<"$uris")}"
  # One found without the other: the same host's sibling path; neither: deb.debian.org.
  if [ -z "$MIRROR" ]; then MIRROR="${SECURITY:+${SECURITY%-security}}"; fi
  MIRROR="${MIRROR:-http://deb.debian.org/debian}"
  SECURITY="${SECURITY:-$MIRROR-security}"
}

# A private apt: its own sources list, lists, cache and an empty dpkg status, under $APTDIR.
apt_setup() {
  local v s uri keys="" k opt
  pick_mirrors
  for k in /usr/share/keyrings/debian-archive-keyring.gpg /usr/share/keyrings/debian-archive-removed-keys.gpg; do
    [ -r "$k" ] && keys="${keys:+$keys,}$k" # removed-keys: old releases' keys, once retired
  done
  if [ -n "$keys" ]; then
    opt="signed-by=$keys"
  else
    # FALLBACK, unverified: no Debian archive keyring on this machine (e.g. not Debian), so the
    # Release files cannot be checked. Install debian-archive-keyring to get signatures checked.
    echo "drivers: WARNING: no /usr/share/keyrings/debian-archive-keyring.gpg; using trusted=yes" >&2
    opt="trusted=yes"
  fi
  mkdir -p "$APTDIR/lists/partial" "$APTDIR/cache/archives/partial" "$APTDIR/debs"
  : >"$APTDIR/status"
  for v in "$@"; do spec "$v"; echo "$SUITES"; done | tr ' ' '\n' | sort -u | while read -r s; do
    case "$s" in *-security) uri="$SECURITY" ;; *) uri="$MIRROR" ;; esac
    echo "deb [arch=$ARCH $opt] $uri $s main"
  done >"$APTDIR/sources.list"
  APT=(-o "Dir::Etc::sourcelist=$APTDIR/sources.list" -o Dir::Etc::sourceparts=/nonexistent
    -o "Dir::State::Lists=$APTDIR/lists" -o "Dir::Cache=$APTDIR/cache"
    -o "Dir::State::status=$APTDIR/status" -o Acquire::Languages=none
    -o Acquire::IndexTargets::deb::DEP-11::DefaultEnabled=false)
  # As root apt downloads as user _apt, who cannot write into a 0700 temp dir under the repo.
  [ "$(id -u)" != 0 ] || APT+=(-o APT::Sandbox::User=root)
  echo "drivers: apt update (private lists) from $MIRROR and $SECURITY"
  # A suite the mirror no longer serves fails here; a missing package is reported below.
  apt-get "${APT[@]}" -qq update || echo "drivers: apt update reported errors (above)" >&2
}

# The newest version of package $1 in suites "$2" whose version matches glob $3.
best_version() {
  local pkg="$1" suites=" $2 " glob="$3" best="" ver src suite
  while IFS='|' read -r _ ver src; do
    ver="${ver//[[:space:]]/}"; suite="$(awk '{ print $2 }' <<<"$src")"; suite="${suite%%/*}"
    # shellcheck disable=SC2053 # $glob is a pattern on purpose
    [[ "$suites" == *" $suite "* && "$ver" == $glob ]] || continue
    if [ -z "$best" ] || dpkg --compare-versions "$ver" gt "$best"; then best="$ver"; fi
  done < <(apt-cache "${APT[@]}" madison "$pkg" 2>/dev/null)
  echo "$best"
}

install_one() {
  local v="$1" stage pkg ver pkgs=() icd lib d main=mesa-vulkan-drivers glob="$1-*"
  spec "$v"
  if [ "$v" = swiftshader ]; then main=chromium-common; glob="*"; fi
  for pkg in $main $EXTRA; do
    if [ "$pkg" = "$main" ]; then ver="$(best_version "$pkg" "$SUITES" "$glob")"
    else ver="$(best_version "$pkg" "$SUITES" "*")"; fi
    [ -n "$ver" ] || die "$pkg for $(label "$v") not found in $SUITES at $MIRROR" \
      "(set UMBRAGE_DEBIAN_MIRROR, e.g. to an archive mirror, if the suite has moved)"
    pkgs+=("$pkg=$ver")
  done
  echo "drivers: $v: ${pkgs[*]}"
  rm -f "$APTDIR"/debs/*.deb
  (cd "$APTDIR/debs" && apt-get "${APT[@]}" -qq download "${pkgs[@]}") || die "download failed for $v"
  stage="$(mktemp -d "$DRIVERS_DIR/.stage-$v.XXXXXX")"
  STAGES+=("$stage")
  for pkg in "$APTDIR"/debs/*.deb; do dpkg -x "$pkg" "$stage"; done
  if [ "$v" = swiftshader ]; then
    keep_swiftshader "$stage"
  else
    keep_lavapipe "$stage" "$v"
  fi

  write_env "$v" "$stage" "$ICD" "$(dirname "$LIB")" >"$stage/env.sh"
  printf '%s\n' "${pkgs[@]}" >"$stage/packages.txt"
  date -u +%Y-%m-%dT%H:%M:%SZ >"$stage/$STAMP"
  chmod 755 "$stage"
  # Atomic: a half-written or stamp-less leftover is replaced; a concurrent winner is kept.
  if [ -e "$DRIVERS_DIR/$v" ] && ! installed "$v"; then rm -rf "${DRIVERS_DIR:?}/$v"; fi
  mv -T "$stage" "$DRIVERS_DIR/$v" 2>/dev/null || installed "$v" || die "$v: could not move $stage into place"
  echo "drivers: $v installed in $DRIVERS_DIR/$v ($(du -sh "$DRIVERS_DIR/$v" | cut -f1))"
}

# Points the ICD JSON's library_path at the extracted library (an absolute path: the JSON names
# it by a system path, a bare name or a relative path). Sets ICD and LIB, relative to the stage.
rewrite_icd() { # STAGE VERSION ICD LIB
  local stage="$1" v="$2"
  ICD="$3"; LIB="$4"
  sed -i -E "s#(\"library_path\"[[:space:]]*:[[:space:]]*)\"[^\"]*\"#\\1\"$DRIVERS_DIR/$v/$LIB\"#" "$stage/$ICD"
  grep -q "\"$DRIVERS_DIR/$v/$LIB\"" "$stage/$ICD" || die "$v: could not rewrite library_path in $ICD"
}

# SwiftShader: keep the driver and its ICD JSON, drop the rest of Chromium's data.
keep_swiftshader() { # STAGE
  local stage="$1" keep
  keep="$(mktemp -d "$stage/.keep.XXXXXX")"
  [ -f "$stage/usr/lib/chromium/libvk_swiftshader.so" ] && [ -f "$stage/usr/lib/chromium/vk_swiftshader_icd.json" ] ||
    die "swiftshader: no usr/lib/chromium/libvk_swiftshader.so or vk_swiftshader_icd.json in chromium-common"
  mv "$stage/usr/lib/chromium/libvk_swiftshader.so" "$stage/usr/lib/chromium/vk_swiftshader_icd.json" "$keep/"
  rm -rf "${stage:?}/usr" "${stage:?}/etc"
  mkdir -p "$stage/usr/lib/swiftshader" "$stage/usr/share/vulkan/icd.d"
  mv "$keep/libvk_swiftshader.so" "$stage/usr/lib/swiftshader/"
  mv "$keep/vk_swiftshader_icd.json" "$stage/usr/share/vulkan/icd.d/"
  rmdir "$keep"
  rewrite_icd "$stage" swiftshader usr/share/vulkan/icd.d/vk_swiftshader_icd.json usr/lib/swiftshader/libvk_swiftshader.so
}

keep_lavapipe() { # STAGE VERSION
  local stage="$1" v="$2" icd lib d

  # The ICD JSON names the library by a system path or a bare name: point it at our copy. Mesa
  # 25's is lvp_icd.json (no arch); it is renamed so every version has lvp_icd.<cpu>.json.
  icd="$(find "$stage/usr/share/vulkan/icd.d" -name 'lvp_icd*.json' | head -n 1)"
  lib="$(find "$stage/usr/lib" -name libvulkan_lvp.so | head -n 1)"
  if [ -z "$icd" ] || [ -z "$lib" ]; then die "$v: no lvp ICD JSON or libvulkan_lvp.so in the packages"; fi
  icd="${icd#"$stage"/}"; lib="${lib#"$stage"/}"
  d="usr/share/vulkan/icd.d/lvp_icd.$(basename "$(dirname "$lib")" | cut -d- -f1).json"
  [ "$icd" = "$d" ] || { mv "$stage/$icd" "$stage/$d"; icd="$d"; }
  rewrite_icd "$stage" "$v" "$icd" "$lib"
}

# env.sh: select this lavapipe alone (VK_ICD_FILENAMES for old loaders, VK_DRIVER_FILES for new),
# drop loader variables that add or filter drivers, and put its libraries (and any llvm-*/lib)
# first on LD_LIBRARY_PATH, keeping what was there after.
write_env() { # VERSION STAGE ICD LIBDIR (the last two relative to the cache root)
  local v="$1" stage="$2" root="$DRIVERS_DIR/$1" icd="$DRIVERS_DIR/$1/$3" libs="$DRIVERS_DIR/$1/$4" d
  for d in "$stage"/usr/lib/llvm-*/lib; do [ -d "$d" ] && libs="$libs:$root/${d#"$stage"/}"; done
  echo "# $(label "$v") from $root: eval or source this"
  echo "export VK_ICD_FILENAMES=$(printf '%q' "$icd")"
  echo "export VK_DRIVER_FILES=$(printf '%q' "$icd")"
  echo "unset VK_ADD_DRIVER_FILES VK_LOADER_DRIVERS_SELECT VK_LOADER_DRIVERS_DISABLE"
  echo "export LD_LIBRARY_PATH=$(printf '%q' "$libs")\"\${LD_LIBRARY_PATH:+:\$LD_LIBRARY_PATH}\""
}

cmd_install() {
  local v todo=()
  [ $# -gt 0 ] || usage_error "install: name at least one version (${VERSIONS[*]} or all)"
  for v in "$@"; do [ "$v" != all ] || set -- "$@" "${VERSIONS[@]}"; done
  for v in "$@"; do
    [ "$v" != all ] || continue
    spec "$v"
    if installed "$v"; then echo "drivers: $v already installed ($DRIVERS_DIR/$v)"
    elif [[ " ${todo[*]} " != *" $v "* ]]; then todo+=("$v"); fi
  done
  [ ${#todo[@]} -gt 0 ] || return 0
  command -v apt-get >/dev/null 2>&1 || die "install needs apt-get and dpkg (Debian/Ubuntu); no apt-get here"
  ARCH="$(dpkg --print-architecture 2>/dev/null)" || die "install needs apt-get and dpkg (Debian/Ubuntu); no dpkg here"
  case "$DRIVERS_DIR" in *[\"\\\#\&]*) die "the cache path may not contain \" \\ # or &: $DRIVERS_DIR" ;; esac
  mkdir -p "$DRIVERS_DIR"
  # Temp dirs a killed run (SIGKILL, power loss) left behind, once surely not another run's.
  find "$DRIVERS_DIR" -mindepth 1 -maxdepth 1 \( -name '.stage-*' -o -name '.apt.*' \) -mmin +120 -exec rm -rf {} +
  APTDIR="$(mktemp -d "$DRIVERS_DIR/.apt.XXXXXX")"
  STAGES=()
  trap 'rm -rf "$APTDIR" "${STAGES[@]}"' EXIT
  trap 'exit 130' INT
  trap 'exit 143' TERM
  apt_setup "${todo[@]}"
  for v in "${todo[@]}"; do install_one "$v"; done
}

# One device, the expected Vulkan version, and (Mesa >= 21 has driverInfo) the Mesa version.
cmd_check() {
  local out n
  command -v vulkaninfo >/dev/null 2>&1 || die "check needs vulkaninfo (Debian: vulkan-tools); not found"
  # shellcheck disable=SC1090 # env.sh is generated
  out="$(source "$DRIVERS_DIR/$1/env.sh" && vulkaninfo --summary 2>&1)" || { echo "$out"; die "$1: vulkaninfo failed"; }
  grep -E '^\s*(deviceName|deviceType|apiVersion|driverName|driverInfo)\s*=' <<<"$out" || true
  n="$(grep -cE '^\s*deviceName\s*=' <<<"$out" || true)"
  echo "devices: $n"
  [ "$n" = 1 ] || die "$1: expected exactly one device, saw $n"
  grep -qE "apiVersion\s*= ${API//./\\.}\." <<<"$out" || die "$1: expected Vulkan $API.x"
  if [ "$1" = swiftshader ]; then
    grep -qE 'driverName\s*= SwiftShader' <<<"$out" || grep -qE 'deviceName\s*= SwiftShader' <<<"$out" ||
      die "swiftshader: the device is not SwiftShader"
  elif grep -qE 'driverInfo\s*=' <<<"$out"; then
    grep -qE "driverInfo\s*= Mesa ${1//./\\.}\b" <<<"$out" || die "$1: driverInfo names another Mesa"
  fi
  echo "drivers: $1 ok"
}

verb="${1:-}"
[ $# -eq 0 ] || shift
case "$verb" in
  install) cmd_install "$@" ;;
  env|path|check)
    [ $# -eq 1 ] || usage_error "$verb: name exactly one version (${VERSIONS[*]})"
    need_installed "$1"
    case "$verb" in
      env) grep -v '^#' "$DRIVERS_DIR/$1/env.sh" ;;
      path) echo "$DRIVERS_DIR/$1" ;;
      check) cmd_check "$1" ;;
    esac ;;
  list)
    [ $# -eq 0 ] || usage_error "list takes no arguments"
    for v in "${VERSIONS[@]}"; do
      if installed "$v"; then echo "$v installed $(head -n 1 "$DRIVERS_DIR/$v/packages.txt") $DRIVERS_DIR/$v"
      else echo "$v not-installed"; fi
    done ;;
  -h|--help|help) usage ;;
  "") usage_error "missing verb (install, env, list, path, check)" ;;
  *) usage_error "unknown verb '$verb' (install, env, list, path, check)" ;;
esac
