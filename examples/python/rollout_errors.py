#!/usr/bin/env python3
"""Rolls the shipped model out on freshly generated MOVi-A scenes and plots its errors.

Trains nothing: loads models/movi-a-small.h5, generates scenes no model was trained on (native
Bullet, the same generator as `fignet generate`), rolls each out with the network alone from its
first three frames, and plots the translation and rotation errors per frame to a PNG.

    PYTHONPATH=build/release/python python3 examples/python/rollout_errors.py --out errors.png
"""

import argparse
import pathlib

import matplotlib

matplotlib.use("Agg")  # files only, no display
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import fignet  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--model", type=pathlib.Path, default=ROOT / "models" / "movi-a-small.h5")
    parser.add_argument("--scenes", type=int, default=4, help="scenes to generate")
    parser.add_argument("--seed", type=int, default=3, help="the generator's seed")
    parser.add_argument("--frames", type=int, default=96, help="frames per scene")
    parser.add_argument("--out", type=pathlib.Path, default=pathlib.Path("rollout_errors.png"))
    args = parser.parse_args()

    model = fignet.load_model(args.model)
    truths = fignet.generate("movi-a", count=args.scenes, seed=args.seed, frames=args.frames)
    errors = [fignet.rollout_errors(fignet.rollout(model, t), t) for t in truths]

    seconds = np.arange(args.frames) * model.time_step
    figure, (translation, rotation) = plt.subplots(1, 2, figsize=(10, 4), sharex=True)
    for i, e in enumerate(errors):
        translation.plot(seconds, e["translation"], label=f"scene {i}")
        rotation.plot(seconds, e["rotation"])
    translation.set(xlabel="time (s)", ylabel="translation error, RMSE over objects (m)")
    rotation.set(xlabel="time (s)", ylabel="rotation error, mean over objects (°)")
    translation.legend()
    figure.suptitle(f"{args.model.name} on MOVi-A scenes of seed {args.seed}: network alone")
    figure.tight_layout()
    figure.savefig(args.out, dpi=100)

    mean = np.mean([e["mean_translation"] for e in errors])
    rot = np.mean([e["mean_rotation"] for e in errors])
    print(f"{len(errors)} scenes: mean translation error {mean:.3f} m, rotation {rot:.1f}°")
    print(f"plot: {args.out}")


if __name__ == "__main__":
    main()
