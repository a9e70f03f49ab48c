#!/usr/bin/env python3
"""How still a model keeps bodies that rest in the data.

Takes the bodies of a trajectory file that are at rest over its last frames, places each alone on
the floor at its recorded rest pose (its own mesh, mass and materials, as training saw them),
and steps it with each model, the network alone (no free flight, sleeping or guard): prints the
median and largest motion after the first step and after --steps steps. Ground truth is zero
motion (native Bullet creeps ~7 µm per frame there by itself).

    PYTHONPATH=build/release/python python3 scripts/rest_drift.py \\
        --model models/movi-a-small.h5 --data data/movi-a/eval-192.h5

--trace prints the first body's displacement and velocity along the run instead (how it is lost:
a drift that grows as t², or one that stops); --slide the friction the model applies in one step
to a body pushed along the floor (the part of the change of speed that reverses with the push)
against Coulomb's, and its bias (the change with no push); --release the same bodies let go from
rest above their rest poses (a model trained on thrown bodies may hold a still body in the air).
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


FLOOR_FRICTION = 0.3  # MOVi's floor (reference/facts.md); Bullet multiplies the two frictions


TURNS = 1  # --turns


def alone_at_rest(model, t, o, velocity=(0.0, 0.0, 0.0), lift=0.0):
    """A scene of the body alone at its recorded rest pose (sliding at `velocity`, m/s; `lift`
    metres higher), stepped by the network alone."""
    scene = fignet.Scene(model, free_flight=False, sleeping=False, penetration_guard=False,
                         rest_guard=False, turns=TURNS)
    scene.add_floor(height=t.floor_height, friction=FLOOR_FRICTION)
    scene.add_body(t.vertices(o), t.faces(o), mass=t.masses[o], friction=t.frictions[o],
                   restitution=t.restitutions[o],
                   position=t.positions[-1, o] + np.array([0.0, 0.0, lift]),
                   orientation=t.quaternions[-1, o], linear_velocity=velocity)
    return scene


def drift(model, t, o, steps):
    """Displacement after the first step and after `steps` steps, metres."""
    scene = alone_at_rest(model, t, o)
    start = scene.positions[0].copy()
    scene.step(1)
    first = np.linalg.norm(scene.positions[0] - start)
    scene.step(steps - 1)
    return first, np.linalg.norm(scene.positions[0] - start)


def trace(model, t, o, steps):
    """The body's displacement (mm) and velocity (m/s) along the run, at a few steps."""
    scene = alone_at_rest(model, t, o)
    start = scene.positions[0].copy()
    previous = start
    for step in range(1, steps + 1):
        scene.step(1)
        now = scene.positions[0].copy()
        if step in (1, 2, 5, 10, 20, 50, 100, 200, 500, 1000, 2000) or step == steps:
            d, v = 1000 * (now - start), (now - previous) / t.time_step
            print(f"| {step} | {d[0]:.2f}, {d[1]:.2f}, {d[2]:.2f} | {v[0]:.3f}, {v[1]:.3f}, "
                  f"{v[2]:.3f} |")
        previous = now


def speed_change(model, t, o, velocity):
    """The body's change of velocity (m/s) in one step from `velocity` (m/s)."""
    scene = alone_at_rest(model, t, o, velocity=velocity)
    start = scene.positions[0].copy()
    scene.step(1)
    return (scene.positions[0] - start) / t.time_step - np.asarray(velocity)


def slide(models, bodies, speeds):
    """Each body pushed along +x, −x, +y and −y on the floor: the odd part of its change of speed
    in one step (what reverses with the push: friction), mean over bodies and directions, against
    Coulomb friction, −min(v, μ_body·μ_floor·g·dt); and the change with no push at all (a bias
    that no push direction explains), mean over bodies, in x and y."""
    print("| model | bias x, y | " + " | ".join(f"{v} m/s" for v in speeds) + " |")
    print("|---|---|" + "---|" * len(speeds))
    g_dt = 10.0 * bodies[0][0].time_step
    coulomb = [np.mean([-min(v, t.frictions[o] * FLOOR_FRICTION * g_dt) for t, o in bodies])
               for v in speeds]
    print("| Coulomb friction | 0, 0 | " + " | ".join(f"{c:+.3f}" for c in coulomb) + " |")
    for path in models:
        model = fignet.load_model(path)
        bias = np.mean([speed_change(model, t, o, (0.0, 0.0, 0.0)) for t, o in bodies], axis=0)
        changes = []
        for v in speeds:
            odd = []
            for t, o in bodies:
                for axis in (0, 1):
                    push = np.zeros(3)
                    push[axis] = v
                    ahead, back = speed_change(model, t, o, push), speed_change(model, t, o, -push)
                    odd.append((ahead[axis] - back[axis]) / 2)
            changes.append(np.mean(odd))
        print(f"| {path.name} | {bias[0]:+.4f}, {bias[1]:+.4f} | "
              + " | ".join(f"{c:+.3f}" for c in changes) + " |")


def release(models, bodies, gaps):
    """Each body let go from rest `gap` metres above its rest pose: how far it falls over the
    steps exact free fall takes to come within 1 mm of the floor, as a share of that fall (1:
    like free flight, 0: held in the air), median and least over bodies. With a still history
    and gravity g·dt² per step, free fall covers g·dt²·n(n+1)/2 in n steps."""
    g_dt2 = 10.0 * bodies[0][0].time_step ** 2
    steps = [max(1, int((np.sqrt(1 + 8 * (gap - 1e-3) / g_dt2) - 1) / 2)) for gap in gaps]
    print("| model | " + " | ".join(f"{gap} m ({n} steps)" for gap, n in zip(gaps, steps)) + " |")
    print("|---|" + "---|" * len(gaps))
    for path in models:
        model = fignet.load_model(path)
        cells = []
        for gap, n in zip(gaps, steps):
            free_fall = g_dt2 * n * (n + 1) / 2
            shares = []
            for t, o in bodies:
                scene = alone_at_rest(model, t, o, lift=gap)
                start = scene.positions[0][2]
                scene.step(n)
                shares.append((start - scene.positions[0][2]) / free_fall)
            cells.append(f"{np.median(shares):.2f} / {np.min(shares):.2f}")
        print(f"| {path.name} | " + " | ".join(cells) + " |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", type=pathlib.Path, action="append", required=True)
    parser.add_argument("--data", type=pathlib.Path, required=True)
    parser.add_argument("--bodies", type=int, default=12, help="resting bodies to try (first ones)")
    parser.add_argument("--steps", type=int, default=100, help="steps per body")
    parser.add_argument("--trace", action="store_true",
                        help="print each model's path of the first body instead")
    parser.add_argument("--slide", action="store_true",
                        help="print the friction the model applies in one step to pushed bodies, "
                             "and its bias at rest, instead")
    parser.add_argument("--release", type=float, nargs="*", metavar="GAP",
                        help="let each body go from rest GAP metres above its rest pose "
                             "(default gaps 2, 0.5, 0.1, 0.03, 0.01) and print how far it falls "
                             "as a share of free fall, instead")
    parser.add_argument("--turns", type=int, default=1,
                        help="average each prediction over the scene turned by k/turns of a turn "
                             "about the vertical (1: off)")
    args = parser.parse_args()
    global TURNS
    TURNS = args.turns

    bodies = resting_bodies(fignet.read_trajectories(args.data), frames=10, tolerance=1e-4)
    bodies = bodies[: args.bodies]
    if not bodies:
        raise SystemExit(f"{args.data}: no body rests over its last 10 frames")
    if args.slide:
        print(f"{len(bodies)} bodies of {args.data.name} pushed along ±x and ±y on the floor: "
              "the part of the change of speed in the first step that reverses with the push "
              "(friction), and the change with no push (bias), m/s, mean\n")
        slide(args.model, bodies, [0.01, 0.03, 0.1, 0.3, 1.0, 3.0])
        return
    if args.release is not None:
        gaps = args.release or [2.0, 0.5, 0.1, 0.03, 0.01]
        print(f"{len(bodies)} bodies of {args.data.name} let go from rest above their rest poses: "
              "fall over the steps exact free fall takes to come within 1 mm of the floor, as a "
              "share of that fall, median / least (1: falls freely; 0: held in the air)\n")
        release(args.model, bodies, gaps)
        return
    if args.trace:
        t, o = bodies[0]
        for path in args.model:
            print(f"\n{path.name}: body {o} of a trajectory of {args.data.name}, "
                  f"{t.masses[o]:.1f} kg, friction {t.frictions[o]:.2f}\n")
            print("| step | displacement x, y, z (mm) | velocity x, y, z (m/s) |")
            print("|---|---|---|")
            trace(fignet.load_model(path), t, o, args.steps)
        return
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
