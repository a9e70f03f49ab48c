#!/usr/bin/python3
"""Real meshes nobody here wrote, as a user would bring them: what each needed, its node counts,
the FIGNet world's cost for one body of it, and `fignet compare` on MOVi-C scenes made of it.

Each mesh file becomes its own MOVi-C dataset (`fignet generate --preset movi-c --assets`, 3
scenes), compared against native Bullet (`fignet compare`); then one body of it, dropped 1 m onto
the floor in a FIGNet world (the Python module's Scene), gives the graph's size and the
milliseconds of a learned step. Prints a Markdown table (docs/datasets.md).

  PYTHONPATH=build/release/python scripts/real_meshes.py --model models/movi-a-small.h5 \\
      [--fignet build/release/tools/fignet] [--work /tmp/real-meshes] [FILE ...]

Without FILE arguments it uses the meshes of Debian's assimp-testmodels package.
"""

import argparse
import json
import os
import re
import subprocess
import sys
import time

import numpy as np

import fignet

ASSIMP = "/usr/share/assimp/models"
DEFAULT_MESHES = [
    "OFF/Wuson.off",
    "STL/Spider_binary.stl",
    "STL/sphereWithHole.stl",
    "STL/3DSMaxExport.STL",
    "OBJ/regr01.obj",
    "PLY/pond.0.ply",
    "Collada/duck.dae",
    "Collada/teapots.DAE",
    "glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb",
]


def run(command):
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode != 0:
        return None, result.stderr.strip().splitlines()[-1] if result.stderr else "failed"
    return result.stdout, result.stderr


def compare_runs(json_path):
    """(world, Bullet 48 Hz, chaos floor) of `fignet compare --json`, each as (ms per simulated
    second, mean translation m, mean rotation deg); the world is the last FIGNet run (the world as
    users get it, after the network alone)."""
    with open(json_path) as f:
        runs = json.load(f)["runs"]

    def figures(run):
        if run is None:
            return None
        return (run["ms_per_simulated_second"], run["mean_translation_m"], run["mean_rotation_deg"])

    fignet_runs = [r for r in runs if r["kind"] == "FIGNet"]
    return (figures(fignet_runs[-1] if fignet_runs else None),
            figures(next((r for r in runs if r["name"] == "Bullet 48 Hz"), None)),
            figures(next((r for r in runs if r["kind"] == "chaos floor"), None)))


def one_body_step(model, trajectory, frames=24):
    """Mesh nodes in the graph and ms per learned step for the first body of `trajectory`,
    dropped 1 m onto the floor (its contact with the floor runs the network)."""
    vertices, faces = trajectory.vertices(0), trajectory.faces(0)
    scene = fignet.Scene(model)
    lowest = vertices[:, 2].min()
    scene.add_body(np.array(vertices), np.array(faces), mass=1.0,
                   position=(0.0, 0.0, 1.0 - lowest), name="probe")
    scene.add_floor()
    nodes, seconds, steps = 0, 0.0, 0
    for _ in range(frames):
        start = time.perf_counter()
        scene.step()
        elapsed = time.perf_counter() - start
        stats = scene.last_step_stats()
        if stats.get("simulated_bodies", 0) > 0:
            nodes = max(nodes, stats["mesh_nodes"])
            seconds += elapsed
            steps += 1
    return nodes, (1000.0 * seconds / steps if steps else float("nan"))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("files", nargs="*")
    parser.add_argument("--model", required=True)
    parser.add_argument("--fignet", default="build/release/tools/fignet")
    parser.add_argument("--work", default="/tmp/real-meshes")
    parser.add_argument("--scenes", type=int, default=3)
    args = parser.parse_args()
    files = args.files or [os.path.join(ASSIMP, f) for f in DEFAULT_MESHES]
    os.makedirs(args.work, exist_ok=True)
    model = fignet.load_model(args.model)
    print(f"model {args.model}: trained on meshes of up to {model.config['mesh_vertices']} "
          "vertices\n")
    print("| mesh | what it needed (fignet generate's warning) | graph vertices (data / world) "
          "| ms per learned step, one body | compare: FIGNet world m / deg | Bullet 48 Hz m / deg "
          "| chaos floor m |")
    print("|---|---|---|---|---|---|---|")
    for path in files:
        name = os.path.basename(path)
        folder = os.path.join(args.work, re.sub(r"\W", "_", name))
        os.makedirs(folder, exist_ok=True)
        link = os.path.join(folder, name)
        if not os.path.lexists(link):
            os.symlink(os.path.abspath(path), link)
        data = os.path.join(args.work, re.sub(r"\W", "_", name) + ".h5")
        out, err = run([args.fignet, "generate", "--preset", "movi-c", "--assets", folder,
                        "--count", str(args.scenes), "--seed", "5", "--threads", "1",
                        "--out", data])
        if out is None:
            print(f"| {name} | does not load: {err} | | | | | |")
            continue
        warning = next((l for l in err.splitlines() if "warning" in l), "clean")
        needed = re.sub(r"^fignet: warning: mesh '[^']*' ", "", warning)
        trajectories = fignet.read_trajectories(data)
        data_vertices = trajectories[0].vertices(0).shape[0]
        nodes, ms = one_body_step(model, trajectories[0])
        results = os.path.join(args.work, "compare.json")
        out, _ = run([args.fignet, "compare", "--model", args.model, "--data", data,
                      "--max-scenes", str(args.scenes), "--report",
                      os.path.join(args.work, "report.html"), "--json", results])
        world, bullet, chaos = compare_runs(results) if out is not None else (None, None, None)
        cell = lambda r: f"{r[1]:.2f} / {r[2]:.0f}" if r else "-"
        floor = f"{chaos[1]:.2f}" if chaos else "-"
        print(f"| {name} | {needed} | {data_vertices} / {nodes} | {ms:.2f} | {cell(world)} "
              f"| {cell(bullet)} | {floor} |")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
