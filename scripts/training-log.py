#!/usr/bin/env python3
"""The validations of `fignet train` logs (OUT.log.jsonl) as one Markdown table.

Usage: scripts/training-log.py [--batch NAME=B ...] [--cost NAME=C ...] [--against NAME] [--fit]
                               [--fit-from SAMPLES] [--plot PNG] [--side-by-side]
                               LOG [LOG ...]

One row per validation of each log: steps, samples seen (the log's "samples"; logs from before
that field need --batch, and count steps × batch), the rollouts' mean translation and rotation error,
and the one-step error per regime (free flight, moving contact, rest, and impacts where the log
has them) in millimetres. The runs of a compute-matched comparison are best read side by side at
equal samples, and at equal compute when their samples cost differently.

--cost NAME=C says that a sample of the run whose name starts with NAME costs C times a sample of
the others (e.g. the ratio of the two configs' time per step, measured in one run on one machine):
the table then has a column of compute, samples × C, in samples of the runs without --cost, and
--plot draws the curves against it.

--against NAME adds a column: each other run's translation error and one-step error in moving
contact relative to the run NAME (its file name, or the one run whose name starts with NAME) at
the same samples, in per cent (−12.0 % is 12 % below NAME's); "—" where NAME has no validation
at those samples.

Logs that record each validation trajectory's error (`valid_per_trajectory_translation_m`, from
2026-12-05) compare scene by scene: the --against cell adds the 95 % interval of the per cent
over bootstrap resamples of the validation scenes (each drawn with both runs' errors) and on how
many scenes the run's error is the lower, and a line under the table pools every validation the
two share (each scene's errors summed over them, the scenes resampled whole). An interval that
holds 0 does not tell the runs apart on these scenes; the scatter of one run between its own
validations is another matter, which only more validations or seeds measure.

--fit adds, per log, the learning curve as a power law: a least-squares line through
ln(translation) against ln(samples) over the validations from --fit-from samples on, its slope
with the slope's standard error, and where the line reaches at 10x and 100x the last validation's
samples (with the range the slope's standard error gives). Successive validations of one run
scatter by 10-30 %, so the fit says how the curve trends, not what a longer run will measure.
--plot writes the curves and their fits on log-log axes (needs matplotlib).

Logs of runs with --valid-stress get a second table: per validation and stress case, the drift of
bodies started at rest (or the error against Bullet) and the late speed, for the network alone
and for the world as users get it.

--side-by-side prints instead one short table with the runs side by side, one row per sample
count at which every run validated: the validation translation error (the lowest in bold; with
--against, each other run's per cent from NAME's), and, from runs with --valid-stress, what rest
does with the network alone: the MOVi cube's lowest point (cm, < 0 is into the floor), the drift
of the stacks of 3 and 5 cubes and of 3 MOVi cubes (cm), and the 10-object pile's drift (m).
Each cell lists the runs' figures in the order the logs were given ("—" where a run's log lacks
the figure).
"""
import argparse
import json
import math
import pathlib
import sys


def parse_count(text: str) -> float:
    """A sample count: 250000, 250k or 1.2M."""
    scale = {"k": 1e3, "m": 1e6}.get(text[-1:].lower(), 1.0)
    number = text[:-1] if scale != 1.0 else text
    try:
        value = float(number) * scale
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"'{text}' is not a sample count (e.g. 100000, 100k, 1.2M)")
    if value < 0:
        raise argparse.ArgumentTypeError(f"'{text}': a sample count is not negative")
    return value


def power_law_fit(samples, errors):
    """Least squares of ln(error) against ln(samples).

    Returns (centre, slope, slope's standard error): the line passes through centre = (mean
    ln(samples), mean ln(error)); the standard error is None with fewer than 3 points."""
    xs = [math.log(s) for s in samples]
    ys = [math.log(e) for e in errors]
    n = len(xs)
    mean_x, mean_y = sum(xs) / n, sum(ys) / n
    sxx = sum((x - mean_x) ** 2 for x in xs)
    if sxx == 0:
        raise ValueError("every validation is at the same sample count")
    slope = sum((x - mean_x) * (y - mean_y) for x, y in zip(xs, ys)) / sxx
    if n < 3:
        return (mean_x, mean_y), slope, None
    residuals = sum((y - mean_y - slope * (x - mean_x)) ** 2 for x, y in zip(xs, ys))
    return (mean_x, mean_y), slope, math.sqrt(residuals / (n - 2) / sxx)


def power_law_at(centre, slope, samples):
    """The fitted error at `samples`; another slope through the same centre gives the range its
    standard error allows."""
    return math.exp(centre[1] + slope * (math.log(samples) - centre[0]))


def longest_prefix_match(by_prefix: dict, name: str, default):
    """The value given for the longest prefix of `name`, so that "w128=3" and "w128-lr=3.1" can
    both be given (to --batch or --cost) and each run gets its own."""
    matches = sorted((prefix for prefix in by_prefix if name.startswith(prefix)), key=len)
    return by_prefix[matches[-1]] if matches else default


def read_validations(log: pathlib.Path, batch):
    """The log's validations as dicts with 'samples' filled in (None when unknown)."""
    validations = []
    for number, line in enumerate(log.read_text().splitlines(), 1):
        try:
            entry = json.loads(line)
        except json.JSONDecodeError:
            raise ValueError(f"{log}:{number}: not a JSON line")
        if "valid_translation_m" not in entry:
            continue
        entry.setdefault("samples", entry["step"] * batch if batch else None)
        validations.append(entry)
    return validations


def read_stress(log: pathlib.Path):
    """The log's stress lines (`fignet train --valid-stress`), in order."""
    return [entry for entry in map(json.loads, log.read_text().splitlines())
            if "stress" in entry]


def stress_cell(figures) -> str:
    """One simulator's figures of a case: drift (started at rest) or error, and the late speed."""
    if not figures.get("finite", False):
        return "not finite"
    late = f", late {figures['late_speed_m_s']:.2f} m/s"
    if "drift_m" in figures:
        # The first step's fall (a fraction of free fall) where the log has it (from the
        # forty-first session's binary on).
        first = (f", first step {figures['first_step_fall']:+.2f}"
                 if "first_step_fall" in figures else "")
        return f"{figures['drift_m']:.3f} m / {figures['drift_deg']:.1f}°{first}{late}"
    return f"error {figures['error_m']:.3f} m{late}"


# The rest figures of --side-by-side: column heading, stress case, figure of the network alone,
# and the factor and format it is printed with.
REST_COLUMNS = [
    ("MOVi cube at rest, lowest point (cm)", [("MOVi cube at rest", "lowest_m")], 100, "{:+.1f}"),
    ("stacks of 3 / 5 cubes, 3 MOVi cubes: drift (cm)",
     [("stack of 3 cubes", "drift_m"), ("stack of 5 cubes", "drift_m"),
      ("stack of 3 MOVi cubes", "drift_m")], 100, "{:.1f}"),
    ("10-object pile: drift (m)", [("10-object pile at rest", "drift_m")], 1, "{:.2f}"),
]


def side_by_side(runs, stress_runs, reference_name):
    """--side-by-side: the runs' validations and rest figures at each sample count all share."""
    names = [name for name, _ in runs]
    by_samples = [{v["samples"]: v for v in validations if v["samples"] is not None}
                  for _, validations in runs]
    stress_by_samples = [{e.get("samples"): e["stress"] for e in entries}
                         for _, entries in stress_runs]
    shared = sorted(set.intersection(*(set(table) for table in by_samples)))
    with_rest = any(table for table in stress_by_samples)
    columns = ["samples", f"validation translation (m): {' / '.join(names)}"]
    if reference_name is not None:
        columns.append(f"against {reference_name}")
    if with_rest:
        columns += [heading for heading, _, _, _ in REST_COLUMNS]
    print("| " + " | ".join(columns) + " |")
    print("|" + "---|" * len(columns))
    for samples in shared:
        errors = [table[samples]["valid_translation_m"] for table in by_samples]
        best = min(errors)
        cells = [format_count(samples),
                 " / ".join(f"**{e:.3f}**" if e == best and len(errors) > 1 else f"{e:.3f}"
                            for e in errors)]
        if reference_name is not None:
            ref = errors[names.index(reference_name)]
            cells.append(" / ".join(percent_from(e, ref)
                                    for name, e in zip(names, errors) if name != reference_name))
        if with_rest:
            for _, figures, factor, form in REST_COLUMNS:
                per_run = []
                for table in stress_by_samples:
                    stress = table.get(samples, {})
                    values = [stress.get(case, {}).get("network_alone", {}).get(key)
                              for case, key in figures]
                    per_run.append(", ".join(
                        with_minus(form.format(factor * v)) if v is not None else "—"
                        for v in values))
                cells.append(" / ".join(per_run))
        print("| " + " | ".join(cells) + " |")


PER_TRAJECTORY = "valid_per_trajectory_translation_m"


def paired_comparison(reference_errors, errors, resamples=10000, seed=1):
    """The errors' total over the reference's, minus one, scene by scene: (relative, 95 % low,
    95 % high, scenes where errors is the lower, scenes not tied). The interval is over bootstrap
    resamples of the scenes, each drawn with both errors (as `fignet eval` does for models)."""
    import numpy as np

    a = np.asarray(reference_errors, dtype=float)
    b = np.asarray(errors, dtype=float)
    picks = np.random.default_rng(seed).integers(0, len(a), size=(resamples, len(a)))
    totals_a = a[picks].sum(axis=1)
    ratios = b[picks].sum(axis=1)[totals_a > 0] / totals_a[totals_a > 0] - 1.0
    low, high = np.quantile(ratios, [0.025, 0.975])
    return b.sum() / a.sum() - 1.0, low, high, int((b < a).sum()), int((b != a).sum())


def paired_text(comparison) -> str:
    """ "−3.1 % [−6.0, −0.4] 14/20": the per cent, its interval, the scenes won of those not tied."""
    relative, low, high, lower, untied = comparison
    return with_minus(f"{100 * relative:+.1f} % [{100 * low:+.1f}, {100 * high:+.1f}] "
                      f"{lower}/{untied}")


def scene_by_scene(entry, other):
    """(other's, entry's) per-trajectory errors, the reference's first as paired_comparison
    takes them, when both validations have them for the same scenes; None otherwise."""
    mine, theirs = entry.get(PER_TRAJECTORY), other.get(PER_TRAJECTORY)
    if mine is None or theirs is None or len(mine) != len(theirs) or not mine:
        return None
    if any(x is None for x in mine + theirs):  # a rollout that left the finite numbers
        return None
    return theirs, mine


def pooled_against(runs, reference_name):
    """Lines under the table: each run against the reference over every validation they share
    with per-trajectory errors, each scene's errors summed over those validations."""
    reference = {v["samples"]: v for v in dict(runs)[reference_name] if v["samples"] is not None}
    lines = []
    for name, validations in runs:
        if name == reference_name:
            continue
        mine_sum, theirs_sum, shared = None, None, 0
        for entry in validations:
            other = reference.get(entry["samples"])
            pair = scene_by_scene(entry, other) if other is not None else None
            if pair is None or (mine_sum is not None and len(pair[1]) != len(mine_sum)):
                continue
            theirs, mine = pair
            if mine_sum is None:
                mine_sum, theirs_sum = [0.0] * len(mine), [0.0] * len(mine)
            mine_sum = [x + y for x, y in zip(mine_sum, mine)]
            theirs_sum = [x + y for x, y in zip(theirs_sum, theirs)]
            shared += 1
        if shared:
            lines.append(f"{name} against {reference_name}, scene by scene over the {shared} "
                         f"validation(s) both have at equal samples ({len(mine_sum)} scenes, "
                         f"each summed over them): translation "
                         f"{paired_text(paired_comparison(theirs_sum, mine_sum))}")
    return lines


def with_minus(text: str) -> str:
    """A figure with the minus sign (−) of the tables instead of a hyphen."""
    return text.replace("-", "−")


def percent_from(value: float, reference: float) -> str:
    """How far value is from reference, in per cent: "−12.0 %" is 12 % below it."""
    return with_minus(f"{100 * (value / reference - 1):+.1f} %")


def format_count(value: float) -> str:
    return f"{value / 1e6:.2f}M" if value >= 1e6 else f"{value / 1e3:.0f}k"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("logs", nargs="+", type=pathlib.Path, help="OUT.log.jsonl files")
    parser.add_argument("--batch", action="append", default=[], metavar="NAME=B",
                        help="batch size of the log whose file name starts with NAME")
    parser.add_argument("--cost", action="append", default=[], metavar="NAME=C",
                        help="a sample of the run whose name starts with NAME costs C samples of "
                             "the others (adds a compute column)")
    parser.add_argument("--against", metavar="NAME",
                        help="add each run's difference from the run NAME at equal samples (%%)")
    parser.add_argument("--fit", action="store_true",
                        help="fit a power law to each log's validation translation error")
    parser.add_argument("--fit-from", type=parse_count, default=0.0, metavar="SAMPLES",
                        help="fit only the validations from this many samples on (e.g. 100k)")
    parser.add_argument("--plot", type=pathlib.Path, metavar="PNG",
                        help="write the curves (and fits) on log-log axes to this PNG")
    parser.add_argument("--side-by-side", action="store_true",
                        help="one short table: the runs' validation and rest figures side by "
                             "side at the samples where all validated")
    args = parser.parse_args()
    given = {}
    for item in args.batch:
        name, _, size = item.partition("=")
        if not size.isdigit():
            parser.error(f"--batch {item}: expected NAME=B with B a number")
        given[name] = int(size)
    costs = {}
    for item in args.cost:
        name, _, factor = item.partition("=")
        try:
            costs[name] = float(factor)
        except ValueError:
            parser.error(f"--cost {item}: expected NAME=C with C a number")
        if not name or not costs[name] > 0:
            parser.error(f"--cost {item}: expected a run name and a cost above 0")

    runs = []
    stress_runs = []
    cost_of = {}
    for log in args.logs:
        name = log.name.removesuffix(".log.jsonl").removesuffix(".h5")
        batch = longest_prefix_match(given, name, None)
        cost_of[name] = longest_prefix_match(costs, name, 1.0)
        try:
            runs.append((name, read_validations(log, batch)))
            stress_runs.append((name, read_stress(log)))
        except OSError as e:
            print(f"training-log.py: {log}: {e.strerror}", file=sys.stderr)
            return 1
        except ValueError as e:
            print(f"training-log.py: {e}", file=sys.stderr)
            return 1

    reference = None
    reference_name = None
    if args.against is not None:
        names = [name for name, _ in runs]
        matches = [args.against] if args.against in names else [
            name for name in names if name.startswith(args.against)]
        if len(matches) != 1:
            which = "no run" if not matches else f"{len(matches)} runs ({', '.join(matches)})"
            print(f"training-log.py: --against {args.against}: {which} by that name",
                  file=sys.stderr)
            return 2
        reference_name = matches[0]
        reference = {v["samples"]: v for v in dict(runs)[reference_name]
                     if v["samples"] is not None}

    def against(name, entry):
        """The cell of --against: per cent differences from the reference at equal samples."""
        if name == reference_name:
            return "reference"
        other = reference.get(entry["samples"])
        if other is None:
            return "—"
        cells = []
        for key in ("valid_translation_m", "valid_one_step_m_moving_contact"):
            if key in entry and key in other and other[key] > 0:
                cells.append(percent_from(entry[key], other[key]))
            else:
                cells.append("-")
        pair = scene_by_scene(entry, other)
        if pair is not None:  # the translation's interval, scene by scene
            cells[0] = paired_text(paired_comparison(*pair))
        return " / ".join(cells)

    pooled = pooled_against(runs, reference_name) if reference is not None else []
    if args.side_by_side:
        side_by_side(runs, stress_runs, reference_name)
        for line in pooled:
            print(f"\n{line}")
        return 0

    with_compute = bool(costs)
    compute_header = " compute |" if with_compute else ""
    against_header = (f" against {args.against} at equal samples: translation / moving contact |"
                      if reference is not None else "")
    print(f"| run | steps | samples |{compute_header} translation (m) | rotation (°) "
          f"| one step: free flight / moving contact / rest / impacts (mm) |{against_header}")
    print("|---|---|---|" + ("---|" if with_compute else "") + "---|---|---|"
          + ("---|" if reference is not None else ""))
    for name, validations in runs:
        for entry in validations:
            seen = entry["samples"]
            samples = f"{seen / 1000:.0f}k" if seen is not None else "?"
            compute = ""
            if with_compute:
                compute = f" {seen * cost_of[name] / 1000:.0f}k |" if seen is not None else " ? |"
            one_step = " / ".join(
                f"{1e3 * entry[key]:.2f}" if key in entry else "-"
                for key in ("valid_one_step_m_free_flight", "valid_one_step_m_moving_contact",
                            "valid_one_step_m_rest", "valid_one_step_m_impacts"))
            difference = f" {against(name, entry)} |" if reference is not None else ""
            print(f"| {name} | {entry['step']} | {samples} |{compute} "
                  f"{entry['valid_translation_m']:.3f} | {entry['valid_rotation_deg']:.1f} "
                  f"| {one_step} |{difference}")
    for line in pooled:
        print(f"\n{line}")

    fits = {}
    if args.fit or args.plot:
        for name, validations in runs:
            if any(v["samples"] is None for v in validations):
                print(f"training-log.py: {name}: samples unknown (give --batch {name}=B)",
                      file=sys.stderr)
                return 1
            points = [(v["samples"], v["valid_translation_m"]) for v in validations
                      if v["samples"] > 0 and v["samples"] >= args.fit_from
                      and v["valid_translation_m"] > 0]
            if len(points) < 2 or len({s for s, _ in points}) < 2:
                print(f"training-log.py: {name}: fewer than 2 validations from "
                      f"{format_count(args.fit_from)} samples on: no fit", file=sys.stderr)
                continue
            fits[name] = (points, power_law_fit(*zip(*points)))
    if args.fit and fits:
        print()
        print("| run | validations fitted | slope of ln(error) vs ln(samples) | fit at the last "
              "| at 10× the samples | at 100× |")
        print("|---|---|---|---|---|---|")
        for name, (points, (centre, slope, slope_error)) in fits.items():
            last = max(s for s, _ in points)

            def reach(factor):
                samples = last * factor
                text = f"{power_law_at(centre, slope, samples):.3f} m ({format_count(samples)})"
                if slope_error is not None:
                    low, high = sorted(power_law_at(centre, slope + sign * slope_error, samples)
                                       for sign in (-1, 1))
                    text += f", {low:.3f}–{high:.3f}"
                return text

            spread = f" ± {slope_error:.3f}" if slope_error is not None else ""
            at_last = power_law_at(centre, slope, last)
            print(f"| {name} | {len(points)} ({format_count(min(s for s, _ in points))}–"
                  f"{format_count(last)}) | {slope:.3f}{spread} | {at_last:.3f} m "
                  f"| {reach(10)} | {reach(100)} |")
    if any(entries for _, entries in stress_runs):
        print("\n| run | step | samples | stress case | network alone | world |")
        print("|---|---|---|---|---|---|")
        for name, entries in stress_runs:
            for entry in entries:
                seen = entry.get("samples")
                samples = f"{seen / 1000:.0f}k" if seen is not None else "?"
                for case, by_simulator in entry["stress"].items():
                    print(f"| {name} | {entry['step']} | {samples} | {case} "
                          f"| {stress_cell(by_simulator.get('network_alone', {}))} "
                          f"| {stress_cell(by_simulator.get('world', {}))} |")

    if args.plot:
        try:
            import matplotlib
            matplotlib.use("Agg")
            import matplotlib.pyplot as plt
        except ImportError:
            print("training-log.py: --plot needs matplotlib (apt-get install python3-matplotlib)",
                  file=sys.stderr)
            return 1
        figure, axes = plt.subplots(figsize=(7, 4.5))
        for name, validations in runs:
            cost = cost_of[name]
            known = [(v["samples"] * cost, v["valid_translation_m"]) for v in validations
                     if v["samples"]]
            if not known:
                continue
            line, = axes.plot(*zip(*known), "o-", markersize=3, label=name)
            if name in fits:
                points, (centre, slope, _) = fits[name]
                ends = [min(s for s, _ in points), 100 * max(s for s, _ in points)]
                axes.plot([cost * s for s in ends], [power_law_at(centre, slope, s) for s in ends],
                          "--", color=line.get_color(), label=f"{name}: fit, slope {slope:.2f}")
        axes.set_xscale("log")
        axes.set_yscale("log")
        axes.set_xlabel("compute (samples of the runs without --cost)" if with_compute
                        else "samples seen")
        axes.set_ylabel("validation translation error (m)")
        axes.grid(True, which="both", alpha=0.3)
        axes.legend(fontsize=8)
        figure.tight_layout()
        temporary = args.plot.with_name(args.plot.name + ".tmp.png")
        figure.savefig(temporary, dpi=110)
        temporary.replace(args.plot)
        print(f"\nplot: {args.plot}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
