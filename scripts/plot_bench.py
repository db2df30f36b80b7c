#!/usr/bin/env python3
"""Plots of a benchmark run (results/bench.json by default):
acceleration over the fastest baseline (Bullet or a peer) of each run against
object count, one line per cell size; every method's frame time; and the
parts of the accelerator's frame time stacked. Skipped methods (with their
reason in the JSON) leave gaps."""
import pathlib
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from json_input import parse_and_read  # noqa: E402


def ran(m):
    return "skipped" not in m and m.get("frame_ms") is not None


def profile_of(m):
    """The device profile an accelerator row is modelled on ("" for none)."""
    return (m.get("profile") or {}).get("name", "")


def platforms(cfg):
    """Each platform the accelerator rows are modelled on, for titles: its name, part and clock."""
    profiles = cfg.get("profiles") or []
    if not profiles:
        return f"{cfg.get('clock_hz', 0) / 1e6:.0f} MHz"
    return "\n".join(f"{p['name']}: {p['part']['name']} {p['part']['clock_hz']['value'] / 1e6:.0f} MHz "
                     f"({p['part']['clock_hz']['provenance']}), {p['link']['generation']} "
                     f"{p['link']['effective_bytes_per_second_each_way']['value'] / 1e9:.2f} GB/s "
                     f"({p['link']['effective_bytes_per_second_each_way']['provenance']})" for p in profiles)


def plot_acceleration(rows, cfg, out):
    fig, ax = plt.subplots(figsize=(7, 5))
    counts = [r["objects"] for r in rows]
    series = [("cpu", "", "--s")] + [("accelerator", p, "-o") for p in
                                      sorted({profile_of(m) for r in rows for m in r["methods"]
                                              if m["kind"] == "accelerator"})]
    for kind, profile, style in series:
        for cell in cfg["cell_sizes"]:
            xs, ys = [], []
            for r in rows:
                base = r.get("fastest_baseline")
                m = next((m for m in r["methods"] if m["kind"] == kind and str(m["cell_size"]) == cell
                          and m.get("partition", "k-d") == "k-d" and profile_of(m) == profile), None)
                if base and m and ran(m):
                    xs.append(r["objects"])
                    ys.append(base["frame_ms"] / m["frame_ms"]["median"])
            if xs:
                label = f"{kind} on {profile}, cell {cell}" if profile else f"{kind}, cell {cell}"
                ax.plot(xs, ys, style, label=label, alpha=1.0 if kind == "accelerator" else 0.5)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.axhline(1, color="grey", lw=0.8)
    ax.set_xlabel("objects")
    ax.set_ylabel("acceleration over the fastest baseline")
    names = ", ".join(f"n={r['objects']}: {r['fastest_baseline']['name']}" for r in rows if r.get("fastest_baseline"))
    ax.set_title(f"m={cfg.get('hardware', {}).get('m', '?')}, device and link modelled, host measured\n"
                 f"{platforms(cfg)}\nfastest of Bullet and the peers: {names}", fontsize=6)
    ax.set_xticks(counts)
    ax.set_xticklabels([str(c) for c in counts])
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(out / "acceleration.png", dpi=120)
    plt.close(fig)


def plot_methods(rows, out):
    fig, ax = plt.subplots(figsize=(8, 5))
    names = []
    for r in rows:
        for m in r["methods"]:
            if m["name"] not in names and (m["kind"] in ("bullet", "peer") or m["name"].endswith(" 128")
                                           or " 128 on " in m["name"]):
                names.append(m["name"])
    for name in names:
        xs, ys = [], []
        for r in rows:
            m = next((m for m in r["methods"] if m["name"] == name), None)
            if m and ran(m):
                xs.append(r["objects"])
                ys.append(m["frame_ms"]["median"])
        kind = next(m["kind"] for r in rows for m in r["methods"] if m["name"] == name)
        style = {"bullet": "-o", "peer": "-.^", "accelerator": "-s", "cpu": "--s"}[kind]
        if xs:
            ax.plot(xs, ys, style, label=name)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("objects")
    ax.set_ylabel("median ms per frame (one thread)")
    ax.set_title("Every broad phase on the bouncing cube (gaps: skipped, see the table)", fontsize=9)
    ax.legend(fontsize=6, ncol=2)
    fig.tight_layout()
    fig.savefig(out / "methods.png", dpi=120)
    plt.close(fig)


def plot_parts(rows, out):
    fig, axes = plt.subplots(1, len(rows), figsize=(4 * len(rows), 4), squeeze=False)
    for ax, r in zip(axes[0], rows):
        accel = [m for m in r["methods"] if m["kind"] == "accelerator" and ran(m)]
        names = [f'{m.get("partition", "k-d")} {m["cell_size"]}' + (f' on {profile_of(m)}' if profile_of(m) else "")
                 for m in accel]
        host = [m["host_ms_measured"]["median"] for m in accel]
        dev = [m["device_ms_modelled"]["median"] for m in accel]
        xfer = [m["transfer_ms_modelled"]["median"] for m in accel]
        ax.bar(names, host, label="host (measured)")
        ax.bar(names, dev, bottom=host, label="device, loads included (modelled)")
        ax.bar(names, xfer, bottom=[h + d for h, d in zip(host, dev)], label="transfer (modelled)")
        ax.set_title(f"n = {r['objects']}")
        ax.set_xlabel("partition, cell size and device profile")
        ax.tick_params(axis="x", labelrotation=45)
        ax.set_ylabel("ms per frame (median)")
    axes[0][0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(out / "frame_parts.png", dpi=120)
    plt.close(fig)


TIMELINE_LANES = (
    ("produce", "host: keys, partition, packing\n(measured)", "tab:blue"),
    ("link", "link (modelled)", "tab:orange"),
    ("device", "device: load + compute\n(modelled)", "tab:red"),
    ("decode", "host: decode, filter\n(measured; the producer's thread)", "tab:green"),
)


def plot_timeline(rows, out, objects=8000):
    """One accelerated frame as a pipeline: the row of `objects` objects, or
    the largest row with a timeline. Returns the file written, or None."""
    timed = [r for r in rows if r.get("timeline")]
    if not timed:
        return None
    row = next((r for r in timed if r["objects"] == objects), max(timed, key=lambda r: r["objects"]))
    t = row["timeline"]
    fig, ax = plt.subplots(figsize=(10, 3.9))
    lanes = list(reversed(TIMELINE_LANES))
    for y, (lane, _, colour) in enumerate(lanes):
        spans = [(s, e - s) for s, e in t["lanes"].get(lane, []) if e > s]
        ax.broken_barh(spans, (y - 0.35, 0.7), facecolors=colour, edgecolor="none")
    ax.set_yticks(range(len(lanes)))
    ax.set_yticklabels([label for _, label, _ in lanes], fontsize=8)
    ax.set_xlabel("time in the frame, ms")
    ax.axvline(t["frame_ms"], color="black", lw=1)
    paced = t.get("paced_ms")
    paced_text = (
        f"\nmedian paced frame {paced:.3f} ms: the host's threads MEASURED against a device emulated for its "
        f"modelled time"
        if paced is not None
        else ""
    )
    ax.set_title(
        f"{t['method']}, {t['objects']} objects, one frame: {t['frame_ms']:.3f} ms with host, link and device "
        f"overlapped (MODELLED schedule)\nvs {t['serial_ms']:.3f} ms in series; "
        f"{t.get('batches', t.get('runs'))} hand-overs to the device{paced_text}",
        fontsize=8,
    )
    fig.tight_layout()
    path = out / "timeline.png"
    fig.savefig(path, dpi=130)
    plt.close(fig)
    return path


def main() -> int:
    args, (rows, cfg) = parse_and_read("plot_bench", __doc__, "results/bench.json", "--out-dir", "results",
                                       ("rows", "configuration"))
    out = pathlib.Path(args.out_dir)
    out.mkdir(parents=True, exist_ok=True)
    plot_acceleration(rows, cfg, out)
    plot_methods(rows, out)
    plot_parts(rows, out)
    timeline = plot_timeline(rows, out)
    print(f"plot_bench: wrote {out / 'acceleration.png'}, {out / 'methods.png'}, {out / 'frame_parts.png'}"
          + (f" and {timeline}" if timeline else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())
