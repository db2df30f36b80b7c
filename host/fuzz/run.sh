#!/usr/bin/env bash
# Runs every fuzz target of build dir $1 in two lanes side by side (each
# target is single-threaded): pairs in one, the two scene-file parsers
# (box_file, broadmark_file) one after the other in the other. In time mode
# pairs searches $2 seconds and each parser half of it; in --runs mode each
# target makes $2 executions. Each
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

# One target: its search, then its verdict. Prints and returns nonzero on a finding.
fuzz_target() {
  local target=$1 amount=$2 work="$build/work/$1" log="$build/$1.log" status=0
  echo "fuzz: $target ($mode=$amount), log in $log"
  mkdir -p "$work"
  local dict=()
  [ -f "$here/$target.dict" ] && dict=(-dict="$here/$target.dict")
  # A pairs input of 512 bytes holds up to about 70 boxes: enough for chunked
  # cells and many leaves, and the brute force stays cheap.
  local max_len=4096
  [ "$target" = pairs ] && max_len=512
  "$build/${target}_fuzzer" "$mode=$amount" -timeout=10 -rss_limit_mb=2048 -max_len=$max_len -print_final_stats=1 \
    -artifact_prefix="$build/artifacts/$target-" "${dict[@]}" "$work" "$here/corpus/$target" >"$log" 2>&1 ||
    status=$?
  grep -E '^(Done|stat::number_of_executed_units|stat::average_exec_per_sec)' "$log" | sed "s/^/fuzz: $target: /" || true
  if [ $status -ne 0 ]; then
    tail -n 40 "$log" >&2
    echo "fuzz: $target FAILED (exit $status); the input is in $build/artifacts/, replay it with" \
      "$build/${target}_fuzzer <file>" >&2
    return 1
  fi
}

# The file parsers are cheap and simple: half a slot each keeps make test's time.
parser_share=$amount
[ "$mode" = -max_total_time ] && parser_share=$(((amount + 1) / 2))
fuzz_target pairs "$amount" &
pairs_pid=$!
parsers_failed=0
{ fuzz_target box_file "$parser_share" && fuzz_target broadmark_file "$parser_share"; } || parsers_failed=1
wait "$pairs_pid" || exit 1
exit $parsers_failed
