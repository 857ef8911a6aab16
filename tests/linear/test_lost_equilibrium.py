"""Very soft mounts under a large thrust: the straight pose is exact, found to rounding; beyond
the path's reach, every command ends with exit 2 and one line naming the thrust and the reason.

Independent answer: on the symmetric three-mount ring with linear mounts, the equilibrium under
a follower thrust along the axis is the pure surge ``T / (3 k_axial)``.
"""

from __future__ import annotations

import re
import subprocess
import sys

import numpy as np
import pytest

import impstab
from impstab.errors import NumericalError
from impstab.linear.linearize import linearize


@pytest.fixture(scope="module")
def soft(tmp_path_factory):
    folder = tmp_path_factory.mktemp("soft")
    text = open("examples/imp_symmetric.toml").read()
    assert "k_axial = 1.0e5" in text
    text = re.sub(r"k_shear = [^\n#]*", "k_shear = 1.0 ", text)
    path = folder / "soft.toml"
    path.write_text(text)
    return path


def test_straight_pose_found_to_rounding_under_half_a_meganewton(soft):
    model = impstab.load_model(soft)
    for thrust in (8000.0, 5.0e5, 1.0e6):
        lin = linearize(model, thrust, "equilibrium")
        assert lin.displacement[0] == pytest.approx(thrust / (3 * 1.0e5), rel=1e-12)
        assert np.abs(lin.displacement[1:]).max() < 1e-7  # the rounding of a 0.06 N/m lateral stiffness
        assert np.abs(lin.rotation - np.eye(3)).max() < 1e-12


def test_beyond_reach_python_error_names_the_reason(soft):
    model = impstab.load_model(soft)
    with pytest.raises(NumericalError, match=r"33\.3 m under it, 99\.4 times the model's size") as err:
        impstab.modes(model, thrust=1.0e7)
    assert "linear statics" in err.value.reason


@pytest.mark.parametrize("command", [["modes", "--thrust", "1e7"],
                                     ["simulate", "--thrust", "1e7", "--duration", "0.1", "--no-plot"]])
def test_beyond_reach_cli_exit_2_one_line(soft, command, tmp_path):
    out = subprocess.run([sys.executable, "-m", "impstab", command[0], str(soft), *command[1:]],
                         capture_output=True, text=True, cwd=tmp_path)
    assert out.returncode == 2
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("impstab: error: --thrust = 10000000.0: no static equilibrium")
    assert "times the model's size" in lines[0] and "loses stability at 11087.2 N (flutter)" in lines[0]
    assert not list(tmp_path.iterdir())  # nothing written
