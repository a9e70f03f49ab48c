"""FIGNet (Face Interaction Graph Networks) for Bullet, from Python.

Learned rigid-body simulation: load a trained model, roll out trajectories, evaluate them with
the metrics of ``fignet eval``, read and write the trajectory files of ``fignet generate``, and
step scenes of your own meshes with a model or with native Bullet.

    import fignet
    model = fignet.load_model("models/movi-a-small.h5")
    truth = fignet.generate("movi-a", count=1, seed=3)[0]
    predicted = fignet.rollout(model, truth)
    errors = fignet.rollout_errors(predicted, truth)

Arrays are numpy float64; quaternions are (w, x, y, z). Bad input raises ValueError (shapes,
values; fignet.ConfigError and fignet.MeshError are ValueErrors) or OSError (fignet.FileError).
"""

from ._fignet import (  # noqa: F401
    ConfigError,
    FileError,
    MeshError,
    Model,
    Scene,
    Trajectory,
    bf16_products,
    compare_paired,
    evaluate,
    generate,
    load_model,
    pose_errors,
    read_trajectories,
    rollout,
    rollout_errors,
    set_bf16_products,
    write_trajectories,
)
from ._fignet import __version__  # noqa: F401

__all__ = [
    "ConfigError",
    "FileError",
    "MeshError",
    "Model",
    "Scene",
    "Trajectory",
    "bf16_products",
    "compare_paired",
    "evaluate",
    "generate",
    "load_model",
    "pose_errors",
    "read_trajectories",
    "rollout",
    "rollout_errors",
    "set_bf16_products",
    "write_trajectories",
]
