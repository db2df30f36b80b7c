#!/usr/bin/env bash
# Runs the parts of `make test` one after the other, each a make target, and
# ends with one line giving each part's time, so the budget stays in sight:
#   make test: passed in 9m12s of the 10m budget: sbt 4m01s, host 2m10s, fpga 1m50s, fuzz 1m11s
# A failing part stops the run, as make would, and the line names it.
# --ahead TARGET builds TARGET at low priority from the start, in the cores
# the parts leave idle (sbt compiling Scala on one thread, a build's last
# link); the part named TARGET waits for it, then finds it built. Its log is
# build/ahead-TARGET.log: a failure there is reported again by the part that
# builds it properly.
#   test_parts.sh [--ahead TARGET] NAME=TARGET ...
set -uo pipefail
budget_s=600
make_cmd=${MAKE:-make}
clock() { printf '%dm%02ds' $(($1 / 60)) $(($1 % 60)); }

ahead=
if [ "${1:-}" = "--ahead" ]; then ahead=$2; shift 2; fi

start=$SECONDS
ahead_pid=
# The ahead build runs in a process group of its own (so it can be ended with
# its children): a run that stops early, or is interrupted, ends it here. Not
# a session of its own: the kernel's autogroup scheduling would share the
# cores between the two sessions, and its nice would count for nothing.
stop_ahead() { [ -n "$ahead_pid" ] && kill -- "-$ahead_pid" 2>/dev/null; ahead_pid=; }
trap stop_ahead EXIT
if [ -n "$ahead" ]; then
  mkdir -p build
  set -m  # job control: the background job leads a process group
  nice -n 19 "$make_cmd" --no-print-directory "$ahead" >"build/ahead-$ahead.log" 2>&1 &
  ahead_pid=$!
  set +m
fi
parts=()
failed=
for part in "$@"; do
  name=${part%%=*}
  t0=$SECONDS
  if [ -n "$ahead_pid" ] && [ "$name" = "$ahead" ]; then
    wait "$ahead_pid"
    ahead_pid=
  fi
  "$make_cmd" --no-print-directory "${part#*=}" || failed=$name
  parts+=("$name $(clock $((SECONDS - t0)))")
  [ -n "$failed" ] && break
done
total=$((SECONDS - start))
verdict=passed
[ -n "$failed" ] && verdict="FAILED ($failed)"
over=
[ $total -gt $budget_s ] && over=" (OVER BUDGET)"
line=$(printf '%s, ' "${parts[@]}")
echo "make test: $verdict in $(clock $total) of the $(clock $budget_s) budget$over: ${line%, }"
[ -z "$failed" ]
