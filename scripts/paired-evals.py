#!/usr/bin/env python3
"""Two `fignet eval --json` (or two `fignet compare --json`) results compared scene by scene, as
`fignet eval` compares the models of one run: for runs that one invocation cannot hold together
(other `--turns`, other builds, other world options).

    scripts/paired-evals.py REFERENCE.json RUN.json [--reference-run NAME] [--run NAME]

Each side is one run of its file (default: its first FIGNet run; --run / --reference-run pick one
by name). Both files must hold the same data and trajectories. Prints, for the mean translation
and the mean rotation over each rollout: the two means, the run's mean over the reference's minus
one with a 95 % interval over 10,000 bootstrap resamples of the scenes (fixed seed: the same
interval every time), the scenes where the run is the lower, and the two-sided sign test: the
library's own comparison (`fignet.compare_paired`), so the figures are those `fignet eval` prints
for models of one run. Needs the Python module (PYTHONPATH=build/release/python).
"""

import argparse
import json
import sys

import fignet


def fail(message):
    print(f"paired-evals.py: {message}", file=sys.stderr)
    sys.exit(1)


def load_run(path, name):
    """(data files, per-trajectory errors) of the run `name` of `path`, or its first FIGNet run."""
    try:
        with open(path) as file:
            result = json.load(file)
    except (OSError, json.JSONDecodeError) as error:
        fail(f"cannot read '{path}': {error}")
    runs = result.get("runs") if isinstance(result, dict) else None
    if not runs:
        fail(f"'{path}' is not a `fignet eval --json` or `fignet compare --json` result (no runs)")
    if name is None:
        chosen = [run for run in runs if run.get("kind") == "FIGNet"][:1]
    else:
        chosen = [run for run in runs if run.get("name") == name]
    if not chosen:
        names = ", ".join(str(run.get("name")) for run in runs)
        missing = f"no run {name!r}" if name else "no FIGNet run"
        fail(f"'{path}' has {missing} (its runs: {names})")
    per_trajectory = chosen[0].get("per_trajectory")
    if not per_trajectory:
        fail(f"run {chosen[0].get('name')!r} of '{path}' has no per-trajectory errors")
    return result.get("data"), per_trajectory


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("reference")
    parser.add_argument("run")
    parser.add_argument("--reference-run", help="the reference file's run, by name")
    parser.add_argument("--run", dest="run_name", help="the run file's run, by name")
    args = parser.parse_args()

    reference_data, reference = load_run(args.reference, args.reference_run)
    run_data, run = load_run(args.run, args.run_name)
    if reference_data != run_data or len(reference) != len(run):
        fail(f"the two results are of different scenes ({reference_data}, {len(reference)} "
             f"trajectories; {run_data}, {len(run)})")

    # eval's "data" lists its files; compare's is the one file it simulated.
    files = [run_data] if isinstance(run_data, str) else (run_data or [])
    print(f"{len(run)} scenes of {', '.join(files)}; {args.run} against {args.reference}")
    for label, field in (("mean translation (m)", "mean_translation_m"),
                         ("mean rotation (deg)", "mean_rotation_deg")):
        a = [trajectory[field] for trajectory in reference]
        b = [trajectory[field] for trajectory in run]
        c = fignet.compare_paired(a, b)
        print(f"{label}: {c['mean_a']:.4f} -> {c['mean_b']:.4f}  {100 * c['relative']:+.1f}% "
              f"[{100 * c['relative_low']:+.1f}, {100 * c['relative_high']:+.1f}]  "
              f"lower on {c['b_lower']}/{c['b_lower'] + c['a_lower']}  p={c['sign_test_p']:.2g}")


if __name__ == "__main__":
    main()
