"""The scripts of scripts/: training-log.py, which reads `fignet train`'s logs, and the
measurements of model-card.sh."""

import json
import math
import os
import re
import subprocess
import sys


def run_training_log(source_dir, *args):
    return subprocess.run([sys.executable, str(source_dir / "scripts" / "training-log.py"), *args],
                          capture_output=True, text=True)


def write_log(path, validations):
    """A log of (samples, translation) validations at batch 8, with loss lines between them."""
    with open(path, "w") as log:
        for samples, translation in validations:
            log.write(json.dumps({"step": samples // 8, "samples": samples, "loss": 0.5}) + "\n")
            log.write(json.dumps({"step": samples // 8, "samples": samples,
                                  "valid_translation_m": translation,
                                  "valid_rotation_deg": 40.0}) + "\n")


def table_rows(stdout):
    """The cells of the first table's rows (below its header and rule), stripped."""
    return [[cell.strip() for cell in line.strip("|").split("|")]
            for line in stdout.splitlines()[2:] if line.startswith("| ")]


def fit_row(stdout, name):
    rows = [line for line in stdout.splitlines() if line.startswith(f"| {name} |")
            and "validations fitted" not in line and "(" in line.split("|")[2]]
    assert len(rows) == 1, stdout
    return [cell.strip() for cell in rows[0].strip("|").split("|")]


def test_fit_recovers_an_exact_power_law(source_dir, tmp_path):
    # error = 3·samples^-0.3 exactly: the slope is -0.3 with no spread, and the extrapolations
    # are the law's own values.
    samples = [25_000 * k for k in range(1, 9)]
    write_log(tmp_path / "law.h5.log.jsonl", [(s, 3.0 * s ** -0.3) for s in samples])
    result = run_training_log(source_dir, "--fit", str(tmp_path / "law.h5.log.jsonl"))
    assert result.returncode == 0, result.stderr
    cells = fit_row(result.stdout, "law")
    assert cells[1].startswith("8 (25k–200k)")
    assert cells[2] == "-0.300 ± 0.000"
    last = samples[-1]
    assert cells[3] == f"{3.0 * last ** -0.3:.3f} m"
    ten = 3.0 * (10 * last) ** -0.3
    assert cells[4].startswith(f"{ten:.3f} m (2.00M), {ten:.3f}–{ten:.3f}")


def test_fit_from_leaves_out_the_early_validations(source_dir, tmp_path):
    # Two laws joined at 100k: fitting from 100k on sees only the second one's slope.
    early = [(s, 10.0 * s ** -0.5) for s in (25_000, 50_000, 75_000)]
    joint = 10.0 * 100_000 ** -0.5 / 100_000 ** -0.1
    late = [(s, joint * s ** -0.1) for s in (100_000, 200_000, 400_000, 800_000)]
    write_log(tmp_path / "two.h5.log.jsonl", early + late)
    whole = fit_row(run_training_log(source_dir, "--fit", str(tmp_path / "two.h5.log.jsonl")).stdout,
                    "two")
    tail = fit_row(run_training_log(source_dir, "--fit", "--fit-from", "100k",
                                    str(tmp_path / "two.h5.log.jsonl")).stdout, "two")
    assert tail[2] == "-0.100 ± 0.000"
    assert float(whole[2].split()[0]) < -0.15


def test_the_slope_error_is_the_least_squares_one(source_dir, tmp_path):
    # Scattered points: the slope and its standard error against the textbook formulas.
    points = [(20_000, 1.9), (40_000, 1.4), (60_000, 1.6), (80_000, 1.1), (100_000, 1.2)]
    write_log(tmp_path / "noisy.h5.log.jsonl", points)
    cells = fit_row(run_training_log(source_dir, "--fit",
                                     str(tmp_path / "noisy.h5.log.jsonl")).stdout, "noisy")
    xs = [math.log(s) for s, _ in points]
    ys = [math.log(e) for _, e in points]
    mx, my = sum(xs) / 5, sum(ys) / 5
    sxx = sum((x - mx) ** 2 for x in xs)
    slope = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sxx
    residual = sum((y - my - slope * (x - mx)) ** 2 for x, y in zip(xs, ys))
    assert cells[2] == f"{slope:.3f} ± {math.sqrt(residual / 3 / sxx):.3f}"


def test_cost_puts_runs_on_a_common_compute_axis(source_dir, tmp_path):
    # A run whose samples cost 3x, and the longest matching prefix decides between two costs.
    write_log(tmp_path / "wide.h5.log.jsonl", [(10_000, 2.0), (20_000, 1.5)])
    write_log(tmp_path / "wide-slow.h5.log.jsonl", [(10_000, 2.5)])
    write_log(tmp_path / "base.h5.log.jsonl", [(30_000, 1.8)])
    result = run_training_log(source_dir, "--cost", "wide=3", "--cost", "wide-slow=4",
                              *(str(tmp_path / f"{n}.h5.log.jsonl")
                                for n in ("wide", "wide-slow", "base")))
    assert result.returncode == 0, result.stderr
    header = result.stdout.splitlines()[0]
    assert "| samples | compute |" in header
    rows = {(cells[0], cells[1]): cells for cells in table_rows(result.stdout)}
    assert rows[("wide", "2500")][2:4] == ["20k", "60k"]
    assert rows[("wide-slow", "1250")][2:4] == ["10k", "40k"]
    assert rows[("base", "3750")][2:4] == ["30k", "30k"]
    # Without --cost there is no compute column; a cost must be a positive number.
    plain = run_training_log(source_dir, str(tmp_path / "base.h5.log.jsonl"))
    assert "compute" not in plain.stdout.splitlines()[0]
    for bad in ("wide=0", "wide=lots", "=2"):
        result = run_training_log(source_dir, "--cost", bad, str(tmp_path / "base.h5.log.jsonl"))
        assert result.returncode == 2 and f"--cost {bad}" in result.stderr


def test_against_gives_each_run_its_difference_at_equal_samples(source_dir, tmp_path):
    # Per cent from the reference at the same samples; "—" where it has no validation there; the
    # reference named by a prefix that fits one run only, and refused where it fits none or two.
    write_log(tmp_path / "shipped.h5.log.jsonl", [(10_000, 2.0), (20_000, 1.0)])
    write_log(tmp_path / "lever.h5.log.jsonl", [(10_000, 1.5), (20_000, 1.1), (30_000, 0.9)])
    logs = [str(tmp_path / f"{n}.h5.log.jsonl") for n in ("shipped", "lever")]
    result = run_training_log(source_dir, "--against", "ship", *logs)
    assert result.returncode == 0, result.stderr
    assert "against ship at equal samples" in result.stdout.splitlines()[0]
    cells = {(row[0], row[2]): row[-1] for row in table_rows(result.stdout)}
    assert cells[("lever", "10k")] == "−25.0 % / -", result.stdout
    assert cells[("lever", "20k")] == "+10.0 % / -"
    assert cells[("lever", "30k")] == "—"
    assert cells[("shipped", "10k")] == cells[("shipped", "20k")] == "reference"
    for name, said in (("nothing", "no run"), ("", "2 runs")):
        result = run_training_log(source_dir, "--against", name, *logs)
        assert result.returncode == 2 and said in result.stderr, result.stderr


def write_scene_log(path, validations):
    """A log of (samples, per-trajectory translations) validations, as fignet train writes them
    since it records each validation scene's error."""
    with open(path, "w") as log:
        for samples, errors in validations:
            log.write(json.dumps({"step": samples // 8, "samples": samples,
                                  "valid_translation_m": sum(errors) / len(errors),
                                  "valid_rotation_deg": 40.0,
                                  "valid_per_trajectory_translation_m": errors}) + "\n")


def test_against_compares_scene_by_scene_where_logs_have_each_scenes_error(source_dir, tmp_path):
    # Every scene 10 % lower: every resample says −10 %, and the run wins all five scenes. One
    # scene three times worse and the rest 10 % lower: nearly level, an interval across 0.
    base = [0.2, 0.5, 1.0, 0.3, 0.8]
    write_scene_log(tmp_path / "base.h5.log.jsonl", [(10_000, base), (20_000, base)])
    write_scene_log(tmp_path / "lower.h5.log.jsonl",
                    [(10_000, [0.9 * e for e in base]), (20_000, [0.9 * e for e in base])])
    mixed = [0.9] * 19 + [3.0]
    write_scene_log(tmp_path / "flat.h5.log.jsonl", [(10_000, [1.0] * 20)])
    write_scene_log(tmp_path / "mixed.h5.log.jsonl", [(10_000, mixed)])
    logs = [str(tmp_path / f"{n}.h5.log.jsonl") for n in ("base", "lower")]
    result = run_training_log(source_dir, "--against", "base", *logs)
    assert result.returncode == 0, result.stderr
    cells = {(row[0], row[2]): row[-1] for row in table_rows(result.stdout)}
    assert cells[("lower", "10k")] == "−10.0 % [−10.0, −10.0] 5/5 / -", result.stdout
    assert ("lower against base, scene by scene over the 2 validation(s) both have at equal "
            "samples (5 scenes, each summed over them): translation −10.0 % [−10.0, −10.0] 5/5"
            in result.stdout)
    result = run_training_log(source_dir, "--side-by-side", "--against", "flat",
                              *(str(tmp_path / f"{n}.h5.log.jsonl") for n in ("flat", "mixed")))
    assert result.returncode == 0, result.stderr
    line = [text for text in result.stdout.splitlines() if text.startswith("mixed against")][0]
    match = re.search(r"translation ([+−]\d+\.\d) % \[([+−]\d+\.\d), ([+−]\d+\.\d)\] 19/20", line)
    assert match, line
    relative, low, high = (float(g.replace("−", "-")) for g in match.groups())
    assert relative == round(100 * (sum(mixed) / 20 - 1), 1) and low < 0 < high
    # Logs from before the per-scene errors keep the plain per cent.
    write_log(tmp_path / "old.h5.log.jsonl", [(10_000, 0.5)])
    result = run_training_log(source_dir, "--against", "old", str(tmp_path / "old.h5.log.jsonl"),
                              logs[0])
    cells = {(row[0], row[2]): row[-1] for row in table_rows(result.stdout)}
    assert cells[("base", "10k")] == "+12.0 % / -", result.stdout
    assert "scene by scene" not in result.stdout


def test_batch_counts_samples_of_old_logs_by_the_longest_prefix(source_dir, tmp_path):
    # Logs from before the "samples" field: steps × the batch given for the longest prefix of
    # the run's name, as --cost decides.
    for name in ("w128", "w128-lr"):
        with open(tmp_path / f"{name}.h5.log.jsonl", "w") as log:
            log.write(json.dumps({"step": 1000, "valid_translation_m": 1.0,
                                  "valid_rotation_deg": 40.0}) + "\n")
    result = run_training_log(source_dir, "--batch", "w128=8", "--batch", "w128-lr=16",
                              *(str(tmp_path / f"{n}.h5.log.jsonl") for n in ("w128", "w128-lr")))
    assert result.returncode == 0, result.stderr
    rows = {cells[0]: cells for cells in table_rows(result.stdout)}
    assert rows["w128"][2] == "8k" and rows["w128-lr"][2] == "16k", result.stdout


def test_stress_lines_get_a_table_of_their_own(source_dir, tmp_path):
    # `fignet train --valid-stress` lines: drift for a case started at rest, error for the others,
    # the first step's fall where logged (not in logs before it was), the late speed, and a run
    # that went non-finite said so.
    log = tmp_path / "pile.h5.log.jsonl"
    write_log(log, [(8000, 1.0)])
    with open(log, "a") as out:
        out.write(json.dumps({"step": 1000, "samples": 8000, "stress": {
            "10-object pile at rest": {
                "network_alone": {"finite": True, "drift_m": 38.85, "drift_deg": 161.7,
                                  "late_speed_m_s": 4.81, "lowest_m": -0.05},
                "world": {"finite": True, "drift_m": 0.0123, "drift_deg": 2.0,
                          "first_step_fall": 0.004, "late_speed_m_s": 0.0, "lowest_m": 0.0}},
            "canonical: cube dropped from 1 m": {
                "network_alone": {"finite": False},
                "world": {"finite": True, "error_m": 0.109, "late_speed_m_s": 0.0,
                          "lowest_m": 0.003}}}}) + "\n")
    result = run_training_log(source_dir, str(log))
    assert result.returncode == 0, result.stderr
    rows = {cells[3]: cells for cells in table_rows(result.stdout) if len(cells) == 6}
    assert rows["10-object pile at rest"][1:3] == ["1000", "8k"], result.stdout
    assert rows["10-object pile at rest"][4] == "38.850 m / 161.7°, late 4.81 m/s"
    assert rows["10-object pile at rest"][5] == "0.012 m / 2.0°, first step +0.00, late 0.00 m/s"
    assert rows["canonical: cube dropped from 1 m"][4] == "not finite"
    assert rows["canonical: cube dropped from 1 m"][5] == "error 0.109 m, late 0.00 m/s"


def test_bad_logs_and_counts_are_named(source_dir, tmp_path):
    bad = tmp_path / "bad.log.jsonl"
    bad.write_text('{"step": 1}\nnot json\n')
    result = run_training_log(source_dir, str(bad))
    assert result.returncode == 1
    assert re.search(r"bad\.log\.jsonl:2: not a JSON line", result.stderr)
    result = run_training_log(source_dir, "--fit", "--fit-from", "lots", str(bad))
    assert result.returncode == 2
    assert "'lots' is not a sample count" in result.stderr
    result = run_training_log(source_dir, str(tmp_path / "missing.log.jsonl"))
    assert result.returncode == 1 and "missing.log.jsonl" in result.stderr


def test_model_card_names_what_it_lacks(source_dir, tmp_path):
    # Checked before any measurement starts: the arguments, the model, the tool, the test split
    # (looked for relative to the working directory, here one without data/).
    script = str(source_dir / "scripts" / "model-card.sh")
    env = dict(os.environ, FIGNET=os.environ["FIGNET_CLI"])

    def card(*args, **changes):
        return subprocess.run(["bash", script, *args], capture_output=True, text=True,
                              cwd=tmp_path, env=dict(env, **changes))

    result = card()
    assert result.returncode == 2 and "usage:" in result.stderr
    result = card("missing.h5")
    assert result.returncode == 2 and "no model file 'missing.h5'" in result.stderr
    model = str(source_dir / "models" / "movi-a-small.h5")
    result = card(model, FIGNET=str(tmp_path / "none"))
    assert result.returncode == 2 and "no fignet tool" in result.stderr
    result = card(model)
    assert result.returncode == 2 and "data/movi-a/test.h5 is missing" in result.stderr
    assert not (tmp_path / "out").exists()


def load_rest_response(source_dir):
    """scripts/rest-response.py as a module (its file name is not an importable name)."""
    import importlib.util
    spec = importlib.util.spec_from_file_location(
        "rest_response", source_dir / "scripts" / "rest-response.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_rest_response_stacks_movi_cubes_as_trained(source_dir):
    # The stack is built of MOVi-A's own cube (each side split 3×3), not an 8-corner cube the
    # network never saw, and the table has one row per predicted frame and a column per cube.
    import numpy as np
    rest_response = load_rest_response(source_dir)
    vertices, faces = rest_response.movi_cube_mesh()
    assert vertices.shape == (56, 3) and faces.shape == (108, 3)
    assert np.allclose(vertices.min(axis=0), -0.7) and np.allclose(vertices.max(axis=0), 0.7)
    result = subprocess.run([sys.executable, str(source_dir / "scripts" / "rest-response.py"),
                             str(source_dir / "models" / "movi-a-small.h5"), "--levels", "3",
                             "--frames", "2"], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    rows = [line for line in result.stdout.splitlines() if re.match(r"\| \d+ \|", line)]
    assert len(rows) == 2 and all(len(row.strip("|").split("|")) == 4 for row in rows), result.stdout


def test_rest_response_perturbation_moves_a_falling_cube_in_proportion(source_dir):
    # --perturb moves only the history the network reads: a cube in free flight, 10 m up, answers
    # a perturbation σ by a few σ (x' = 2x − x₋₁ + a), where a resting stack's tie would answer
    # micrometres; and the table has a row per draw and a column per cube.
    import numpy as np
    import fignet
    rest_response = load_rest_response(source_dir)
    model = fignet.load_model(str(source_dir / "models" / "movi-a-small.h5"))
    vertices, faces = rest_response.movi_cube_mesh()
    frames = model.history + 2
    falling = fignet.Trajectory(time_step=model.time_step, gravity=model.gravity)
    heights = 10.0 - 0.5 * 10.0 * (np.arange(frames) * model.time_step) ** 2
    positions = np.stack([np.zeros(frames), np.zeros(frames), heights], axis=1)
    falling.add_object(vertices, faces, positions, np.tile([1.0, 0, 0, 0], (frames, 1)), mass=3.0)
    sigma = 1e-6
    response = rest_response.one_step_response(model, falling, sigma, draws=4)
    assert response.shape == (4, 1)
    assert np.all(response > 0.3 * sigma) and np.all(response < 20 * sigma), response
    result = subprocess.run([sys.executable, str(source_dir / "scripts" / "rest-response.py"),
                             str(source_dir / "models" / "movi-a-small.h5"), "--levels", "2",
                             "--perturb", "1e-10", "--draws", "3"], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    rows = [line for line in result.stdout.splitlines() if re.match(r"\| \d+ \|", line)]
    assert len(rows) == 3, result.stdout
    assert all(len(row.strip("|").split("|")) == 3 for row in rows), result.stdout
    bad = subprocess.run([sys.executable, str(source_dir / "scripts" / "rest-response.py"),
                          str(source_dir / "models" / "movi-a-small.h5"), "--perturb", "-1"],
                         capture_output=True, text=True)
    assert bad.returncode != 0 and "--perturb must be > 0" in bad.stderr


def test_side_by_side_puts_runs_next_to_each_other_at_shared_samples(source_dir, tmp_path):
    # Two runs validated at 10k and 20k, one also at 30k: only the shared rows, the lower error in
    # bold, the per cent from the reference, and each rest figure of the network alone in the
    # logs' order, scaled to its unit; a case one log lacks is "—".
    def stress(lowest, stack, pile):
        alone = {"finite": True, "late_speed_m_s": 0.0, "drift_deg": 0.1}
        cases = {"MOVi cube at rest": {"network_alone": {**alone, "drift_m": 0.01,
                                                          "lowest_m": lowest}},
                 "stack of 3 cubes": {"network_alone": {**alone, "drift_m": stack}},
                 "stack of 5 cubes": {"network_alone": {**alone, "drift_m": 2 * stack}}}
        if pile is not None:
            cases["10-object pile at rest"] = {"network_alone": {**alone, "drift_m": pile}}
        return cases

    runs = {"base": [(10_000, 2.0, -0.05, 0.04, 1.5), (20_000, 1.0, 0.002, 0.03, 0.2)],
            "lever": [(10_000, 1.5, 0.001, 0.02, None), (20_000, 1.1, 0.003, 0.01, None),
                      (30_000, 0.9, 0.004, 0.01, None)]}
    for name, points in runs.items():
        with open(tmp_path / f"{name}.h5.log.jsonl", "w") as log:
            for samples, translation, lowest, stack, pile in points:
                log.write(json.dumps({"step": samples // 8, "samples": samples,
                                      "valid_translation_m": translation,
                                      "valid_rotation_deg": 40.0}) + "\n")
                log.write(json.dumps({"step": samples // 8, "samples": samples,
                                      "stress": stress(lowest, stack, pile)}) + "\n")
    result = run_training_log(source_dir, "--side-by-side", "--against", "base",
                              *(str(tmp_path / f"{n}.h5.log.jsonl") for n in ("base", "lever")))
    assert result.returncode == 0, result.stderr
    assert "base / lever" in result.stdout.splitlines()[0]
    rows = table_rows(result.stdout)
    assert [row[0] for row in rows] == ["10k", "20k"], result.stdout
    assert rows[0][1:] == ["2.000 / **1.500**", "−25.0 %", "−5.0 / +0.1",
                           "4.0, 8.0, — / 2.0, 4.0, —", "1.50 / —"]
    assert rows[1][1:3] == ["**1.000** / 1.100", "+10.0 %"]
    assert rows[1][3] == "+0.2 / +0.3"


def write_eval(path, data, name, translations, rotation=30.0):
    """A `fignet eval --json` result with one FIGNet run and the ballistic baseline."""
    per_trajectory = [{"mean_translation_m": t, "mean_rotation_deg": rotation}
                      for t in translations]
    runs = [{"name": name, "kind": "FIGNet", "per_trajectory": per_trajectory},
            {"name": "ballistic", "kind": "constant velocity + gravity",
             "per_trajectory": per_trajectory}]
    path.write_text(json.dumps({"data": [data], "trajectories": len(translations), "runs": runs}))


def run_paired_evals(source_dir, *args):
    return subprocess.run([sys.executable, str(source_dir / "scripts" / "paired-evals.py"),
                           *map(str, args)], capture_output=True, text=True)


def test_paired_evals_compares_scene_by_scene(source_dir, tmp_path):
    # Every scene halved: -50 % with a degenerate interval, lower on all 6, sign test 2/64; the
    # rotations are tied everywhere, so no scene counts either way.
    write_eval(tmp_path / "a.json", "test.h5", "A.h5", [1.0, 2.0, 0.5, 3.0, 1.5, 0.25])
    write_eval(tmp_path / "b.json", "test.h5", "B.h5", [0.5, 1.0, 0.25, 1.5, 0.75, 0.125])
    result = run_paired_evals(source_dir, tmp_path / "a.json", tmp_path / "b.json")
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith("6 scenes of test.h5;")
    translation = [line for line in result.stdout.splitlines() if line.startswith("mean trans")]
    assert len(translation) == 1, result.stdout
    assert "-50.0% [-50.0, -50.0]  lower on 6/6  p=0.031" in translation[0]
    assert "+0.0% [+0.0, +0.0]  lower on 0/0  p=1" in result.stdout


def test_paired_evals_names_what_does_not_match(source_dir, tmp_path):
    write_eval(tmp_path / "a.json", "test.h5", "A.h5", [1.0, 2.0])
    write_eval(tmp_path / "b.json", "other.h5", "B.h5", [1.0, 2.0])
    result = run_paired_evals(source_dir, tmp_path / "a.json", tmp_path / "b.json")
    assert result.returncode == 1 and "different scenes" in result.stderr
    result = run_paired_evals(source_dir, tmp_path / "a.json", tmp_path / "a.json", "--run", "C.h5")
    assert result.returncode == 1
    assert "has no run 'C.h5' (its runs: A.h5, ballistic)" in result.stderr
    result = run_paired_evals(source_dir, tmp_path / "a.json", tmp_path / "missing.json")
    assert result.returncode == 1 and "cannot read" in result.stderr and "missing.json" in result.stderr


def write_compare(path, world_translations):
    """A `fignet compare --json` result: Bullet's runs and a model's two rows, scene by scene."""
    def run(name, kind, translations):
        return {"name": name, "kind": kind, "per_trajectory": [
            {"mean_translation_m": t, "mean_rotation_deg": 10.0 * t} for t in translations]}
    scenes = len(world_translations)
    runs = [run("Bullet 240 Hz", "ground truth", [0.0] * scenes),
            run("FIGNet m.h5, network alone", "FIGNet", [1.0] * scenes),
            run("FIGNet m.h5", "FIGNet", world_translations),
            run("Bullet 48 Hz", "Bullet", [0.5] * scenes)]
    path.write_text(json.dumps({"data": "test.h5", "scene_count": scenes, "runs": runs}))


def test_paired_evals_reads_compare_results(source_dir, tmp_path):
    # Two compare results (other world options): the world's row picked by name, 3 of 4 scenes
    # lower by a quarter, one level.
    write_compare(tmp_path / "a.json", [1.0, 2.0, 4.0, 1.0])
    write_compare(tmp_path / "b.json", [0.75, 1.5, 3.0, 1.0])
    result = run_paired_evals(source_dir, tmp_path / "a.json", tmp_path / "b.json",
                              "--run", "FIGNet m.h5", "--reference-run", "FIGNet m.h5")
    assert result.returncode == 0, result.stderr
    assert "4 scenes of test.h5;" in result.stdout  # compare names one file, eval a list
    assert "mean translation (m): 2.0000 -> 1.5625  -21.9%" in result.stdout
    assert "lower on 3/3" in result.stdout
    # By default each side is its first FIGNet run: the network alone, level here.
    result = run_paired_evals(source_dir, tmp_path / "a.json", tmp_path / "b.json")
    assert result.returncode == 0 and "+0.0% [+0.0, +0.0]  lower on 0/0" in result.stdout
