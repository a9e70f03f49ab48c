#!/usr/bin/env python3
"""How still a model keeps bodies that rest in the data.

Takes the bodies of a trajectory file that are at rest over its last frames, places each alone on
the floor at its recorded rest pose (its own mesh, mass and materials, as training saw them),
and steps it with each model, the network alone (no free flight, sleeping or guard): prints the
median and largest motion after the first step and after --steps steps. Ground truth is zero
motion (native Bullet creeps ~7 µm per frame there by itself).

    PYTHONPATH=build/release/python python3 scripts/rest_drift.py \\
        --model models/movi-a-small.h5 --data data/movi-a/eval-192.h5
"""

import argparse
import pathlib

import numpy as np

import fignet


def resting_bodies(trajectories, frames, tolerance):
    """(trajectory, object) pairs whose centre moved less than `tolerance` over the last frames."""
    found = []
    for t in trajectories:
        p = t.positions
        for o in range(t.num_objects):
            if not t.kinematic[o] and np.abs(p[-1, o] - p[-frames, o]).max() < tolerance:
                found.append((t, o))
    return found


def drift(model, t, o, steps):
    """Displacement after the first step and after `steps` steps, metres."""
    scene = fignet.Scene(model, free_flight=False, sleeping=False, penetration_guard=False,
                         rest_guard=False)
    scene.add_floor(height=t.floor_height)
    scene.add_body(t.vertices(o), t.faces(o), mass=t.masses[o], friction=t.frictions[o],
                   restitution=t.restitutions[o], position=t.positions[-1, o],
                   orientation=t.quaternions[-1, o])
    start = scene.positions[0].copy()
    scene.step(1)
    first = np.linalg.norm(scene.positions[0] - start)
    scene.step(steps - 1)
    return first, np.linalg.norm(scene.positions[0] - start)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", type=pathlib.Path, action="append", required=True)
    parser.add_argument("--data", type=pathlib.Path, required=True)
    parser.add_argument("--bodies", type=int, default=12, help="resting bodies to try (first ones)")
    parser.add_argument("--steps", type=int, default=100, help="steps per body")
    args = parser.parse_args()

    bodies = resting_bodies(fignet.read_trajectories(args.data), frames=10, tolerance=1e-4)
    bodies = bodies[: args.bodies]
    if not bodies:
        raise SystemExit(f"{args.data}: no body rests over its last 10 frames")
    print(f"{len(bodies)} bodies at rest in {args.data}, each alone, {args.steps} steps\n")
    print(f"| model | first step: median / max (mm) | after {args.steps} steps: median / max (m) |")
    print("|---|---|---|")
    for path in args.model:
        model = fignet.load_model(path)
        first, last = np.array([drift(model, t, o, args.steps) for t, o in bodies]).T
        print(f"| {path.name} | {1000 * np.median(first):.2f} / {1000 * first.max():.2f} | "
              f"{np.median(last):.3f} / {last.max():.3f} |")


if __name__ == "__main__":
    main()
