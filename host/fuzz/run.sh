#!/usr/bin/env bash
# Runs every fuzz target of build dir $1, one after the other, either for $2
# seconds each (time mode; the two scene-file parsers, box_file and
# broadmark_file, share one such slot, half each) or for $2 executions each
# (--runs mode). Each
# starts from the committed seeds (host/fuzz/corpus/<target>, never written)
# plus a working corpus in the build dir, so every committed reproducer is
# replayed first. Any crash, sanitizer report, failed property or input
# slower than 10 s fails the script, leaving the input in <build>/artifacts.
#   run.sh BUILD_DIR SECONDS        run.sh --runs BUILD_DIR EXECUTIONS
set -euo pipefail
mode=-max_total_time
if [ "${1:-}" = "--runs" ]; then mode=-runs; shift; fi
build=${1:?build dir}
amount=${2:?seconds or executions}
here=$(cd "$(dirname "$0")" && pwd)

mkdir -p "$build/artifacts"
for target in box_file broadmark_file pairs; do
  work="$build/work/$target"
  share=$amount
  # The file parsers are cheap and simple: half a slot each keeps make test's time.
  if [ "$mode" = -max_total_time ] && [ "$target" != pairs ]; then share=$(( (amount + 1) / 2 )); fi
  mkdir -p "$work"
  dict=()
  [ -f "$here/$target.dict" ] && dict=(-dict="$here/$target.dict")
  # A pairs input of 512 bytes holds up to about 70 boxes: enough for chunked
  # cells and many leaves, and the brute force stays cheap.
  max_len=4096
  [ "$target" = pairs ] && max_len=512
  log="$build/$target.log"
  echo "fuzz: $target ($mode=$share), log in $log"
  status=0
  "$build/${target}_fuzzer" "$mode=$share" -timeout=10 -rss_limit_mb=2048 -max_len=$max_len -print_final_stats=1 \
    -artifact_prefix="$build/artifacts/$target-" "${dict[@]}" "$work" "$here/corpus/$target" >"$log" 2>&1 ||
    status=$?
  grep -E '^(Done|stat::number_of_executed_units|stat::average_exec_per_sec)' "$log" | sed "s/^/fuzz: $target: /" || true
  if [ $status -ne 0 ]; then
    tail -n 40 "$log" >&2
    echo "fuzz: $target FAILED (exit $status); the input is in $build/artifacts/, replay it with" \
      "$build/${target}_fuzzer <file>" >&2
    exit 1
  fi
done
