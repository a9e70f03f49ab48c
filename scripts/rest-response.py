#!/usr/bin/env python3
"""A model's answer to a stack at rest, frame by frame: the first frames of `fignet stress`'s stack.

A stack of MOVi cubes (MOVi-A's own 1.4 m cube mesh of 56 vertices, 3 kg, friction 0.8, as
`fignet stress`'s "stack of N MOVi cubes", each resting on the 5 mm collision margin) is rolled
out by the network alone from frames that do not move, as a rollout from rest starts. It prints
each cube's speed over each predicted frame: the truth is 0, free fall from rest reaches g·dt in
one frame, and a speed that rises and falls every other frame is a network overshooting its own
answer to contact. Needs the Python module (PYTHONPATH=build/release/python) and numpy.

With --perturb SIGMA it prints instead how far each cube's next position moves when every
position of the stack's history moves by N(0, SIGMA²) per coordinate (a few draws): the
one-step response to rounding. A cube in free flight answers about 3·SIGMA; at a resting contact
the closest points of parallel faces are a tie that any perturbation breaks, so there the
answer is micrometres however small SIGMA is (docs/graph.md, "Ties at resting contact").

    scripts/rest-response.py models/movi-a-small.h5 --levels 2 --frames 8
    scripts/rest-response.py models/movi-a-small.h5 --levels 2 --perturb 1e-10
"""
import argparse

import numpy as np

import fignet

HALF = 0.7  # MOVi cube half extent, m
GAP = 0.005  # Bullet's collision margin in fignet generate's data, m: a body rests this high
# over the floor, and two bodies twice this apart (each shape's margin); the stress suite's
# stacks start GAP apart, and so does this script unless --gap says otherwise
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


def stack(model, levels, frames, gap=GAP):
    """A trajectory of `levels` cubes standing still for history + 1 + `frames` frames, the
    lowest GAP above the floor and each `gap` above the one below."""
    vertices, faces = movi_cube_mesh()
    history = model.history
    trajectory = fignet.Trajectory(time_step=model.time_step, gravity=model.gravity)
    for level in range(levels):
        center = np.array([0, 0, HALF + GAP + level * (2 * HALF + gap)])
        positions = np.tile(center, (history + 1 + frames, 1))
        quaternions = np.tile([1.0, 0, 0, 0], (history + 1 + frames, 1))
        trajectory.add_object(vertices, faces, positions, quaternions, mass=DENSITY * (2 * HALF) ** 3,
                              friction=0.8, restitution=0.7)
    return trajectory


def one_step_response(model, trajectory, sigma, draws, seed=0):
    """How far each cube's first predicted position moves when the history's positions are
    perturbed by N(0, sigma²) per coordinate, one row per draw, (draws, cubes), metres."""
    history = model.history
    base = np.asarray(fignet.rollout(model, trajectory).positions)[history + 1]
    positions = np.asarray(trajectory.positions)
    quaternions = np.asarray(trajectory.quaternions)
    rng = np.random.default_rng(seed)
    rows = []
    for _ in range(draws):
        moved = fignet.Trajectory(time_step=trajectory.time_step, gravity=trajectory.gravity)
        for k in range(trajectory.num_objects):
            noisy = positions[:, k].copy()
            noisy[:history + 1] += rng.normal(0.0, sigma, (history + 1, 3))
            moved.add_object(trajectory.vertices(k), trajectory.faces(k), noisy, quaternions[:, k],
                             mass=trajectory.masses[k], friction=trajectory.frictions[k],
                             restitution=trajectory.restitutions[k])
        predicted = np.asarray(fignet.rollout(model, moved).positions)[history + 1]
        rows.append(np.linalg.norm(predicted - base, axis=1))
    return np.array(rows)


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
    parser.add_argument("--perturb", type=float, metavar="SIGMA",
                        help="print the one-step response to perturbations of SIGMA metres")
    parser.add_argument("--draws", type=int, default=4, help="perturbations drawn (default 4)")
    parser.add_argument("--gap", type=float, default=GAP, metavar="METRES",
                        help="between stacked cubes (default 0.005 as the stress suite; Bullet "
                        "rests two bodies 0.010 apart)")
    args = parser.parse_args()
    if args.levels < 1 or args.frames < 1:
        parser.error("--levels and --frames must be at least 1")
    if not 0 <= args.gap < 1:
        parser.error("--gap must be in [0, 1) metres")
    if args.perturb is not None and not (args.perturb > 0 and args.draws >= 1):
        parser.error("--perturb must be > 0 and --draws at least 1")
    model = fignet.load_model(args.model)
    if args.perturb is not None:
        response = one_step_response(model, stack(model, args.levels, 1, args.gap), args.perturb,
                                     args.draws)
        print(f"{args.model}: a stack of {args.levels} MOVi cubes at exact rest; each draw moves "
              f"every history position by N(0, ({args.perturb:.0e} m)²) per coordinate\n")
        print("| draw | " + " | ".join(f"cube {k + 1} moves (µm)" for k in range(args.levels))
              + " |")
        print("|---" * (args.levels + 1) + "|")
        for draw, row in enumerate(response, start=1):
            print(f"| {draw} | " + " | ".join(f"{1e6 * v:.3f}" for v in row) + " |")
        return
    table = speeds(model, stack(model, args.levels, args.frames, args.gap))
    free_fall = np.linalg.norm(model.gravity) * model.time_step
    print(f"{args.model}: a stack of {args.levels} MOVi cubes at exact rest, the network alone; "
          f"free fall from rest reaches {free_fall:.3f} m/s in one frame\n")
    print("| frame | " + " | ".join(f"cube {k + 1} speed (m/s)" for k in range(args.levels)) + " |")
    print("|---" * (args.levels + 1) + "|")
    for frame, row in enumerate(table, start=1):
        print(f"| {frame} | " + " | ".join(f"{v:.3f}" for v in row) + " |")


if __name__ == "__main__":
    main()
