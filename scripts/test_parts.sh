#!/usr/bin/env bash
# Runs the parts of `make test`, each a make target, and ends with one line
# giving each part's time, so the budget stays in sight:
#   make test: passed in 9m12s of the 10m00s budget: sbt 5m01s (fuzz 1m10s beside it), host 3m10s, fpga 1m15s
# Each argument is a step, and the steps run one after the other. A step of
# several parts joined by "+" runs them side by side (for a part that needs
# nothing from the others): the first part's output streams, each other part's
# goes to build/test-parts/NAME.log and is printed when the step ends.
# A failing part stops the run after its step, as make would, and the line
# names it.
#   test_parts.sh NAME=TARGET[+NAME=TARGET...] ...
set -uo pipefail
budget_s=600
make_cmd=${MAKE:-make}
logs=build/test-parts
clock() { printf '%dm%02ds' $(($1 / 60)) $(($1 % 60)); }

mkdir -p "$logs"
start=$SECONDS
summary=()
failed=
for step in "$@"; do
  IFS='+' read -ra parts <<<"$step"
  pids=()
  for k in "${!parts[@]}"; do
    name=${parts[$k]%%=*}
    target=${parts[$k]#*=}
    rm -f "$logs/$name.time"
    (
      t0=$SECONDS
      if [ "$k" -eq 0 ]; then
        "$make_cmd" --no-print-directory "$target"
      else
        "$make_cmd" --no-print-directory "$target" >"$logs/$name.log" 2>&1
      fi
      status=$?
      echo $((SECONDS - t0)) >"$logs/$name.time"
      exit $status
    ) &
    pids+=($!)
  done
  line=
  for k in "${!parts[@]}"; do
    name=${parts[$k]%%=*}
    wait "${pids[$k]}" || failed="${failed:+$failed, }$name"
    if [ "$k" -gt 0 ]; then
      echo "--- $name (ran beside ${parts[0]%%=*}): $logs/$name.log"
      cat "$logs/$name.log"
    fi
    took=$(clock "$(cat "$logs/$name.time" 2>/dev/null || echo 0)")
    if [ "$k" -eq 0 ]; then line="$name $took"; else line="$line ($name $took beside it)"; fi
  done
  summary+=("$line")
  [ -n "$failed" ] && break
done
total=$((SECONDS - start))
verdict=passed
[ -n "$failed" ] && verdict="FAILED ($failed)"
over=
[ $total -gt $budget_s ] && over=" (OVER BUDGET)"
line=$(printf '%s, ' "${summary[@]}")
echo "make test: $verdict in $(clock $total) of the $(clock $budget_s) budget$over: ${line%, }"
[ -z "$failed" ]
