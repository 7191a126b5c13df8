#!/usr/bin/env python3
"""Plots the bits of every frame of a .gvid stream, coloured by frame type, with each frame's QP.

Usage: plot_bits.py STREAM.gvid [-o bits.png]
Without -o the plot opens in a window (with a display); with -o it is written to the file.
Needs the gvkit module on the Python path (PYTHONPATH=build/python, or `cmake --install`).
"""
import argparse
import sys

import matplotlib

import gvkit


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("stream", help="a .gvid file")
    parser.add_argument("-o", "--output", help="image file to write (PNG, SVG, PDF)")
    args = parser.parse_args(argv)
    if args.output:
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    reader = gvkit.open(args.stream)
    info, stats = reader.info, reader.stats()
    frames = range(len(reader))
    colours = {"I": "tab:red", "P": "tab:blue", "B": "tab:green"}
    fig, ax = plt.subplots(figsize=(9, 4))
    for kind, colour in colours.items():
        chosen = [f for f in frames if stats["type"][f] == kind]
        if chosen:
            ax.bar(chosen, stats["bits"][chosen] / 1000.0, color=colour, label=f"{kind} frames")
    ax.set_ylim(0, stats["bits"].max() / 1000.0 * 1.3)  # room for the legend
    ax.set_xlabel("frame (display order)")
    ax.set_ylabel("kbit per frame")
    profile = info["profile"] or "legacy"
    ax.set_title(f"{args.stream}: {info['width']}x{info['height']}, format {info['format']} "
                 f"({profile}), {stats['bits'].sum() / 1000.0 / len(reader) * info['fps']:.0f} "
                 f"kbit/s at {info['fps']:g} fps")
    qp_axis = ax.twinx()
    qp_axis.plot(list(frames), stats["qp"], color="black", marker=".", linewidth=1, label="QP")
    qp_axis.set_ylabel("QP")
    low, high = int(stats["qp"].min()), int(stats["qp"].max())
    qp_axis.set_ylim(low - 1, high + 1 + 0.4 * (high - low + 2))  # below the legend
    handles, labels = ax.get_legend_handles_labels()
    more_handles, more_labels = qp_axis.get_legend_handles_labels()
    ax.legend(handles + more_handles, labels + more_labels, loc="upper center", ncol=4)
    fig.tight_layout()
    if args.output:
        fig.savefig(args.output, dpi=100)
        print(f"{args.output}: {len(reader)} frames")
    else:
        plt.show()
    return 0


if __name__ == "__main__":
    sys.exit(main())
