#!/usr/bin/env bash
# timed.sh COMMAND...: runs COMMAND (through bash, so `eval ... && ...` works), then appends its
# wall time to target/ci-times.txt and prints it, `[time] 123 s: COMMAND`, keeping its status.
# The Makefile's test steps run through it, so that a CI log shows where the minutes go
# (.ci/run prints the table at the end).
start=$(date +%s)
bash -c "$*"
status=$?
mkdir -p target
printf '%5d s  %s%s\n' "$(($(date +%s) - start))" "$*" "$([ $status = 0 ] || echo "  (exit $status)")" | tee -a target/ci-times.txt | sed 's/^/[time] /'
exit $status
