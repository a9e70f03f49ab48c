"""Trajectories between numpy, files and the generator."""

import subprocess

import numpy as np
import pytest

import fignet
from conftest import box


def test_generated_trajectories_survive_a_file_round_trip(tmp_path):
    path = tmp_path / "two.h5"
    generated = fignet.generate("movi-a", count=2, seed=5, frames=12, path=path)
    read = fignet.read_trajectories(path)
    assert len(read) == len(generated) == 2
    for a, b in zip(generated, read):
        assert a.num_frames == b.num_frames == 12
        np.testing.assert_array_equal(a.positions, b.positions)
        np.testing.assert_array_equal(a.quaternions, b.quaternions)
        np.testing.assert_array_equal(a.masses, b.masses)
        np.testing.assert_array_equal(a.linear_velocities, b.linear_velocities)
        for o in range(a.num_objects):
            np.testing.assert_array_equal(a.vertices(o), b.vertices(o))
            np.testing.assert_array_equal(a.faces(o), b.faces(o))


@pytest.mark.parametrize("stacks,levels,spheres",
                         [(0, (1, 3), 0.0), (2, (1, 3), 0.0), (2, (4, 5), 0.0), (2, (1, 3), 0.5)])
def test_generate_gives_what_the_command_line_gives(tmp_path, cli, stacks, levels, spheres):
    path = tmp_path / "cli.h5"
    level_args = ["--min-stack-levels", str(levels[0]), "--max-stack-levels", str(levels[1]),
                  "--sphere-topped-stacks", str(spheres)]
    subprocess.run(
        [cli, "generate", "--preset", "movi-a", "--count", "2", "--seed", "7", "--frames", "10",
         "--stacks", str(stacks), *(level_args if stacks else []), "--out", path],
        check=True, capture_output=True,
    )
    from_cli = fignet.read_trajectories(path)
    from_python = fignet.generate("movi-a", count=2, seed=7, frames=10, threads=1, stacks=stacks,
                                  min_stack_levels=levels[0], max_stack_levels=levels[1],
                                  sphere_topped_stacks=spheres)
    assert len(from_cli) == len(from_python) == 2
    for a, b in zip(from_cli, from_python):
        assert a.num_objects == b.num_objects
        np.testing.assert_array_equal(a.positions, b.positions)
        np.testing.assert_array_equal(a.quaternions, b.quaternions)


def test_a_trajectory_built_from_numpy_round_trips(tmp_path):
    vertices, faces = box(0.25)
    frames = 5
    positions = np.stack([np.array([0.0, 0.0, 1.0 - 0.01 * f]) for f in range(frames)])
    turn = np.array([np.cos(0.05), 0.0, 0.0, np.sin(0.05)])  # (w, x, y, z)
    quaternions = np.tile(turn, (frames, 1))
    t = fignet.Trajectory(time_step=1 / 48, gravity=(0, 0, -9.81))
    t.add_object(vertices, faces, positions, quaternions, mass=2.0, friction=0.4, restitution=0.2)
    assert (t.num_objects, t.num_frames) == (1, frames)
    path = tmp_path / "made.h5"
    fignet.write_trajectories(path, [t], preset="hand-made", seed=3)
    (back,) = fignet.read_trajectories(path)
    np.testing.assert_allclose(back.positions[:, 0], positions, rtol=0, atol=0)
    np.testing.assert_allclose(back.quaternions[:, 0], quaternions, rtol=0, atol=1e-15)
    np.testing.assert_array_equal(back.vertices(0), vertices)
    np.testing.assert_array_equal(back.faces(0), faces)
    assert back.masses[0] == 2.0 and back.frictions[0] == 0.4 and back.restitutions[0] == 0.2
    np.testing.assert_array_equal(back.gravity, [0, 0, -9.81])
    assert back.floor_height == 0.0


def test_mesh_arrays_are_read_only_views():
    (t,) = fignet.generate("movi-a", count=1, seed=2, frames=4)
    vertices = t.vertices(0)
    assert not vertices.flags.writeable
    assert np.shares_memory(vertices, t.vertices(0))  # the same storage, not a copy
    with pytest.raises(ValueError):
        vertices[0, 0] = 1.0
    with pytest.raises(IndexError):
        t.vertices(t.num_objects)
