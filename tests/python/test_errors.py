"""Bad input raises Python exceptions carrying the library's message; nothing aborts."""

import numpy as np
import pytest

import fignet
from conftest import box


def test_bad_shapes_raise_value_errors_naming_the_argument():
    vertices, faces = box()
    t = fignet.Trajectory()
    with pytest.raises(ValueError, match="vertices: expected an array of shape \\(n, 3\\)"):
        t.add_object(vertices[:, :2], faces, np.zeros((3, 3)), np.tile([1.0, 0, 0, 0], (3, 1)))
    with pytest.raises(ValueError, match="faces: expected an integer array"):
        t.add_object(vertices, faces.astype(float), np.zeros((3, 3)), np.tile([1.0, 0, 0, 0], (3, 1)))
    with pytest.raises(ValueError, match="quaternions must have shape \\(frames, 4\\)"):
        t.add_object(vertices, faces, np.zeros((3, 3)), np.zeros((2, 4)))
    with pytest.raises(ValueError, match="a zero or non-finite pose"):
        t.add_object(vertices, faces, np.zeros((3, 3)), np.zeros((3, 4)))
    with pytest.raises(ValueError, match="gravity: expected 3"):
        fignet.Trajectory(gravity=(0, -10))


def test_bad_meshes_raise_mesh_errors():
    vertices, faces = box()
    with pytest.raises(fignet.MeshError, match="references vertex 8"):
        fignet.Trajectory().add_object(vertices, faces + 8, np.zeros((2, 3)),
                                       np.tile([1.0, 0, 0, 0], (2, 1)))
    scene = fignet.Scene()
    with pytest.raises(ValueError, match="not closed"):
        scene.add_body(vertices, faces[:10], inertia="volume")
    with pytest.raises(fignet.ConfigError, match="expected auto, volume, convex or shell"):
        scene.add_body(vertices, faces, inertia="solid")
    flat = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
    with pytest.raises(fignet.MeshError, match="flat"):
        scene.add_body(flat, np.array([[0, 1, 2]]))


def test_open_meshes_load_with_one_warning():
    vertices, faces = box()
    scene = fignet.Scene()
    with pytest.warns(UserWarning, match="open edges") as warned:
        scene.add_body(vertices, faces[:10], name="open box")
    assert len(warned) == 1 and "open box" in str(warned[0].message)
    scene.add_floor()
    scene.step(5)
    assert np.isfinite(scene.positions).all()


def test_bad_files_raise_os_errors(tmp_path):
    with pytest.raises(OSError, match="nonexistent.h5"):
        fignet.load_model(tmp_path / "nonexistent.h5")
    not_hdf5 = tmp_path / "text.h5"
    not_hdf5.write_text("not a trajectory file")
    with pytest.raises(fignet.FileError, match="text.h5"):
        fignet.read_trajectories(not_hdf5)
    with pytest.raises(OSError):
        fignet.write_trajectories(tmp_path / "missing-folder" / "out.h5", [])


def test_misuse_of_models_and_scenes_raises(model):
    (t,) = fignet.generate("movi-a", count=1, seed=4, frames=8)
    with pytest.raises(ValueError, match="given_frames = 2"):
        fignet.rollout(model, t, given_frames=2)
    with pytest.raises(ValueError, match="frame 7"):
        model.predict(t, 7)
    scene = fignet.Scene(model)
    with pytest.raises(fignet.ConfigError, match="no bodies"):
        scene.step()
    vertices, faces = box()
    scene.add_body(vertices, faces, position=(0, 0, 3))
    with pytest.raises(ValueError, match="orientation: a zero quaternion"):
        scene.add_body(vertices, faces, orientation=(0, 0, 0, 0))
    scene.step()
    with pytest.raises(fignet.ConfigError, match="after the first step"):
        scene.add_body(vertices, faces)


def test_pose_errors_check_the_kinematic_flags_against_the_objects():
    positions = np.zeros((4, 3, 3))
    quaternions = np.tile([1.0, 0, 0, 0], (4, 3, 1))
    with pytest.raises(ValueError, match="kinematic: 1 flags for 3 objects"):
        fignet.pose_errors(positions, quaternions, positions, quaternions, kinematic=[False])
