#!/usr/bin/env python3
"""A model's answer to a stack at rest, frame by frame: the first frames of `fignet stress`'s stack.

A stack of MOVi cubes (MOVi-A's own 1.4 m cube mesh of 56 vertices, 3 kg, friction 0.8, as
`fignet stress`'s "stack of N MOVi cubes", each resting on the 5 mm collision margin) is rolled
out by the network alone from frames that do not move, as a rollout from rest starts. It prints
each cube's speed over each predicted frame: the truth is 0, free fall from rest reaches g·dt in
one frame, and a speed that rises and falls every other frame is a network overshooting its own
answer to contact. Needs the Python module (PYTHONPATH=build/release/python) and numpy.

    scripts/rest-response.py models/movi-a-small.h5 --levels 2 --frames 8
"""
import argparse

import numpy as np

import fignet

HALF = 0.7  # MOVi cube half extent, m
GAP = 0.005  # Bullet's collision margin in fignet generate's data, m
DENSITY = 1.1  # kg/m³, the stress suite's MOVi cube: 3.0 kg


def movi_cube_mesh():
    """The 1.4 m cube of MOVi-A's scenes as the network was trained on it (each side split 3×3),
    taken from the first generated scene that holds one: an 8-corner cube would be a mesh the
    network never saw."""
    for seed in range(1, 100):
        scene = fignet.generate("movi-a", count=1, seed=seed)[0]
        for k in range(scene.num_objects):
            vertices = np.asarray(scene.vertices(k))
            if len(vertices) == 56 and np.allclose(np.ptp(vertices, axis=0), 2 * HALF):
                return vertices, np.asarray(scene.faces(k))
    raise RuntimeError("no 1.4 m cube in MOVi-A scenes 1-99")


def stack(model, levels, frames):
    """A trajectory of `levels` cubes standing still for history + 1 + `frames` frames."""
    vertices, faces = movi_cube_mesh()
    history = model.history
    trajectory = fignet.Trajectory(time_step=model.time_step, gravity=model.gravity)
    for level in range(levels):
        center = np.array([0, 0, HALF + GAP + level * (2 * HALF + GAP)])
        positions = np.tile(center, (history + 1 + frames, 1))
        quaternions = np.tile([1.0, 0, 0, 0], (history + 1 + frames, 1))
        trajectory.add_object(vertices, faces, positions, quaternions, mass=DENSITY * (2 * HALF) ** 3,
                              friction=0.8, restitution=0.7)
    return trajectory


def speeds(model, trajectory):
    """Each cube's speed (m/s) over each frame the network predicts, (frames, cubes)."""
    history = model.history
    predicted = np.asarray(fignet.rollout(model, trajectory).positions)
    return np.linalg.norm(np.diff(predicted[history:], axis=0), axis=2) / model.time_step


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("model", help="model file (.h5)")
    parser.add_argument("--levels", type=int, default=2, help="cubes in the stack (default 2)")
    parser.add_argument("--frames", type=int, default=8, help="frames to predict (default 8)")
    args = parser.parse_args()
    if args.levels < 1 or args.frames < 1:
        parser.error("--levels and --frames must be at least 1")
    model = fignet.load_model(args.model)
    table = speeds(model, stack(model, args.levels, args.frames))
    free_fall = np.linalg.norm(model.gravity) * model.time_step
    print(f"{args.model}: a stack of {args.levels} MOVi cubes at exact rest, the network alone; "
          f"free fall from rest reaches {free_fall:.3f} m/s in one frame\n")
    print("| frame | " + " | ".join(f"cube {k + 1} speed (m/s)" for k in range(args.levels)) + " |")
    print("|---" * (args.levels + 1) + "|")
    for frame, row in enumerate(table, start=1):
        print(f"| {frame} | " + " | ".join(f"{v:.3f}" for v in row) + " |")


if __name__ == "__main__":
    main()
