#!/usr/bin/env python3
"""Plots of a benchmark run (results/bench.json by default):
acceleration against object count, one line per cell size, and the parts of
the accelerator's frame time stacked."""
import argparse
import json
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--json", default="results/bench.json")
    ap.add_argument("--out-dir", default="results")
    args = ap.parse_args()
    try:
        data = json.loads(pathlib.Path(args.json).read_text())
        rows = data["rows"]
        cfg = data["configuration"]
    except (OSError, ValueError, KeyError) as e:
        print(f"plot_bench: cannot read {args.json}: {e}", file=sys.stderr)
        return 1
    out = pathlib.Path(args.out_dir)
    out.mkdir(parents=True, exist_ok=True)
    counts = [r["objects"] for r in rows]
    clock = cfg["clock_hz"] / 1e6

    fig, ax = plt.subplots(figsize=(7, 4.5))
    for kind, style in (("accelerator", "-o"), ("cpu", "--s")):
        for cell in cfg["cell_sizes"]:
            ys = []
            for r in rows:
                fastest = r["fastest_bullet"]
                m = next(m for m in r["methods"] if m["kind"] == kind and str(m["cell_size"]) == cell)
                ys.append(m["acceleration_over"][fastest])
            label = f"{kind}, cell {cell}"
            ax.plot(counts, ys, style, label=label, alpha=1.0 if kind == "accelerator" else 0.5)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.axhline(1, color="grey", lw=0.8)
    ax.set_xlabel("objects")
    ax.set_ylabel("acceleration over the fastest Bullet broad phase")
    ax.set_title(f"m={cfg['hardware']['m']}, {clock:.0f} MHz (device and link modelled, host measured)", fontsize=9)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(out / "acceleration.png", dpi=120)

    fig, axes = plt.subplots(1, len(rows), figsize=(4 * len(rows), 4), squeeze=False)
    for ax, r in zip(axes[0], rows):
        accel = [m for m in r["methods"] if m["kind"] == "accelerator"]
        names = [str(m["cell_size"]) for m in accel]
        host = [m["host_ms_measured"]["median"] for m in accel]
        dev = [m["device_ms_modelled"]["median"] for m in accel]
        xfer = [m["transfer_ms_modelled"]["median"] for m in accel]
        ax.bar(names, host, label="host (measured)")
        ax.bar(names, dev, bottom=host, label="device (modelled)")
        ax.bar(names, xfer, bottom=[h + d for h, d in zip(host, dev)], label="transfer (modelled)")
        ax.set_title(f"n = {r['objects']}")
        ax.set_xlabel("k-d tree cell size")
        ax.set_ylabel("ms per frame (median)")
    axes[0][0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out / "frame_parts.png", dpi=120)
    print(f"plot_bench: wrote {out / 'acceleration.png'} and {out / 'frame_parts.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
