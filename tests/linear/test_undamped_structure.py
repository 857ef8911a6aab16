"""A model family that is undamped and non-gyroscopic by construction says so, and it is exact.

The engine then takes the undamped form without sampling D and G at the far end of the search
range (static equilibria there are the costliest to reach). The statement must agree with the
matrices themselves at every load, and the critical thrust must not change.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest

import impstab
from impstab.linear.linearize import ModelFamily
from impstab.model import load_model, model_from_dict

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def _variants():
    sym = load_model(EXAMPLES / "imp_symmetric.toml")
    yield "symmetric", sym, True
    yield "asymmetric", load_model(EXAMPLES / "imp_asymmetric.toml"), True
    yield "damped and spinning", load_model(EXAMPLES / "imp_damped.toml"), False
    spinning = tomllib.loads((EXAMPLES / "imp_symmetric.toml").read_text())
    spinning["propeller"] = {"polar_inertia": 0.5, "speed": 100.0}
    yield "undamped, spinning", model_from_dict(spinning), False


@pytest.mark.parametrize("name, model, expected", list(_variants()), ids=lambda v: v if isinstance(v, str) else "")
def test_the_statement_agrees_with_the_matrices_at_every_load(name, model, expected):
    fam = ModelFamily(model)
    assert fam.undamped_nongyroscopic is expected
    loads = np.linspace(0.0, float(model.analysis.thrust_max), 7)
    _, d, g, _ = fam.matrices(loads)
    finite = np.isfinite(d).all(axis=(-2, -1)) & np.isfinite(g).all(axis=(-2, -1))
    vanish = not (d[finite].any() or g[finite].any())
    if expected:
        assert vanish
    else:
        assert not vanish


def test_the_critical_thrust_is_the_one_found_by_sampling(monkeypatch):
    model = load_model(EXAMPLES / "imp_asymmetric.toml")
    shortcut = impstab.critical_thrust(model).thrust
    monkeypatch.setattr(ModelFamily, "undamped_nongyroscopic", property(lambda self: False))
    sampled = impstab.critical_thrust(model).thrust
    assert shortcut == pytest.approx(sampled, rel=1e-13)


def test_a_grown_system_is_left_to_the_sampled_test():
    # beam mounts with mass: the internal dofs' matrices come from another assembly; no statement
    assert ModelFamily(load_model(EXAMPLES / "imp_beam_mounts.toml")).undamped_nongyroscopic is False
