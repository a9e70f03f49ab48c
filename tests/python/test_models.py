"""Models from Python: the same rollouts and figures as the command line."""

import json
import subprocess

import numpy as np

import fignet


def test_a_loaded_model_describes_itself(model):
    assert model.config["preset"] == "small"
    assert model.history == 2
    assert model.parameter_count > 100_000
    assert abs(model.time_step - 1 / 48) < 1e-12
    np.testing.assert_array_equal(model.gravity, [0, 0, -10])
    assert "small" in repr(model)
    # The shipped model records its data's materials: MOVi-A's metal and rubber, Kubric's floor.
    np.testing.assert_allclose(model.config["friction"], (0.4, 0.8), rtol=1e-6)
    np.testing.assert_allclose(model.config["restitution"], (0.3, 0.7), rtol=1e-6)
    np.testing.assert_allclose(model.config["floor_friction"], (0.3, 0.3), rtol=1e-6)
    np.testing.assert_allclose(model.config["floor_restitution"], (0.5, 0.5), rtol=1e-6)


def test_a_widened_model_names_its_hidden_widths(tmp_path, cli, model):
    # The shipped model's hidden layers are its latent width: nothing more to say.
    assert "hidden" not in repr(model)
    data, out = tmp_path / "scenes.h5", tmp_path / "wide.h5"
    fignet.generate("movi-a", count=2, seed=5, frames=8, path=data)
    train = [cli, "train", "--data", data, "--set", "batch_size=2", "--set", "statistics_warmup=0",
             "--threads", "1", "--out", out]
    subprocess.run([*train, "--preset", "small", "--steps", "1"], check=True, capture_output=True)
    subprocess.run([*train, "--resume", "--steps", "2", "--widen-object-hidden", "96"], check=True,
                   capture_output=True)
    wide = fignet.load_model(out)
    assert wide.config["hidden_size"] == 0 and wide.config["object_hidden_size"] == 96
    assert "latent 64, hidden 64, object hidden 96," in repr(wide)


def test_evaluation_equals_fignet_eval_on_the_same_file(tmp_path, cli, model, source_dir):
    data = tmp_path / "scenes.h5"
    truths = fignet.generate("movi-a", count=2, seed=21, frames=16, path=data)
    report = tmp_path / "eval.json"
    subprocess.run(
        [cli, "eval", "--model", source_dir / "models" / "movi-a-small.h5", "--data", data,
         "--threads", "1", "--json", report],
        check=True, capture_output=True,
    )
    (run,) = [r for r in json.loads(report.read_text())["runs"] if r["name"] != "ballistic"]
    ours = fignet.evaluate(model, truths)
    for key in ("mean_translation_m", "final_translation_m", "mean_rotation_deg", "travel_ratio"):
        assert abs(ours[key] - run[key]) <= 1e-9 * max(1.0, abs(run[key])), key
    np.testing.assert_allclose(ours["translation_per_frame_m"], run["translation_per_frame_m"],
                               rtol=1e-9, atol=1e-12)
    # The same through rollout() and rollout_errors(), one trajectory at a time.
    errors = [fignet.rollout_errors(fignet.rollout(model, t), t) for t in truths]
    assert abs(np.mean([e["mean_translation"] for e in errors]) - run["mean_translation_m"]) <= 1e-9
    # Travel: what the rollouts' centres cover over the truth's, summed over the trajectories.
    travel = sum(e["predicted_travel"] for e in errors) / sum(e["true_travel"] for e in errors)
    assert abs(travel - run["travel_ratio"]) <= 1e-9


def test_averaged_evaluation_equals_fignet_eval_with_the_same_turns_and_mirror(
        tmp_path, cli, model, source_dir):
    data = tmp_path / "scenes.h5"
    truths = fignet.generate("movi-a", count=2, seed=21, frames=12, path=data)
    report = tmp_path / "eval.json"
    subprocess.run(
        [cli, "eval", "--model", source_dir / "models" / "movi-a-small.h5", "--data", data,
         "--threads", "1", "--turns", "2", "--mirror", "--json", report],
        check=True, capture_output=True,
    )
    (run,) = [r for r in json.loads(report.read_text())["runs"] if r["name"] != "ballistic"]
    averaged = fignet.evaluate(model, truths, turns=2, mirror=True)
    plain = fignet.evaluate(model, truths)
    for key in ("mean_translation_m", "mean_rotation_deg"):
        assert abs(averaged[key] - run[key]) <= 1e-9 * max(1.0, abs(run[key])), key
    # Four predictions a step averaged are not the one: the options reached the predictor.
    assert abs(averaged["mean_translation_m"] - plain["mean_translation_m"]) > 1e-6


def test_rollouts_keep_the_given_frames_and_match_one_step_predictions(model):
    (truth,) = fignet.generate("movi-a", count=1, seed=8, frames=12)
    predicted = fignet.rollout(model, truth, given_frames=5, frames=10)
    assert predicted.num_frames == 10
    np.testing.assert_array_equal(predicted.positions[:5], truth.positions[:5])
    assert not np.array_equal(predicted.positions[5:], truth.positions[5:10])
    # The first predicted frame is a one-step prediction from the truth.
    step = model.predict(truth, 4)
    np.testing.assert_allclose(step["positions"], predicted.positions[5], rtol=0, atol=1e-12)
    nodes = sum(truth.vertices(o).shape[0] for o in range(truth.num_objects))
    assert step["accelerations"].shape == (nodes, 3)


def test_pose_errors_on_numpy_equal_rollout_errors(model):
    (truth,) = fignet.generate("movi-a", count=1, seed=6, frames=10)
    predicted = fignet.rollout(model, truth)
    a = fignet.rollout_errors(predicted, truth, first_predicted=3)
    b = fignet.pose_errors(predicted.positions, predicted.quaternions, truth.positions,
                           truth.quaternions, first_predicted=3, kinematic=list(truth.kinematic))
    np.testing.assert_array_equal(a["translation"], b["translation"])
    assert a["mean_rotation"] == b["mean_rotation"]
    # An error of exactly 1 m on every object from frame 3 on.
    shifted = truth.positions.copy()
    shifted[3:, :, 0] += 1.0
    c = fignet.pose_errors(shifted, truth.quaternions, truth.positions, truth.quaternions)
    np.testing.assert_allclose(c["translation"][3:], 1.0, rtol=1e-12)
    assert c["mean_rotation"] < 1e-9


def test_bf16_products_move_an_evaluation_a_little_or_are_refused_with_the_reason(model):
    (truth,) = fignet.generate("movi-a", count=1, seed=21, frames=12)
    plain = fignet.evaluate(model, [truth])
    try:
        fignet.set_bf16_products(True)
    except fignet.ConfigError as refused:
        assert "set_bf16_products" in str(refused)
        assert not fignet.bf16_products()
        return
    try:
        assert fignet.bf16_products()
        rounded = fignet.evaluate(model, [truth])
    finally:
        fignet.set_bf16_products(False)
    assert not fignet.bf16_products()
    # Operands rounded to 8 significant bits: another rollout, of about the same error.
    assert rounded["mean_translation_m"] != plain["mean_translation_m"]
    assert abs(rounded["mean_translation_m"] - plain["mean_translation_m"]) < 0.5 * max(
        plain["mean_translation_m"], 0.01)
    assert fignet.evaluate(model, [truth])["mean_translation_m"] == plain["mean_translation_m"]
