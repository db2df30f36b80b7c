#!/usr/bin/env bash
# Runs the parts of `make test` one after the other, each a make target, and
# ends with one line giving each part's time, so the budget stays in sight:
#   make test: passed in 9m12s of the 10m budget: sbt 4m01s, host 2m10s, fpga 1m50s, fuzz 1m11s
# A failing part stops the run, as make would, and the line names it.
#   test_parts.sh NAME=TARGET ...
set -uo pipefail
budget_s=600
make_cmd=${MAKE:-make}
clock() { printf '%dm%02ds' $(($1 / 60)) $(($1 % 60)); }

start=$SECONDS
parts=()
failed=
for part in "$@"; do
  name=${part%%=*}
  t0=$SECONDS
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
