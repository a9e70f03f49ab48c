#!/usr/bin/env python3
"""The validations of `fignet train` logs (OUT.log.jsonl) as one Markdown table.

Usage: scripts/training-log.py [--batch NAME=B ...] LOG [LOG ...]

One row per validation of each log: steps, samples seen (the log's "samples"; logs from before
that field need --batch, and count steps × batch), the rollouts' mean translation and rotation error,
and the one-step error per regime (free flight, moving contact, rest) in millimetres. The runs of
a compute-matched comparison are best read side by side at equal samples.
"""
import argparse
import json
import pathlib
import sys


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("logs", nargs="+", type=pathlib.Path, help="OUT.log.jsonl files")
    parser.add_argument("--batch", action="append", default=[], metavar="NAME=B",
                        help="batch size of the log whose file name starts with NAME")
    args = parser.parse_args()
    given = {}
    for item in args.batch:
        name, _, size = item.partition("=")
        if not size.isdigit():
            parser.error(f"--batch {item}: expected NAME=B with B a number")
        given[name] = int(size)

    print("| run | steps | samples | translation (m) | rotation (°) "
          "| one step: free flight / moving contact / rest (mm) |")
    print("|---|---|---|---|---|---|")
    for log in args.logs:
        name = log.name.removesuffix(".log.jsonl").removesuffix(".h5")
        batch = next((b for prefix, b in given.items() if name.startswith(prefix)), None)
        try:
            lines = log.read_text().splitlines()
        except OSError as e:
            print(f"training-log.py: {log}: {e.strerror}", file=sys.stderr)
            return 1
        for number, line in enumerate(lines, 1):
            try:
                entry = json.loads(line)
            except json.JSONDecodeError:
                print(f"training-log.py: {log}:{number}: not a JSON line", file=sys.stderr)
                return 1
            if "valid_translation_m" not in entry:
                continue
            step = entry["step"]
            seen = entry.get("samples", step * batch if batch else None)
            samples = f"{seen / 1000:.0f}k" if seen is not None else "?"
            one_step = " / ".join(
                f"{1e3 * entry[key]:.2f}" if key in entry else "-"
                for key in ("valid_one_step_m_free_flight", "valid_one_step_m_moving_contact",
                            "valid_one_step_m_rest"))
            print(f"| {name} | {step} | {samples} | {entry['valid_translation_m']:.3f} "
                  f"| {entry['valid_rotation_deg']:.1f} | {one_step} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
