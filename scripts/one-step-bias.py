#!/usr/bin/env python3
"""A model's one-step predictions from the truth, split by where each body is and how fast it moves.

For every object-step of the first N trajectories: the network's next-frame velocity against the
truth's, as accelerations (m/s²). On the floor, along the body's horizontal motion, a mean error
below zero is a braking bias (the body slows more than the truth); the squared-error shares say
which regime carries the one-step error. Needs the Python module (PYTHONPATH=build/release/python)
and numpy.

    scripts/one-step-bias.py models/movi-a-small.h5 data/movi-a/test.h5 --trajectories 100
"""
import argparse
import sys

import numpy as np

import fignet

FLOOR_CONTACT_M = 0.02  # lowest vertex within this of the floor: on the floor
AIR_M = 0.10  # lowest vertex above this: clear of the floor (other bodies may touch it)
IMPACT_G = 2.0  # an impact: the true acceleration differs from gravity by this many g (fignet eval's)
SPEED_BANDS = [(0, 0.05), (0.05, 0.3), (0.3, 1), (1, 2), (2, 4), (4, float("inf"))]


def rotation(q):
    w, x, y, z = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


def object_steps(model, trajectories):
    """Rows of (velocity into the step, true and predicted velocity out of it, lowest vertex)."""
    dt = model.time_step
    rows = []
    for index, trajectory in enumerate(trajectories):
        positions, quaternions = trajectory.positions, trajectory.quaternions
        for frame in range(model.history, trajectory.num_frames - 1):
            predicted = np.asarray(model.predict(trajectory, frame)["positions"])
            for body in range(trajectory.num_objects):
                if trajectory.kinematic[body]:
                    continue
                here = positions[frame, body]
                vertices = np.asarray(trajectory.vertices(body)) @ rotation(quaternions[frame, body]).T
                rows.append(np.concatenate([
                    (here - positions[frame - 1, body]) / dt,
                    (positions[frame + 1, body] - here) / dt,
                    (predicted[body] - here) / dt,
                    [vertices[:, 2].min() + here[2] - trajectory.floor_height],
                ]))
        print(f"\r{index + 1}/{len(trajectories)} trajectories", end="", file=sys.stderr)
    print(file=sys.stderr)
    return np.array(rows)


def report(rows, dt, gravity):
    v, v_true, v_pred, lowest = rows[:, 0:3], rows[:, 3:6], rows[:, 6:9], rows[:, 9]
    speed = np.linalg.norm(v[:, :2], axis=1)
    direction = v[:, :2] / np.maximum(speed, 1e-9)[:, None]
    along_true = ((v_true[:, :2] - v[:, :2]) * direction).sum(1) / dt
    along_pred = ((v_pred[:, :2] - v[:, :2]) * direction).sum(1) / dt
    impact = np.linalg.norm((v_true - v) / dt - gravity, axis=1) > IMPACT_G * np.linalg.norm(gravity)
    on_floor, in_air = lowest < FLOOR_CONTACT_M, lowest > AIR_M
    print(f"{len(rows)} object-steps\n")
    print("On the floor without an impact, acceleration along the horizontal motion (m/s²):\n")
    print("| speed (m/s) | object-steps | truth | model | bias | mean absolute error |")
    print("|---|---|---|---|---|---|")
    for low, high in SPEED_BANDS:
        band = on_floor & ~impact & (speed >= low) & (speed < high)
        if not band.any():
            continue
        error = along_pred[band] - along_true[band]
        print(f"| {low}–{high:g} | {band.sum()} | {along_true[band].mean():.3f} | "
              f"{along_pred[band].mean():.3f} | {error.mean():+.3f} | {np.abs(error).mean():.3f} |")
    squared = (np.linalg.norm(v_pred - v_true, axis=1) / dt) ** 2
    print("\nShares of the summed squared 3-D acceleration error:\n")
    print("| where | object-steps | error | RMS (m/s²) |")
    print("|---|---|---|---|")
    for name, mask in [("on the floor", on_floor & ~impact), ("on the floor, impact", on_floor & impact),
                       (f"clear of the floor (> {AIR_M} m)", in_air & ~impact),
                       ("clear of the floor, impact", in_air & impact),
                       ("in between", ~in_air & ~on_floor)]:
        print(f"| {name} | {100 * mask.mean():.1f} % | {100 * squared[mask].sum() / squared.sum():.1f} % | "
              f"{np.sqrt(squared[mask].mean()):.2f} |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("model", help="model file (.h5)")
    parser.add_argument("data", help="trajectory file (fignet generate)")
    parser.add_argument("--trajectories", type=int, default=100, help="how many (default 100)")
    args = parser.parse_args()
    model = fignet.load_model(args.model)
    trajectories = fignet.read_trajectories(args.data)[: args.trajectories]
    report(object_steps(model, trajectories), model.time_step, np.asarray(model.gravity))


if __name__ == "__main__":
    main()
