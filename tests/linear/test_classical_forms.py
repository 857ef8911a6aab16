"""The direct classical kernel against the general per-thrust linearization (``linearize_batch``).

``affine_forms`` forms ``K = K0 + T K1`` of many designs with :func:`classical_forms`; the
reference is the route it replaced: ``linearize_batch`` in the classical form, per design, at
the thrusts 0 and a large one (so that ``K1 = (K(big) - K0) / big`` is exact to rounding), on
every example model and on random layouts with full 6x6 mounts, off-axis thrust, partial
follower and preload on or off. A second check needs no differencing: ``K0 + T K1`` equals
``linearize_batch`` at ordinary thrusts where the thrust changes K by a good fraction.
"""

from pathlib import Path

import numpy as np
import pytest

from impstab.linear.linearize import affine_forms, pack_model
from impstab.linear.tangent import classical_forms, linearize_batch
from impstab.model import load_model
from impstab.model.mount_law import N_LAW

EXAMPLES = sorted((Path(__file__).resolve().parents[2] / "examples").glob("*.toml"))
EXAMPLES = [p for p in EXAMPLES if not p.name.startswith(("study_", "optimize_"))]  # model files only


# The kernels are called with arguments of the types the library passes, so that they run the
# machine code compiled for the commands, not variants of their own (each a compilation of tens of
# seconds in the test run): classical_forms takes writable stacks of designs; linearize_batch a
# model's read-only thrust direction and point, the start pose (here the default unloaded one)
# and the mount laws as a model packs them (zeros for linear mounts).
START = (0.0, np.zeros(3), np.eye(3))


def _linear_laws(positions):
    return np.zeros((len(positions), N_LAW))


def _as_in_a_model(a):
    view = a.view()
    view.flags.writeable = False
    return view


def _reference(mass6, damp6, positions, stiffness, damping, e_dir, r_thrust, tangency, preload):
    """``M, D, G, K0, K1`` per design from ``linearize_batch`` (classical) at thrusts 0 and big."""
    out = []
    for i in range(len(mass6)):
        big = 1e8 * max(np.abs(stiffness[i]).max(), 1e-300) * max(np.linalg.norm(positions[i], axis=-1).max(), 1e-3)
        m, d, g, k, _, _, _ = linearize_batch(
            np.array([0.0, big]), np.ones(2), mass6[i], damp6[i], positions[i], stiffness[i], damping[i],
            _as_in_a_model(e_dir[i]), _as_in_a_model(r_thrust[i]), tangency[i], preload, 1.0, False, 1.0, *START,
            _linear_laws(positions[i]),
        )
        out.append((m[0], d[0], g[0], k[0], (k[1] - k[0]) / big))
    return [np.array(a) for a in zip(*out)]


def _close(got, ref, rtol=1e-13):
    """Equal to rounding, relative to each design's matrix norm."""
    for a, b in zip(got, ref):
        scale = np.abs(b).max(axis=(-2, -1), keepdims=True)
        assert np.all(np.abs(a - b) <= rtol * np.maximum(scale, 1e-300)), np.abs(a - b).max()


def _spd(rng, n, scale):
    a = rng.normal(size=(n, 6, 6))
    return scale * (a @ a.transpose(0, 2, 1) + 6 * np.eye(6))


def _random_designs(rng, n, nm):
    positions = rng.uniform(-0.5, 0.5, (n, nm, 3))
    stiffness = _spd(rng, n * nm, 1e4).reshape(n, nm, 6, 6)
    stiffness[:, ::2, 3:] = 0.0  # every other mount translational only (the paper's mount)
    stiffness[:, ::2, :, 3:] = 0.0
    stiffness[:, ::2, :3, :3] += 1e5 * np.eye(3)
    damping = _spd(rng, n * nm, 1.0).reshape(n, nm, 6, 6)
    e_dir = rng.normal(size=(n, 3))
    e_dir /= np.linalg.norm(e_dir, axis=-1, keepdims=True)
    r_thrust = rng.uniform(-0.3, 0.3, (n, 3))
    return (_spd(rng, n, 10.0), _spd(rng, n, 0.1), positions, stiffness, damping, e_dir,
            r_thrust, rng.uniform(0.0, 1.0, n))


@pytest.mark.parametrize("preload", [True, False])
@pytest.mark.parametrize("nm", [2, 3, 8])
def test_random_layouts_equal_the_general_kernel(preload, nm):
    args = _random_designs(np.random.default_rng(nm), 20, nm)
    m, d, g, k0, k1, _ = classical_forms(*args, preload)
    _close((m, d, g, k0, k1), _reference(*args, preload))


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
@pytest.mark.parametrize("damped", [True, False])
def test_examples_equal_the_general_kernel(path, damped):
    pk = pack_model(load_model(path), damped=damped)
    stack = lambda a: np.array(a, dtype=float)[None]  # noqa: E731  (writable, as the library stacks designs)
    args = (stack(pk.mass6), stack(pk.damp6), stack(pk.positions), stack(pk.stiffness), stack(pk.damping),
            stack(pk.e_dir), stack(pk.r_thrust), stack(pk.tangency))
    m, d, k0, k1, g, _ = affine_forms(*args, pk.preload, stack(pk.length_scale), False)
    _close((m, d, g, k0, k1), _reference(*args, pk.preload))


@pytest.mark.parametrize("preload", [True, False])
def test_affine_form_is_the_stiffness_at_each_thrust(preload):
    """No differencing: K0 + T K1 against linearize_batch where T changes K by a good fraction."""
    args = _random_designs(np.random.default_rng(7), 10, 4)
    m, d, g, k0, k1, q1 = classical_forms(*args, preload)
    mass6, damp6, positions, stiffness, damping, e_dir, r_thrust, tangency = args
    for i in range(10):
        thrusts = np.array([0.0, 0.01, -0.1, 1.0]) * np.abs(k0[i]).max()  # N, against arms of ~0.3 m
        mi, di, gi, ki, _, _, _ = linearize_batch(
            thrusts, np.ones(4), mass6[i], damp6[i], positions[i], stiffness[i], damping[i], _as_in_a_model(e_dir[i]),
            _as_in_a_model(r_thrust[i]), tangency[i], preload, 1.0, False, 1.0, *START, _linear_laws(positions[i]),
        )
        got = k0[i] + thrusts[:, None, None] * k1[i]
        assert np.abs(ki[-1] - ki[0]).max() > 0.05 * np.abs(ki[0]).max()  # the thrust matters
        np.testing.assert_allclose(got, ki, rtol=0, atol=1e-13 * np.abs(ki).max())
        np.testing.assert_array_equal(m[i], mi[0])
        np.testing.assert_allclose(d[i], di[0], rtol=0, atol=1e-14 * np.abs(di[0]).max())
        np.testing.assert_array_equal(g[i], gi[0])
        # q1 is the linear static displacement per newton
        load = np.concatenate([e_dir[i], np.cross(r_thrust[i], e_dir[i])])
        np.testing.assert_allclose(k0[i] @ q1[i], load, rtol=0, atol=1e-12)


def test_preload_changes_k1():
    """The preload part is not zero on these layouts (so the comparisons above exercise it)."""
    args = _random_designs(np.random.default_rng(3), 5, 3)
    on = classical_forms(*args, True)[4]
    off = classical_forms(*args, False)[4]
    assert np.abs(on - off).max() > 0.01 * np.abs(on).max()
