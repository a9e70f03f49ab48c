"""The scene API: bodies from numpy, stepped by a model or by native Bullet."""

import warnings

import numpy as np
import pytest

import fignet
from conftest import box

GRAVITY = np.array([0.0, 0.0, -10.0])


def parabola(p0, v0, seconds):
    return p0 + v0 * seconds + 0.5 * GRAVITY * seconds**2


def semi_implicit_euler(p0, v0, n, dt):
    """Bullet's integrator (and the learned world's free flight) after n steps of dt."""
    return p0 + n * dt * v0 + 0.5 * n * (n + 1) * dt**2 * GRAVITY


def test_free_flight_with_a_model_is_exact(model):
    scene = fignet.Scene(model)
    vertices, faces = box(0.3)
    p0, v0 = np.array([0.0, 0.0, 20.0]), np.array([1.0, -0.5, 2.0])
    scene.add_body(vertices, faces, mass=2.0, position=p0, linear_velocity=v0)
    scene.step(12)
    assert scene.frame == 12
    assert scene.last_step_stats()["free_flight_bodies"] == 1
    # Seeded in free flight, the body's history is its parabola, and free flight keeps it there.
    np.testing.assert_allclose(scene.positions[0], parabola(p0, v0, 12 * scene.time_step),
                               rtol=0, atol=1e-9)
    np.testing.assert_allclose(scene.quaternions[0], [1, 0, 0, 0], atol=1e-12)
    # Seeded moving straight, it follows Bullet's semi-implicit Euler at the model's step.
    straight = fignet.Scene(model, seed_falling=False)
    straight.add_body(vertices, faces, mass=2.0, position=p0, linear_velocity=v0)
    straight.step(12)
    np.testing.assert_allclose(straight.positions[0],
                               semi_implicit_euler(p0, v0, 12, straight.time_step),
                               rtol=0, atol=1e-9)


def test_materials_outside_the_models_data_are_named_in_one_warning(model):
    scene = fignet.Scene(model)
    scene.add_floor(friction=0.9)
    vertices, faces = box(0.3)
    scene.add_body(vertices, faces, name="plain", position=(0, 0, 5))  # Bullet's restitution 0
    scene.add_body(vertices, faces, friction=0.4, restitution=0.3, position=(3, 0, 5))  # MOVi metal
    with pytest.warns(UserWarning) as warned:
        scene.step(1)
    lines = [str(w.message) for w in warned if "training data" in str(w.message)]
    assert len(lines) == 1
    assert "body 0 'plain' (friction 0.5, restitution 0)" in lines[0]
    assert "body 1" not in lines[0]
    assert "the floor (friction 0.9, restitution 0.5)" in lines[0]
    assert "bodies of friction 0.4-0.8 and restitution 0.3-0.7" in lines[0]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        scene.step(1)  # said once, at the first step
        native = fignet.Scene()  # native Bullet has no training data to be outside of
        native.add_body(vertices, faces)
        native.step(1)


def test_native_bullet_falls_as_gravity_says():
    scene = fignet.Scene()  # no model: Bullet at 240 Hz
    vertices, faces = box(0.3)
    p0 = np.array([0.0, 0.0, 20.0])
    scene.add_body(vertices, faces, position=p0)
    scene.step(24)
    seconds = 24 * scene.time_step
    # 240 Hz substeps: semi-implicit Euler at 1/240 s, in Bullet's single precision.
    expected = semi_implicit_euler(p0, np.zeros(3), 24 * 5, seconds / (24 * 5))
    np.testing.assert_allclose(scene.positions[0], expected, rtol=0, atol=1e-4)
    assert abs(scene.positions[0, 2] - parabola(p0, 0, seconds)[2]) < 10 * seconds / 240
    assert scene.last_step_stats() == {}


def test_bodies_are_placed_and_reported_by_their_mesh_frame():
    vertices, faces = box(0.5)
    offset = vertices + np.array([2.0, 0.0, 0.0])  # the mesh's origin lies outside the box
    turn = np.array([np.cos(0.3), 0.0, 0.0, np.sin(0.3)])
    scene = fignet.Scene()
    scene.add_body(offset, faces, position=(1, 1, 10), orientation=turn)
    np.testing.assert_allclose(scene.positions[0], [1, 1, 10], atol=1e-12)
    np.testing.assert_allclose(scene.quaternions[0], turn, atol=1e-12)
    scene.step(2)
    assert np.all(np.abs(scene.positions[0, :2] - [1, 1]) < 1e-6)  # falls straight down
    np.testing.assert_allclose(np.abs(scene.quaternions[0]), np.abs(turn), atol=1e-6)


def test_a_cube_on_the_floor_with_a_model_stays_above_it(model):
    scene = fignet.Scene(model, rest_guard=False)  # the model moves it
    scene.add_floor()
    vertices, faces = box(0.35)
    scene.add_body(vertices, faces, density=2700, position=(0, 0, 0.35))
    scene.step(48)
    # The penetration guard keeps it out of the floor whatever the model does.
    assert scene.positions[0, 2] > 0.35 - 0.02


def test_a_cube_at_rest_stays_with_the_rest_guard_and_creeps_without(model):
    moved = {}
    for guard in (True, False):
        scene = fignet.Scene(model, rest_guard=guard)
        scene.add_floor()
        vertices, faces = box(0.35)
        start = np.array([0.2, -0.1, 0.35])
        scene.add_body(vertices, faces, density=2700, position=start)
        scene.step(96)
        moved[guard] = np.linalg.norm(scene.positions[0] - start)
        assert scene.last_step_stats()["rested_bodies"] == (1 if guard else 0)
    assert moved[True] < 1e-6
    assert moved[False] > 0.01  # the shipped model's creep at rest


def test_kinematic_bodies_move_at_their_velocity_alone():
    scene = fignet.Scene()
    vertices, faces = box(0.2)
    scene.add_body(vertices, faces, kinematic=True, position=(0, 0, 1), linear_velocity=(1, 0, 0))
    scene.step(48)
    np.testing.assert_allclose(scene.positions[0], [1, 0, 1], atol=1e-5)


def test_mesh_files_load_as_bodies(source_dir):
    assets = source_dir / "examples" / "assets"
    meshes = sorted(p for p in assets.glob("*") if p.suffix in {".obj", ".stl", ".ply", ".off"})
    if not meshes:
        pytest.skip("no mesh files in examples/assets")
    scene = fignet.Scene()
    scene.add_mesh_file(meshes[0], position=(0, 0, 5))
    scene.step(1)
    assert scene.positions[0, 2] < 5


def sphere(radius, rings, segments):
    """A UV sphere: rings - 1 latitude circles of `segments` vertices and two poles."""
    vertices = [[0.0, 0.0, radius]]
    for i in range(1, rings):
        theta = np.pi * i / rings
        for j in range(segments):
            phi = 2 * np.pi * j / segments
            vertices.append([radius * np.sin(theta) * np.cos(phi),
                             radius * np.sin(theta) * np.sin(phi), radius * np.cos(theta)])
    vertices.append([0.0, 0.0, -radius])
    faces, last = [], len(vertices) - 1
    for j in range(segments):
        faces.append([0, 1 + j, 1 + (j + 1) % segments])
        base = 1 + (rings - 2) * segments
        faces.append([last, base + (j + 1) % segments, base + j])
    for i in range(rings - 2):
        for j in range(segments):
            a, b = 1 + i * segments + j, 1 + i * segments + (j + 1) % segments
            faces.append([a, a + segments, b])
            faces.append([b, a + segments, b + segments])
    return np.array(vertices), np.array(faces)


def test_a_fine_mesh_enters_the_graph_within_the_node_budget(model):
    vertices, faces = sphere(0.5, 40, 40)  # 1562 vertices
    nodes = {}
    for budget in (None, 0):
        # The ball rests on the floor: without the rest guard, so that the network sees it.
        scene = fignet.Scene(model, free_flight=False, graph_vertices=budget, rest_guard=False)
        scene.add_body(vertices, faces, mass=5.0, position=(0, 0, 0.51), name="ball",
                       max_graph_vertices=0)
        scene.add_floor()
        scene.step(1)
        nodes[budget] = scene.last_step_stats()["mesh_nodes"]
    # The model's resolution (at most 1000 when its file predates it) within 2 %, or none.
    assert 0 < nodes[None] < 400
    assert nodes[0] >= len(vertices)


def test_turn_averaging_cancels_the_models_sideways_push_at_rest(model):
    # A model pushes a resting body sideways by a bias of its own; predictions averaged with the
    # scene turned half a turn cancel the part of it whose direction does not turn with the scene
    # (FIGNetWorldOptions::turns; the exact cancellation of a constant bias is ModelPredictor's
    # C++ test). The body is the data's own (a 1.4 m metal cube of 7.4 kg on Kubric's floor,
    # resting 5 mm up where Bullet's margin rests it): outside the data's materials a model's push
    # is its guess. Over 48 steps from (0.2, -0.1) the models shipped to 2026-11-29 moved it
    # 0.5-0.7 mm with one turn and 0.2-0.6 of that with two; the model of 2026-12-03 pushes 4-5x
    # less, too little to cancel in 48 steps (0.13 mm, ratio 1.1), and from the origin over 192
    # steps moves it 0.50 mm with one turn and 0.65 of that with two. A ratio near 1 would say
    # the turns never reached the predictor; unequal runs, that they ran at all.
    moved, ends = {}, {}
    for turns in (1, 2):
        scene = fignet.Scene(model, free_flight=False, sleeping=False, penetration_guard=False,
                             rest_guard=False, turns=turns)
        scene.add_floor()
        vertices, faces = box(0.7)
        start = np.array([0.0, 0.0, 0.705])
        scene.add_body(vertices, faces, mass=7.4, friction=0.4, restitution=0.3, position=start)
        scene.step(192)
        ends[turns] = scene.positions[0].copy()
        moved[turns] = np.linalg.norm(ends[turns][:2] - start[:2])
    assert np.linalg.norm(ends[2] - ends[1]) > 1e-6, ends
    assert moved[2] < 0.8 * moved[1], moved
    # The mirror (FIGNetWorldOptions::mirror; its reflection equivariance is tested in C++)
    # reaches the predictor too: the same run with it ends elsewhere.
    scene = fignet.Scene(model, free_flight=False, sleeping=False, penetration_guard=False,
                         rest_guard=False, mirror=True)
    scene.add_floor()
    scene.add_body(vertices, faces, mass=7.4, friction=0.4, restitution=0.3, position=start)
    scene.step(192)
    assert np.linalg.norm(scene.positions[0] - ends[1]) > 1e-7
    with pytest.raises(ValueError, match="turns"):
        fignet.Scene(model, turns=0).step(1)
