"""Shared fixtures of the Python module's tests (run by ctest, which sets the paths below)."""

import os
import pathlib

import numpy as np
import pytest


def _path(variable):
    value = os.environ.get(variable)
    if not value:
        pytest.skip(f"{variable} is not set (these tests run through ctest)")
    return pathlib.Path(value)


@pytest.fixture(scope="session")
def source_dir():
    return _path("FIGNET_SOURCE_DIR")


@pytest.fixture(scope="session")
def cli():
    """The `fignet` command-line tool of the same build."""
    return _path("FIGNET_CLI")


@pytest.fixture(scope="session")
def model(source_dir):
    import fignet

    return fignet.load_model(source_dir / "models" / "movi-a-small.h5")


def box(half=0.5):
    """A closed box centred on the origin, faces wound outward: (vertices, faces)."""
    corners = np.array(
        [[x, y, z] for z in (-half, half) for y in (-half, half) for x in (-half, half)], float
    )
    faces = np.array(
        [
            [0, 2, 3], [0, 3, 1],  # -z
            [4, 5, 7], [4, 7, 6],  # +z
            [0, 1, 5], [0, 5, 4],  # -y
            [2, 6, 7], [2, 7, 3],  # +y
            [0, 4, 6], [0, 6, 2],  # -x
            [1, 3, 7], [1, 7, 5],  # +x
        ],
        np.int32,
    )
    return corners, faces
