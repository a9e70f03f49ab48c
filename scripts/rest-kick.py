#!/usr/bin/env python3
"""A model's first answer to a stack at rest: one prediction from frames that do not move.

A stack of MOVi cubes (1.4 m, 3 kg, friction 0.8, as `fignet stress`'s "stack of N MOVi cubes",
each resting on the 5 mm collision margin) is given to the network with every past frame equal,
as a rollout from rest starts, and again with the training's rigid-body random walk on that
history (noise_std over the history, rotations scaled by the body's radius, the oldest frame
clean). It prints each cube's speed over the predicted frame: at exact rest the truth is 0, and
free fall would be g·dt. A network that has only seen resting contacts through the training
noise may answer exact rest very differently from rest with noise. Needs the Python module
(PYTHONPATH=build/release/python) and numpy.

    scripts/rest-kick.py models/movi-a-small.h5 --levels 2 --draws 8
"""
import argparse

import numpy as np

import fignet

HALF = 0.7  # MOVi cube half extent, m
GAP = 0.005  # Bullet's collision margin in fignet generate's data, m
DENSITY = 1.1  # kg/m³, the stress suite's MOVi cube: 3.0 kg


def cube_mesh(half):
    vertices = np.array([[x, y, z] for x in (-half, half) for y in (-half, half) for z in (-half, half)])
    faces = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                      [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    return vertices.astype(float), faces


def quaternion(rotation_vector):
    angle = np.linalg.norm(rotation_vector)
    if angle == 0:
        return np.array([1.0, 0, 0, 0])
    return np.concatenate([[np.cos(angle / 2)], np.sin(angle / 2) * rotation_vector / angle])


def speeds(model, levels, noise_std, rng):
    """Each cube's speed (m/s) over the frame the model predicts after `history` + 1 still frames."""
    vertices, faces = cube_mesh(HALF)
    radius = np.linalg.norm(vertices, axis=1).max()
    history = model.history
    trajectory = fignet.Trajectory(time_step=model.time_step, gravity=model.gravity)
    for level in range(levels):
        center = np.array([0, 0, HALF + GAP + level * (2 * HALF + GAP)])
        # history + 1 input frames and one more, which only kinematic objects would read.
        positions = np.tile(center, (history + 2, 1))
        quaternions = np.tile([1.0, 0, 0, 0], (history + 2, 1))
        translation, rotation = np.zeros(3), np.zeros(3)
        step_std = noise_std / np.sqrt(history)
        for frame in range(1, history + 1):
            translation += rng.normal(0, step_std, 3)
            rotation += rng.normal(0, step_std, 3) / radius
            positions[frame] = center + translation
            quaternions[frame] = quaternion(rotation)
        positions[history + 1], quaternions[history + 1] = positions[history], quaternions[history]
        trajectory.add_object(vertices, faces, positions, quaternions, mass=DENSITY * (2 * HALF) ** 3,
                              friction=0.8, restitution=0.7)
    predicted = np.asarray(model.predict(trajectory, history)["positions"])
    return np.linalg.norm(predicted - trajectory.positions[history], axis=1) / model.time_step


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("model", help="model file (.h5)")
    parser.add_argument("--levels", type=int, default=2, help="cubes in the stack (default 2)")
    parser.add_argument("--noise", type=float, nargs="*", default=[1e-4, 3e-4],
                        help="random-walk noise at the last frame, m (default 1e-4 3e-4)")
    parser.add_argument("--draws", type=int, default=8, help="noise draws per level (default 8)")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    if args.levels < 1:
        parser.error(f"--levels {args.levels}: a stack needs at least one cube")
    model = fignet.load_model(args.model)
    rng = np.random.default_rng(args.seed)
    free_fall = np.linalg.norm(model.gravity) * model.time_step
    print(f"{args.model}: a stack of {args.levels} MOVi cubes; free fall over one frame "
          f"{free_fall:.3f} m/s\n")
    print("| history | " + " | ".join(f"cube {k + 1} (m/s)" for k in range(args.levels)) + " |")
    print("|---" * (args.levels + 1) + "|")
    print("| at rest | " + " | ".join(f"{s:.3f}" for s in speeds(model, args.levels, 0.0, rng)) + " |")
    for noise in args.noise:
        draws = np.array([speeds(model, args.levels, noise, rng) for _ in range(args.draws)])
        print(f"| noise {noise:g} m, mean (max) of {args.draws} | " +
              " | ".join(f"{m:.3f} ({x:.3f})" for m, x in zip(draws.mean(0), draws.max(0))) + " |")


if __name__ == "__main__":
    main()
