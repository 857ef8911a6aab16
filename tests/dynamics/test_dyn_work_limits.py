"""impstab.simulate from Python: the same step and memory limits as ``impstab simulate``."""

from __future__ import annotations

import math

import pytest

import impstab
import impstab.limits as limits
from impstab.dynamics.simulate import default_step
from impstab.errors import ModelError


@pytest.fixture(scope="module")
def model():
    return impstab.load_model("examples/imp_symmetric.toml")


def test_too_many_steps_names_duration_and_the_keyword(model):
    h = default_step(model, 1000.0)
    duration = 2 * limits.MAX_STEPS * h
    with pytest.raises(ModelError) as err:
        impstab.simulate(model, thrust=1000.0, duration=duration)
    text = str(err.value)
    assert err.value.field == "duration" and "time steps (limit 1e+08)" in text and "allow_long=True" in text


def test_too_many_steps_with_dt_names_dt(model):
    with pytest.raises(ModelError) as err:
        impstab.simulate(model, thrust=1000.0, duration=10.0, dt=1e-8)
    assert err.value.field == "dt" and "1e+09 time steps" in str(err.value)


def test_allow_long_raises_the_limit_but_not_without_bound(model, monkeypatch):
    h = default_step(model, 1000.0)
    monkeypatch.setattr(limits, "MAX_STEPS", 1000)
    duration = 3000 * h  # 3000 steps: beyond the (patched) limit, within LONG_FACTOR x it
    with pytest.raises(ModelError, match="allow_long=True"):
        impstab.simulate(model, thrust=1000.0, duration=duration, critical_thrust=False)
    res = impstab.simulate(model, thrust=1000.0, duration=duration, critical_thrust=False, allow_long=True)
    assert res.completed and res.steps == pytest.approx(math.ceil(duration / h), abs=2)
    with pytest.raises(ModelError) as err:  # beyond LONG_FACTOR x the limit even when allowed
        impstab.simulate(model, thrust=1000.0, duration=2 * limits.LONG_FACTOR * 1000 * h, allow_long=True)
    assert "allow_long" not in str(err.value) and "(limit 1e+06)" in str(err.value)


def test_stored_samples_are_bounded(model):
    with pytest.raises(ModelError) as err:
        impstab.simulate(model, thrust=1000.0, duration=100.0, sample=1e-6, allow_long=True)
    assert err.value.field == "sample" and "GiB" in str(err.value)
