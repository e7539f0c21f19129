#!/usr/bin/env bash
# deqp-runner, Mesa's runner from crates.io, drives `umbrage conform` unmodified
# (docs/conform/driver-ci.md):
#
#   scripts/deqp-ci.sh [--full] [--fraction N] [DRIVER...]
#   scripts/deqp-ci.sh --install-only     only step 1 (.ci/run starts it first, in the background)
#
# 1. installs deqp-runner $DEQP_RUNNER_VERSION (default 0.20.3, what Mesa pins and the quicker to
#    build on a fresh CI machine; 0.24.0 passes the same checks) with
#    `cargo install --locked` into $UMBRAGE_TOOLS_DIR (default .tools/), skipped when present;
# 2. checks that conform/umbrage-cases.txt is `umbrage conform --list`;
# 3. runs conform/deqp-umbrage.toml on each DRIVER (default: 22.3.6 swiftshader; any of
#    scripts/drivers.sh's versions) against conform/umbrage-<driver>-fails.txt: 0 unexpected
#    results (and its -flakes.txt where there is one). CI runs one case in $FRACTION (default
#    4, always shard 1: the same quarter every run); --full runs every case;
# 4. a crash injected into one case (UMBRAGE_CONFORM_CRASH_CASE=<case>:abort) costs exactly that
#    case (Crash), and the run passes with it in the baseline; an injected hang costs exactly
#    that case (Timeout);
# 5. three --fraction shards of a list run every case of it once, with the whole run's results.
# Validation layers on (UMBRAGE_VALIDATION=1) unless the caller set UMBRAGE_VALIDATION.
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$REPO"
export PATH="$HOME/.cargo/bin:$PATH"
VERSION="${DEQP_RUNNER_VERSION:-0.20.3}"
TOOLS="${UMBRAGE_TOOLS_DIR:-$REPO/.tools}"
case "$TOOLS" in /*) ;; *) TOOLS="$PWD/$TOOLS" ;; esac
OUT="${DEQP_CI_OUT:-$REPO/target/deqp-ci}"
FRACTION=4
INSTALL_ONLY=0
DRIVERS=()
while [ $# -gt 0 ]; do
  case "$1" in
    --full) FRACTION=1 ;;
    --install-only) INSTALL_ONLY=1 ;;
    --fraction) FRACTION="$2"; shift ;;
    -h|--help) sed -n '2,/^set -e/p' "$0" | sed '$d;s/^# \{0,1\}//'; exit 0 ;;
    -*) echo "deqp-ci: unknown flag $1" >&2; exit 2 ;;
    *) DRIVERS+=("$1") ;;
  esac
  shift
done
[ ${#DRIVERS[@]} -gt 0 ] || DRIVERS=(22.3.6 swiftshader)
export UMBRAGE_VALIDATION="${UMBRAGE_VALIDATION-1}"
fail() { echo "deqp-ci: FAIL: $*" >&2; exit 1; }

RUNNER="$TOOLS/deqp-runner-$VERSION/bin/deqp-runner"
if [ ! -x "$RUNNER" ]; then
  echo "deqp-ci: installing deqp-runner $VERSION into $TOOLS (cargo install --locked; minutes)"
  cargo install deqp-runner --locked --debug --version "$VERSION" --root "$TOOLS/deqp-runner-$VERSION" --quiet
fi
[ "$INSTALL_ONLY" = 0 ] || { "$RUNNER" --version; exit 0; }
export PATH="$(dirname "$(./scripts/umbrage-bin.sh)"):$PATH"

# The shipped list is the code's.
diff <(umbrage conform --list) conform/umbrage-cases.txt >/dev/null ||
  fail "conform/umbrage-cases.txt differs from 'umbrage conform --list' (regenerate it; list renamed cases in the CHANGELOG)"

./scripts/drivers.sh install "${DRIVERS[@]}" 22.3.6 >/dev/null
mkdir -p "$OUT"
rm -rf "${OUT:?}"/*
baseline_of() { echo "conform/umbrage-$( [ "$1" = swiftshader ] && echo swiftshader || echo "lavapipe-$1")-fails.txt"; }
# deqp-runner's summary of a run: fails unless every result is a success.
run_suite() { # DRIVER DIR [deqp-runner flags...]
  local d="$1" dir="$2"; shift 2
  ( eval "$(scripts/drivers.sh env "$d")"
    "$RUNNER" suite --suite conform/deqp-umbrage.toml --output "$dir" --baseline "$(baseline_of "$d")" "$@" ) > "$dir.log" 2>&1
}

for d in "${DRIVERS[@]}"; do
  [ -f "$(baseline_of "$d")" ] || fail "no baseline $(baseline_of "$d")"
  mkdir -p "$OUT/$d"
  start=$(date +%s)
  flakes=()
  f="$(baseline_of "$d")"; f="${f%-fails.txt}-flakes.txt"
  [ ! -f "$f" ] || flakes=(--flakes "$f")
  if ! run_suite "$d" "$OUT/$d" --fraction "$FRACTION" "${flakes[@]}"; then
    tail -20 "$OUT/$d.log" >&2
    fail "deqp-runner on $d: unexpected results (failures.csv: $OUT/$d/failures.csv)"
  fi
  n=$(wc -l < "$OUT/$d/results.csv")
  echo "deqp-ci: $d: $n cases (1 in $FRACTION), 0 unexpected, $(( $(date +%s) - start )) s"
done

# Crash and hang, pinned: one configuration's first 80 cases on lavapipe 22.3.6 (two children
# of 64 and 16 cases), the injected case among the first child's.
D=22.3.6
# (awk, not grep | head: under pipefail, head closing the pipe early fails the script with SIGPIPE)
awk '/^umbrage\.stencil\.d32s8\.dynamic_rendering\.static_state\./ && n < 80 { print; n++ }' conform/umbrage-cases.txt > "$OUT/pin-list.txt"
victim=$(sed -n 5p "$OUT/pin-list.txt")
pin_run() { # NAME FAULT BASELINE_LINE
  local dir="$OUT/pin-$1"
  mkdir -p "$dir"
  printf '%s\n' "$3" | grep -v '^$' > "$dir.baseline" || true
  ( eval "$(scripts/drivers.sh env "$D")"
    UMBRAGE_CONFORM_CRASH_CASE="$victim:$2" "$RUNNER" run --deqp /usr/bin/env --caselist "$OUT/pin-list.txt" \
      --output "$dir" --baseline "$dir.baseline" --timeout 60 -- umbrage conform --timeout 10 ) > "$dir.log" 2>&1
}
# Without the case in the baseline: the run fails with exactly that case as Crash.
if pin_run crash abort ""; then fail "an injected crash passed the run"; fi
[ "$(cat "$OUT/pin-crash/failures.csv")" = "$victim,Crash" ] ||
  fail "an injected crash: failures.csv is not exactly '$victim,Crash': $(head -5 "$OUT/pin-crash/failures.csv")"
[ "$(grep -c ',Pass,' "$OUT/pin-crash/results.csv")" = 79 ] || fail "an injected crash cost other cases than $victim"
# With it: the run passes.
pin_run crash-listed abort "$victim,Crash" || fail "an injected crash listed in the baseline failed the run"
if pin_run hang hang ""; then fail "an injected hang passed the run"; fi
[ "$(cat "$OUT/pin-hang/failures.csv")" = "$victim,Timeout" ] ||
  fail "an injected hang: failures.csv is not exactly '$victim,Timeout': $(head -5 "$OUT/pin-hang/failures.csv")"
[ "$(grep -c ',Pass,' "$OUT/pin-hang/results.csv")" = 79 ] || fail "an injected hang cost other cases than $victim"
echo "deqp-ci: an injected crash and an injected hang each cost exactly $victim"

# Shards: a list of 1 case in 25 (every family), whole and as three --fraction shards.
awk 'NR % 25 == 1' conform/umbrage-cases.txt > "$OUT/shard-list.txt"
shard_run() { # DIR [flags]
  local dir="$1"; shift
  mkdir -p "$dir"
  ( eval "$(scripts/drivers.sh env "$D")"
    "$RUNNER" run --deqp /usr/bin/env --caselist "$OUT/shard-list.txt" --output "$dir" \
      --baseline "$(baseline_of "$D")" "$@" -- umbrage conform --timeout 30 ) > "$dir.log" 2>&1
}
shard_run "$OUT/shard-whole" || fail "the shard list's whole run failed"
for k in 1 2 3; do shard_run "$OUT/shard-$k" --fraction 3 --fraction-start "$k" || fail "shard $k of 3 failed"; done
cut -d, -f1,2 "$OUT"/shard-whole/results.csv | sort > "$OUT/shard-whole.txt"
cat "$OUT"/shard-[123]/results.csv | cut -d, -f1,2 | sort > "$OUT/shard-union.txt"
cut -d, -f1 "$OUT/shard-union.txt" | sort | uniq -d > "$OUT/shard-twice.txt"
[ ! -s "$OUT/shard-twice.txt" ] || fail "cases run by two shards: $(head -3 "$OUT/shard-twice.txt")"
diff <(sort "$OUT/shard-list.txt") <(cut -d, -f1 "$OUT/shard-union.txt") >/dev/null || fail "the three shards do not run the whole list"
diff "$OUT/shard-whole.txt" "$OUT/shard-union.txt" >/dev/null || fail "the shards' results differ from the whole run's"
echo "deqp-ci: three shards ran each of the $(wc -l < "$OUT/shard-list.txt") cases once, with the whole run's results"
echo "deqp-ci: PASS (deqp-runner $VERSION)"
